// 'replica run''s options: the site file fills in what the command line leaves open (one row per
// setting), the warm-up is one option fed by either, and every device kind has its source option,
// defaulted from --hal as its description says.
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#include <platform/cli/commands.h>
#include <platform/cli/run_options.h>
#include <platform/cli/run_sources.h>
#include <platform/site_config.h>
#include <recordings/device_kind.h>

#include <gtest/gtest.h>

namespace replica::tests {
namespace {

using namespace platform;
using namespace platform::run_cli;

// Parses 'args' as 'replica run' does and applies the site file 'toml' (none when empty).
RunOptions parseRun(std::vector<std::string> args, const std::string& toml)
{
    CLI::App app;
    RunOptions o;
    addRunOptions(app, o);
    args.insert(args.begin(), "run");
    std::vector<const char*> argv;
    for (const auto& a : args) {
        argv.push_back(a.c_str());
    }
    app.parse(static_cast<int>(argv.size()), argv.data());
    if (!toml.empty()) {
        const auto file = std::filesystem::temp_directory_path() /
                          ("replica-run-options-" + std::to_string(::getpid()) + ".toml");
        std::ofstream(file) << toml;
        auto site = loadSiteConfig(file);
        std::filesystem::remove(file);
        EXPECT_TRUE(site && site->problems.empty());
        if (site) {
            applySite(site->config, o, app);
        }
    }
    return o;
}

TEST(RunOptions, TheSiteFileFillsOnlyWhatTheCommandLineLeavesOpen)
{
    const std::string site = "[run]\nhal = \"sim\"\nrate_hz = 30.0\n"
                             "[display]\noutput = \"headless\"\nkms_connector = \"HDMI-A-1\"\n"
                             "[devices]\naccel_name = \"lis3dh\"\nlamp_gpio = \"gpiochip0:1,2,3\"\n"
                             "[recording]\nflush_ms = 250\n[render]\nwarm_up = false\n";
    const RunOptions o = parseRun({"--rate", "50", "--accel-name", "bma280"}, site);
    EXPECT_EQ(o.hal, "sim");
    EXPECT_DOUBLE_EQ(o.rateHz, 50.0);              // the command line wins
    EXPECT_EQ(o.live.accelName, "bma280");         // the command line wins
    EXPECT_EQ(o.live.lampGpio, "gpiochip0:1,2,3"); // a nested member, from the site
    EXPECT_EQ(o.outputChoice.kms.connector, "HDMI-A-1");
    EXPECT_EQ(o.recordFlushMs, 250);
    EXPECT_TRUE(o.noWarmUp);
    RunConfig config;
    ASSERT_EQ(runConfigFromOptions(o, {64, 40}, config), kExitOk);
    EXPECT_FALSE(config.warmUp);

    // Without the key the warm-up stays on; --no-warm-up alone turns it off.
    const RunOptions plain = parseRun({}, "[run]\nhal = \"sim\"\n");
    EXPECT_FALSE(plain.noWarmUp);
    EXPECT_EQ(plain.rateHz, 60.0); // the site file's default, as the command line's
    ASSERT_EQ(runConfigFromOptions(plain, {64, 40}, config), kExitOk);
    EXPECT_TRUE(config.warmUp);
    EXPECT_TRUE(parseRun({"--no-warm-up"}, "").noWarmUp);
}

TEST(RunOptions, EveryDeviceKindHasItsSourceOptionDefaultedFromHal)
{
    for (const auto* kind : recordings::deviceKinds()) {
        CLI::App app;
        RunOptions o;
        addRunOptions(app, o);
        EXPECT_NE(app.get_option_no_throw("--" + deviceOption(*kind)), nullptr) << kind->name();
    }
    EXPECT_EQ(deviceOption(recordings::lampSelectorKind()), "lamp-selector");
    // --hal live: each kind's live driver, the optional lamp selector none.
    auto live = chooseDevices(parseRun({"--hal", "live"}, ""));
    ASSERT_TRUE(live) << live.error().message;
    EXPECT_EQ(live->of(recordings::spectrometerKind()), "live");
    EXPECT_EQ(live->of(recordings::trackerKind()), "opentrack");
    EXPECT_EQ(live->of(recordings::accelKind()), "live");
    EXPECT_EQ(live->of(recordings::lampSelectorKind()), "none");
    // --hal sim with one device overridden, and the lamp lines that make the selector gpio.
    auto mixed = chooseDevices(
            parseRun({"--hal", "sim", "--tracker", "hid", "--lamp-gpio", "gpiochip0:1,2,3"}, ""));
    ASSERT_TRUE(mixed) << mixed.error().message;
    EXPECT_EQ(mixed->of(recordings::spectrometerKind()), "sim");
    EXPECT_EQ(mixed->of(recordings::trackerKind()), "hid");
    EXPECT_EQ(mixed->of(recordings::lampSelectorKind()), "gpio");
    // A value no kind knows (as the site file's [sources] could give) is named with the choices.
    RunOptions bad = parseRun({"--hal", "sim"}, "");
    bad.sources["accel"] = "hid";
    auto refused = chooseDevices(bad);
    ASSERT_FALSE(refused);
    EXPECT_NE(refused.error().message.find("accel=hid"), std::string::npos)
            << refused.error().message;
    EXPECT_NE(refused.error().message.find("accel live|sim|replay"), std::string::npos)
            << refused.error().message;
}

} // namespace
} // namespace replica::tests
