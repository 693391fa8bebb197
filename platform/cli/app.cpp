// Builds the 'replica' command line from the registered subcommands and maps outcomes to exit
// codes.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <functional>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <pipeline/base/json_schema.h>
#include <platform/cli/app.h>
#include <platform/cli/commands.h>
#include <platform/logging.h>
#include <platform/version.h>

namespace replica::platform {
namespace {

// CLI11's range checks let NaN through (every comparison with it is false) and take "inf":
// every floating option gets this check as well.
const CLI::Validator kFinite(
        [](std::string& input) -> std::string {
            char* end = nullptr;
            const double v = std::strtod(input.c_str(), &end);
            if (end == input.c_str() || !std::isfinite(v)) {
                return fmt::format("'{}' is not a finite number", input);
            }
            return {};
        },
        "",
        "FINITE");

void requireFiniteFloats(CLI::App& app)
{
    for (CLI::Option* opt : app.get_options()) {
        if (opt->get_type_name().rfind("FLOAT", 0) == 0) {
            opt->check(kFinite);
        }
    }
    for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
        requireFiniteFloats(*sub);
    }
}

// Errors from a thread, or from anywhere past the handler in runCli, would otherwise end in
// std::terminate's multi-line abort: one line and exit 2 instead.
[[noreturn]] void lastResortTerminate()
{
    std::string what = "unknown exception";
    if (auto e = std::current_exception()) {
        try {
            std::rethrow_exception(e);
        } catch (const std::exception& x) {
            what = x.what();
        } catch (...) {
        }
    }
    std::fprintf(stderr,
                 "replica: internal error: %s; this is a bug, please report it with the "
                 "command line\n",
                 what.c_str());
    std::fflush(stderr);
    std::_Exit(kExitUsage);
}

std::string oneLine(std::string s)
{
    for (char& c : s) {
        if (c == '\n' || c == '\r') {
            c = ' ';
        }
    }
    while (!s.empty() && s.back() == ' ') {
        s.pop_back();
    }
    return s;
}

} // namespace

int runCli(int argc, char** argv)
{
    std::set_terminate(lastResortTerminate);
    CLI::App app{"replica: shows a reflective surface on a self-luminous display as it would look "
                 "in the real light in front of it"};
    app.require_subcommand(1);
    // Subcommands hand options they do not know to the top level: --log-level goes anywhere.
    app.fallthrough();
    // CLI11's default adds a second line ("Run with --help ..."): one line instead.
    app.failure_message([](const CLI::App*, const CLI::Error& e) {
        return fmt::format("replica: {}; see 'replica --help'\n", oneLine(e.what()));
    });
    app.set_version_flag("--version", versionString());
    std::string logLevel = "info";
    auto* logOpt = app.add_option("--log-level", logLevel,
                                  "log level for every logger (trace, debug, info, warn, error, "
                                  "critical, off), or per logger as 'hal.tracker=debug,rec=info'; "
                                  "$REPLICA_LOG does the same, and this option wins over it")
                           ->check(CLI::Validator([](std::string& s) { return checkLogSpec(s); },
                                                  "", "LEVELS"))
                           ->capture_default_str();

    int exitCode = 0;
    registerRunCommand(app, exitCode);
    registerReplayCommand(app, exitCode);
    registerInspectCommand(app, exitCode);
    registerRenderCommand(app, exitCode);
    registerPlanCommand(app, exitCode);
    registerBoothCommand(app, exitCode);
    registerSceneCommand(app, exitCode);
    registerDisplayCommand(app, exitCode);
    registerRecoverCommand(app, exitCode);
    registerColorCommand(app, exitCode);
    registerSpectralCommand(app, exitCode);
    registerProbeCommand(app, exitCode);
    registerCalibrateCommand(app, exitCode);
    registerConfigCommand(app, exitCode);
    registerFiguresCommand(app, exitCode);
    requireFiniteFloats(app);

    app.parse_complete_callback([&] {
        if (const char* env = std::getenv("REPLICA_LOG"); env != nullptr) {
            if (const std::string bad = checkLogSpec(env); !bad.empty()) {
                throw CLI::ValidationError("REPLICA_LOG", bad);
            }
        }
        setupLogging(logLevel, logOpt->count() > 0);
        // Unknown keys in a JSON file Replica reads: one warning each, on the pipeline logger.
        jsonWarningSink() = [](const std::string& w) { logger("pipeline")->warn("{}", w); };
    });
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e) == 0 ? 0 : kExitUsage;
    } catch (const std::exception& e) {
        // The last resort: every known bad input has its own line before this; whatever else
        // escapes is one line and exit 2, never an abort.
        std::fprintf(stderr,
                     "replica: internal error: %s; this is a bug, please report it with "
                     "the command line\n",
                     oneLine(e.what()).c_str());
        return kExitUsage;
    }
    return exitCode;
}

} // namespace replica::platform
