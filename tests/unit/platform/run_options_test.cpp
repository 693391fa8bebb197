// 'replica run''s options: the site file fills in what the command line leaves open (one row per
// setting), the warm-up is one option fed by either, and every device kind has its source option,
// defaulted from --hal as its description says.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <unistd.h>

#include <pipeline/base/data_dir.h>
#include <platform/cli/commands.h>
#include <platform/cli/run_options.h>
#include <platform/cli/run_resolve.h>
#include <platform/cli/run_sources.h>
#include <platform/loop/error_probe.h>
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
    o.given = givenOptions(app);
    if (!toml.empty()) {
        const auto file = std::filesystem::temp_directory_path() /
                          ("replica-run-options-" + std::to_string(::getpid()) + ".toml");
        std::ofstream(file) << toml;
        auto site = loadSiteConfig(file);
        std::filesystem::remove(file);
        EXPECT_TRUE(site && site->problems.empty());
        if (site) {
            applySite(site->config, o);
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
    auto plan = resolveRun(o);
    ASSERT_TRUE(plan) << plan.error().lines.front();
    EXPECT_FALSE(plan->config.warmUp);

    // Without the key the warm-up stays on; --no-warm-up alone turns it off.
    const RunOptions plain = parseRun({}, "[run]\nhal = \"sim\"\n");
    EXPECT_FALSE(plain.noWarmUp);
    EXPECT_EQ(plain.rateHz, 60.0); // the site file's default, as the command line's
    plan = resolveRun(plain);
    ASSERT_TRUE(plan) << plan.error().lines.front();
    EXPECT_TRUE(plan->config.warmUp);
    EXPECT_TRUE(parseRun({"--no-warm-up"}, "").noWarmUp);

    // The steady cadence's floor: the site's, the command line's over it, 15 Hz without either.
    EXPECT_DOUBLE_EQ(plain.minRateHz, 15.0);
    EXPECT_DOUBLE_EQ(parseRun({}, "[run]\nmin_rate_hz = 30.0\n").minRateHz, 30.0);
    EXPECT_DOUBLE_EQ(parseRun({"--min-rate", "20"}, "[run]\nmin_rate_hz = 30.0\n").minRateHz, 20.0);
}

TEST(RunOptions, TheLightAndTheBoothComeFromTheSiteFileOrTheCommandLine)
{
    // [booth] light, dir and [spectrometer] direct_cdm2_per_y reach the run configuration.
    const std::string site = fmt::format("[run]\nhal = \"sim\"\n[booth]\nlight = \"direct\"\n"
                                         "dir = \"{}\"\n[spectrometer]\ndirect_cdm2_per_y = 0.25\n",
                                         (dataDir() / "booth").string());
    RunOptions o = parseRun({}, site);
    EXPECT_EQ(o.light, "direct");
    EXPECT_EQ(o.booth, (dataDir() / "booth").string());
    auto file = std::filesystem::temp_directory_path() /
                ("replica-run-light-" + std::to_string(::getpid()) + ".toml");
    std::ofstream(file) << site;
    o.config = file.string();
    auto plan = resolveRun(o);
    std::filesystem::remove(file);
    ASSERT_TRUE(plan) << plan.error().lines.front();
    EXPECT_EQ(plan->config.light, kLightDirect);
    EXPECT_EQ(plan->config.boothDir, "booth"); // inside the data folder: recorded relative to it
    EXPECT_DOUBLE_EQ(plan->config.directCdM2PerY, 0.25);
    // The command line wins; without either: auto, the shipped booth, the default scale.
    EXPECT_EQ(parseRun({"--light", "auto"}, site).light, "auto");
    plan = resolveRun(parseRun({}, "[run]\nhal = \"sim\"\n"));
    ASSERT_TRUE(plan) << plan.error().lines.front();
    EXPECT_EQ(plan->config.light, kLightAuto);
    EXPECT_EQ(plan->config.boothDir, "booth");
    EXPECT_DOUBLE_EQ(plan->config.directCdM2PerY, kDefaultDirectCdM2PerY);
}

TEST(RunOptions, TheErrorProbeIsOffWithoutASiteFileAndEvery10sFromOne)
{
    // No site file: off. A site file without the key (the kiosk's): every 10 s. The key, then the
    // command line, win; the period chosen is recorded in the RunConfig.
    EXPECT_EQ(parseRun({}, "").errorProbeS, 0.0);
    EXPECT_EQ(parseRun({}, "[run]\nhal = \"sim\"\n").errorProbeS, kKioskErrorProbeS);
    EXPECT_EQ(parseRun({}, "[render]\nerror_probe = 3.5\n").errorProbeS, 3.5);
    EXPECT_EQ(parseRun({}, "[render]\nerror_probe = 0\n").errorProbeS, 0.0);
    const RunOptions o = parseRun({"--error-probe", "2"}, "[render]\nerror_probe = 30\n");
    EXPECT_EQ(o.errorProbeS, 2.0);
    auto plan = resolveRun(o);
    ASSERT_TRUE(plan) << plan.error().lines.front();
    EXPECT_EQ(plan->config.errorProbeS, 2.0);
    auto back = RunConfig::fromJson(plan->config.toJson());
    ASSERT_TRUE(back) << back.error().message;
    EXPECT_EQ(back->errorProbeS, 2.0);
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

// Writes 'toml' as a site file and resolves 'replica run --kiosk --config FILE ARGS' as the kiosk
// and 'replica config check' both do.
Resolved<RunPlan> resolveKiosk(const std::string& toml, std::vector<std::string> args = {})
{
    const auto file = std::filesystem::temp_directory_path() /
                      ("replica-resolve-" + std::to_string(::getpid()) + ".toml");
    std::ofstream(file) << toml;
    args.insert(args.begin(), {"--kiosk", "--config", file.string()});
    auto plan = resolveRun(parseRun(args, ""));
    std::filesystem::remove(file);
    return plan;
}

TEST(RunResolve, WhatTheKioskWouldRefuseIsTheSiteFilesProblemWithItsLineAndKey)
{
    const std::string good = "[run]\nhal = \"sim\"\n";
    ASSERT_TRUE(resolveKiosk(good + "[display]\noutput = \"headless\"\n"));
    // Each value the reader accepts but the kiosk could not use: exit 78, the key and its line
    // (the file's last).
    const std::vector<std::pair<std::string, std::string>> cases{
            {"[defaults]\nlamp = \"sodium\"\n", "defaults.lamp"},
            {"[devices]\naccel_axes = \"x,x,q\"\n", "devices.accel_axes"},
            {"[devices]\nlamp_gpio = \"gpiochip0:17\"\n", "devices.lamp_gpio"},
            {"[tracker]\nbind = \"localhost:80\"\n", "tracker.bind"},
            {"[display]\noutput = \"headless\"\nsize = \"16384x16\"\n", "display.size"},
            // Sides past 2^32 wrapped to 1 and 600 once: each is read whole before narrowing.
            {"[display]\noutput = \"headless\"\nsize = \"4294967297x1\"\n", "display.size"},
            {"[display]\noutput = \"headless\"\nsize = \"960x4294967896\"\n", "display.size"},
            {"[scene]\ndir = \"/nonexistent-replica-scene\"\n", "scene.dir"},
            {"[display]\nprofile = \"/nonexistent-replica-profile.json\"\n", "display.profile"},
            {"[log]\nlevel = \"loud\"\n", "log.level"},
            {"[booth]\nid = \"booth-9\"\n", "booth.id"},
    };
    for (const auto& [extra, key] : cases) {
        const std::string text = good + extra;
        const long line = static_cast<long>(std::count(text.begin(), text.end(), '\n'));
        auto plan = resolveKiosk(text);
        ASSERT_FALSE(plan) << key;
        EXPECT_EQ(plan.error().code, kExitConfig) << key;
        EXPECT_EQ(plan.error().problem.key, key);
        EXPECT_EQ(plan.error().problem.line, line) << key;
        EXPECT_NE(plan.error().lines.front().find(fmt::format(":{}: {}: ", line, key)),
                  std::string::npos)
                << plan.error().lines.front();
    }
    // The same value on the command line is the command line's error, naming the option (exit 1,
    // as when the device refused it).
    auto cli = resolveKiosk(good, {"--accel-axes", "x,x,q"});
    ASSERT_FALSE(cli);
    EXPECT_EQ(cli.error().code, kExitFailure);
    EXPECT_EQ(cli.error().lines.front().rfind("--accel-axes x,x,q: ", 0), 0u)
            << cli.error().lines.front();
}

// --size and the site file's display.size share one WxH parser that reads each side whole before
// narrowing it: 4294967392x60 once became a 96x60 frame (while 4294967296x60 was refused).
TEST(RunOptions, AFrameSizePast32BitsIsOutOfRangeNotWrapped)
{
    ASSERT_TRUE(parseSize("960x600"));
    EXPECT_EQ(*parseSize("96X60"), std::make_pair(96, 60));
    for (const char* bad : {"4294967392x60", "4294967296x60", "96x4294967356",
                            "18446744073709551712x60", "99999999999999999999999x60", "-96x60",
                            "+96x60", " 96x60", "96x60 ", "96x60x2", "0x60", "96x"}) {
        EXPECT_FALSE(parseSize(bad)) << bad;
    }
}

// One renderer: "flat" is refused by name with a line that says so, from the site file (exit 78,
// its line and key) and from the command line (exit 2, usage); "booth" is what a run draws with.
TEST(RunResolve, TheFlatRendererIsRefusedWithOneLineThatSaysItWasRemoved)
{
    const std::string good = "[run]\nhal = \"sim\"\n[display]\noutput = \"headless\"\n";
    ASSERT_TRUE(resolveKiosk(good + "[scene]\nrenderer = \"booth\"\n"));
    ASSERT_TRUE(resolveKiosk(good, {"--renderer", "booth"}));
    const std::string text = good + "[scene]\nrenderer = \"flat\"\n";
    auto site = resolveKiosk(text);
    ASSERT_FALSE(site);
    EXPECT_EQ(site.error().code, kExitConfig);
    EXPECT_EQ(site.error().problem.key, "scene.renderer");
    EXPECT_EQ(site.error().problem.line, 6);
    ASSERT_EQ(site.error().lines.size(), 1u);
    EXPECT_NE(site.error().lines.front().find(":6: scene.renderer: \"flat\": the flat renderer "
                                              "was removed"),
              std::string::npos)
            << site.error().lines.front();
    auto cli = resolveKiosk(good, {"--renderer", "flat"});
    ASSERT_FALSE(cli);
    EXPECT_EQ(cli.error().code, kExitUsage);
    ASSERT_EQ(cli.error().lines.size(), 1u);
    EXPECT_EQ(cli.error().lines.front().rfind("--renderer flat: the flat renderer was removed", 0),
              0u)
            << cli.error().lines.front();
    auto other = resolveKiosk(good, {"--renderer", "ray"});
    ASSERT_FALSE(other);
    EXPECT_EQ(other.error().code, kExitUsage);
}

} // namespace
} // namespace replica::tests
