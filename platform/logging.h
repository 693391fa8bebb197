// Named spdlog loggers per area (hal.spectrometer, hal.tracker, hal.accel, pipeline, render,
// output, rec, loop, hal.lamp) and the --log-level / $REPLICA_LOG knob.
#pragma once

#include <memory>
#include <string>

#include <spdlog/spdlog.h>

namespace replica::platform {

// Creates the area loggers (writing to stderr) and applies levels: info, then $REPLICA_LOG, then
// spec when it came from the command line (which wins). spec is a level name for all loggers, or
// 'name=level,name=level'; both must have passed checkLogSpec.
void setupLogging(const std::string& spec, bool fromCommandLine);

// Empty when every level in spec is one of spdlog's names (trace, debug, info, warn, error,
// critical, off); else a one-line reason naming the bad level and the valid ones.
std::string checkLogSpec(const std::string& spec);

// The logger for an area; created on first use if setupLogging has not run.
std::shared_ptr<spdlog::logger> logger(const std::string& area);

} // namespace replica::platform
