// Named spdlog loggers per area (hal.spectrometer, hal.tracker, hal.accel, pipeline, render,
// output, rec, loop, hal.lamp) and the --log-level / $REPLICA_LOG knob. On a terminal or a file
// each line is "[time] [area] [level] message"; under systemd, when $JOURNAL_STREAM says stderr is
// the journal, each line goes to the journal with its priority and the area as fields (see
// docs/appliance.md, "Logs").
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <string>

#include <spdlog/spdlog.h>

namespace replica::platform {

// Creates the area loggers (writing to stderr, or to the journal) and applies levels: info, then
// $REPLICA_LOG, then spec when it came from the command line (which wins). spec is a level name for
// all loggers, or 'name=level,name=level'; both must have passed checkLogSpec.
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

// One warning or error of this process, as every recording holds it (/replica/log).
struct LoggedMessage {
    std::chrono::steady_clock::time_point time;
    spdlog::level::level_enum level = spdlog::level::warn;
    std::string area;
    std::string message;
};

// The process keeps its warnings and errors from the first setupLogging on (the newest
// kLogHistoryLimit of them), so that a recording opened later still holds those logged before it
// (--uncalibrated's, a site file's, start-up recovery's).
constexpr std::size_t kLogHistoryLimit = 1000;

// Calls `follower` with each warning and error kept so far, oldest first, then with each new one
// as it is logged, until the returned handle is destroyed; none is missed or repeated. It runs
// under the history's lock, on the thread that logs: it must not log.
using LogFollower = std::function<void(const LoggedMessage&)>;
std::shared_ptr<void> followLogs(LogFollower follower);

// True when $JOURNAL_STREAM's value ("DEVICE:INODE", which systemd sets for a service whose
// stderr it connected to the journal) names the file open on fd; false for an empty, malformed or
// other file's value (a child whose stderr was redirected keeps the variable, not the stream).
bool journalStreamIs(const char* journalStream, int fd);

// The syslog priority the journal files a line of this level under (error 3, warning 4, info 6,
// debug and trace 7, critical 2).
int journalPriority(spdlog::level::level_enum level);

// A line for a journal stream when the native protocol is unavailable: "<PRIORITY>[area] message\n"
// (journald reads the priority from the prefix, sd-daemon(3)).
std::string journalStreamLine(spdlog::level::level_enum level,
                              const std::string& area,
                              const std::string& message);

} // namespace replica::platform
