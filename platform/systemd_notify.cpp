// sd_notify through libsystemd (when built with it).
#include <cstdlib>

#include <fmt/format.h>

#include <platform/logging.h>
#include <platform/systemd_notify.h>

#ifdef REPLICA_HAVE_LIBSYSTEMD
#include <systemd/sd-daemon.h>
#endif

namespace replica::platform {

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

void SystemdNotifier::frameShown(std::uint64_t frames, std::uint64_t skippedTicks)
{
    const auto now = std::chrono::steady_clock::now();
    const auto status = [&] {
        return fmt::format("STATUS={} frames shown, {} late ticks skipped", frames, skippedTicks);
    };
    if (!ready_) {
        ready_ = true;
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
