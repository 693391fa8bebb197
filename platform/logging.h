// Named spdlog loggers per area (hal.spectrometer, hal.tracker, hal.accel, pipeline, render,
// output, rec, loop) and the --log-level / $REPLICA_LOG knob.
#pragma once

#include <memory>
#include <string>

#include <spdlog/spdlog.h>

namespace replica::platform {

// Creates the area loggers (writing to stderr) and applies levels from spec and $REPLICA_LOG.
// spec is a level name for all loggers, or 'name=level,name=level'.
void setupLogging(const std::string& spec);

// The logger for an area; created on first use if setupLogging has not run.
std::shared_ptr<spdlog::logger> logger(const std::string& area);

} // namespace replica::platform
