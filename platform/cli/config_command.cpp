// 'replica config check FILE': the site file resolved as the kiosk resolves it (run_resolve.h),
// every problem with its file, line and key.
#include <fmt/format.h>

#include <platform/cli/commands.h>
#include <platform/cli/run_resolve.h>
#include <platform/logging.h>
#include <platform/site_config.h>

namespace replica::platform {
namespace {

struct ConfigOptions {
    std::string file;
    bool print = false;
};

int checkMain(const ConfigOptions& o)
{
    // What 'replica run --kiosk --config FILE' resolves, opening no device.
    run_cli::RunOptions run;
    run.config = o.file;
    run.kiosk = true;
    auto plan = run_cli::resolveRun(run);
    if (!plan) {
        for (const auto& line : plan.error().lines) {
            fmt::print(stderr, "{}\n", line);
        }
        return kExitFailure;
    }
    if (o.print) {
        fmt::print("{}\n", plan->options.site->toJson());
    } else {
        fmt::print("{}: ok\n", o.file);
    }
    return kExitOk;
}

} // namespace

void registerConfigCommand(CLI::App& app, int& exitCode)
{
    auto opts = std::make_shared<ConfigOptions>();
    auto* config = app.add_subcommand("config", "the site file (/etc/replica/replica.toml)");
    config->require_subcommand(1);
    auto* check = config->add_subcommand(
            "check", "check a site file as 'replica run --kiosk' resolves it, opening no device: "
                     "every unknown key, wrong type, out-of-range or non-finite value with its "
                     "line, then the display profile, scene and booth loaded, lamp names, GPIO "
                     "lines, axes, addresses, frame size and log levels; exit 0 when the kiosk "
                     "would start, 1 otherwise");
    check->add_option("file", opts->file, "the site file")->required();
    check->add_flag("--print", opts->print, "print the resolved configuration (JSON) when good");
    check->callback([opts, &exitCode] { exitCode = checkMain(*opts); });
}

} // namespace replica::platform
