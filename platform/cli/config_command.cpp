// 'replica config check FILE': every problem of a site file, with its key and line.
#include <fmt/format.h>

#include <platform/cli/commands.h>
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
    auto site = loadSiteConfig(o.file);
    if (!site) {
        fmt::print(stderr, "{}\n", site.error().message);
        return kExitFailure;
    }
    for (const auto& p : site->problems) {
        fmt::print(stderr, "{}\n", formatProblem(o.file, p));
    }
    if (!site->problems.empty()) {
        fmt::print(stderr, "{}: {} problem{}\n", o.file, site->problems.size(),
                   site->problems.size() == 1 ? "" : "s");
        return kExitFailure;
    }
    if (o.print) {
        fmt::print("{}\n", site->config.toJson());
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
            "check", "check a site file: every unknown key, wrong type, out-of-range or "
                     "non-finite value with its line; exit 0 when good, 1 otherwise");
    check->add_option("file", opts->file, "the site file")->required();
    check->add_flag("--print", opts->print, "print the resolved configuration (JSON) when good");
    check->callback([opts, &exitCode] { exitCode = checkMain(*opts); });
}

} // namespace replica::platform
