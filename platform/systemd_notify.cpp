// sd_notify through libsystemd (when built with it).
#include <cstdlib>
#include <ctime>
#include <optional>
#include <sstream>
#include <string>

#include <fmt/format.h>
#include <unistd.h>

#include <pipeline/base/input_file.h>
#include <platform/logging.h>
#include <platform/systemd_notify.h>

#ifdef REPLICA_HAVE_LIBSYSTEMD
#include <systemd/sd-daemon.h>
#endif

namespace replica::platform {
namespace {

// Seconds since this process was started (exec), from /proc/self/stat's start time (clock ticks
// since boot) and CLOCK_BOOTTIME: what a visitor waits from the service's start to the first
// frame, dynamic linking included. Nullopt where /proc cannot say.
std::optional<double> secondsSinceProcessStart()
{
    // A line of a few hundred bytes; through the bounded reader like every other file.
    const std::string stat =
            readInputFile("/proc/self/stat", 4096, "process status").value_or(std::string());
    const auto paren = stat.rfind(')'); // the command name may hold spaces and parentheses
    const long ticks = ::sysconf(_SC_CLK_TCK);
    timespec now{};
    if (paren == std::string::npos || ticks <= 0 || ::clock_gettime(CLOCK_BOOTTIME, &now) != 0) {
        return std::nullopt;
    }
    std::istringstream fields(stat.substr(paren + 2));
    std::string field;
    for (int i = 3; i <= 22 && fields >> field; ++i) { // field 22: starttime
    }
    try {
        const double started = std::stod(field) / static_cast<double>(ticks);
        return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec) - started;
    } catch (const std::exception&) {
        return std::nullopt;
    }
}

} // namespace

SystemdNotifier::SystemdNotifier()
{
#ifdef REPLICA_HAVE_LIBSYSTEMD
    std::uint64_t us = 0;
    if (sd_watchdog_enabled(0, &us) > 0) {
        watchdogUs_ = us;
        logger("replica")->info("systemd watchdog: {} s; pinged from the frame loop",
                                static_cast<double>(us) * 1e-6);
    }
#endif
}

void SystemdNotifier::send(const std::string& message)
{
#ifdef REPLICA_HAVE_LIBSYSTEMD
    sd_notify(0, message.c_str());
#else
    (void)message;
#endif
}

void SystemdNotifier::frameShown(std::uint64_t frames, std::uint64_t skippedTicks, int everyNthTick)
{
    const auto now = std::chrono::steady_clock::now();
    const auto status = [&] {
        return fmt::format("STATUS={} frames shown, {} late ticks skipped{}", frames, skippedTicks,
                           everyNthTick > 1
                                   ? fmt::format(", drawing 1 tick in {} (frames longer than "
                                                 "the period)",
                                                 everyNthTick)
                                   : std::string());
    };
    if (!ready_) {
        ready_ = true;
        if (const auto s = secondsSinceProcessStart()) {
            logger("replica")->info("first frame shown {:.2f} s after the process started", *s);
        }
        lastPing_ = now;
        send("READY=1\n" + status() + (watchdogEnabled() ? "\nWATCHDOG=1" : ""));
        return;
    }
    if (watchdogEnabled() && now - lastPing_ >= std::chrono::microseconds(watchdogUs_ / 4)) {
        lastPing_ = now;
        send("WATCHDOG=1\n" + status());
    }
}

void SystemdNotifier::stopping()
{
    send("STOPPING=1");
}

} // namespace replica::platform
