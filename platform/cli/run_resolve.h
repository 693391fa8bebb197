// What 'replica run' resolves before it opens a device, in one place: 'run' (the kiosk included)
// and 'replica config check' call the same function, so that a site file the check accepts is
// one the kiosk starts with, and one it refuses is refused by both in the same words.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <tl/expected.hpp>

#include <platform/cli/run_options.h>
#include <platform/site_config.h>

namespace replica::platform::run_cli {

// Why a run does not start: the lines to show and the exit code (kExitConfig for the site file,
// each line "FILE:LINE: key: what"; kExitUsage for the command line).
struct Refusal {
    int code = 2;
    std::vector<std::string> lines;
    // The site file's first problem (the service screen shows it); key empty: none.
    SiteProblem problem;
    // Where the kiosk shows its service screen: the output the options resolved so far name (a
    // site file's good values included), its frame size, and whether the run was to go on until
    // stopped.
    OutputChoice output;
    std::string size;
    std::string siteFile;
    bool endless = false;
};

template <typename T>
using Resolved = tl::expected<T, Refusal>;

// A problem with an option's value: the site file's (FILE:LINE: key: "value": what, exit 78)
// when the site file gave it, else the command line's (OPTION VALUE: what, exit cliCode: 2 for a
// malformed value, 1 for a file or device spec that does not load).
Refusal refuse(const RunOptions& o,
               const std::string& option,
               const std::string& siteKey,
               const std::string& value,
               const std::string& what,
               int cliCode = 2);

// The run as resolved: the command line over the site file, the frame size, the run
// configuration and the output.
struct RunPlan {
    RunOptions options;
    std::pair<int, int> size{0, 0};
    RunConfig config;
    OutputChoice output;
};

// The site file (--config, or with --kiosk the installed one), its values under the command
// line's, the usage checks, the run configuration, and everything the appliance and the devices
// will read, without opening a device: the booth and its lamp names (the default lamp, one GPIO
// line per lamp), the display profile, the scene, the accelerometer axes, the tracker's bind
// address, the frame size and the log spec.
Resolved<RunPlan> resolveRun(RunOptions o);

} // namespace replica::platform::run_cli
