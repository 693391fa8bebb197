// The 'replica' command line: subcommands registered by platform/cli/*_command.cpp.
#pragma once

namespace replica::platform {

// Parses arguments and runs the chosen subcommand. Exit codes: 0 success, 1 failure, 2 usage error,
// 3 succeeded with loss.
int runCli(int argc, char** argv);

} // namespace replica::platform
