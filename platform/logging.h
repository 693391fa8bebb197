// Named spdlog loggers per area (hal.spectrometer, hal.tracker, hal.accel, pipeline, render,
// output, rec, loop, hal.lamp) and the --log-level / $REPLICA_LOG knob.
#pragma once

#include <functional>
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

// Calls `tap` with every message of `minLevel` or above from every area logger (and those created
// later) until the returned handle is destroyed, whatever level the console shows (a logger set
// above minLevel keeps that level on its console sink). `tap` may run on any thread that logs.
using LogTap = std::function<void(
        spdlog::level::level_enum level, const std::string& area, const std::string& message)>;
std::shared_ptr<void> tapLogs(spdlog::level::level_enum minLevel, LogTap tap);

} // namespace replica::platform
