// Builds the 'replica' command line from the registered subcommands and maps outcomes to exit
// codes.
#include <cstdio>

#include <CLI/CLI.hpp>

#include <platform/cli/app.h>
#include <platform/cli/commands.h>
#include <platform/logging.h>
#include <platform/version.h>

namespace replica::platform {

int runCli(int argc, char** argv)
{
    CLI::App app{"replica: shows a reflective surface on a self-luminous display as it would look "
                 "in the real light in front of it"};
    app.require_subcommand(1);
    app.set_version_flag("--version", versionString());
    std::string logLevel = "info";
    app.add_option("--log-level", logLevel,
                   "log level for every logger (trace, debug, info, warn, error), or per logger as "
                   "'hal.tracker=debug,rec=info'; $REPLICA_LOG does the same")
            ->capture_default_str();

    int exitCode = 0;
    registerRunCommand(app, exitCode);
    registerReplayCommand(app, exitCode);
    registerInspectCommand(app, exitCode);
    registerRenderCommand(app, exitCode);
    registerBoothCommand(app, exitCode);
    registerSceneCommand(app, exitCode);
    registerDisplayCommand(app, exitCode);
    registerRecoverCommand(app, exitCode);
    registerColorCommand(app, exitCode);
    registerSpectralCommand(app, exitCode);
    registerProbeCommand(app, exitCode);
    registerConfigCommand(app, exitCode);

    app.parse_complete_callback([&] { setupLogging(logLevel); });
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e) == 0 ? 0 : kExitUsage;
    }
    return exitCode;
}

} // namespace replica::platform
