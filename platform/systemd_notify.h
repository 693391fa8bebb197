// Talking to systemd when it runs us as a Type=notify service: READY=1 once the first frame is on
// the screen, WATCHDOG=1 from the frame loop (so a hung GL driver gets the service restarted),
// STATUS= lines for 'systemctl status'. Outside systemd (no $NOTIFY_SOCKET) every call does
// nothing.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>

namespace replica::platform {

class SystemdNotifier
{
public:
    SystemdNotifier();

    // Whether systemd asked for watchdog pings (WatchdogSec= set for this process).
    bool watchdogEnabled() const { return watchdogUs_ > 0; }
    // Call once per frame: the first call says READY=1, then a WATCHDOG=1 at most every quarter
    // of the watchdog interval (a 60 Hz loop would otherwise send 60 datagrams a second).
    // 'everyNthTick': the loop's steady cadence (platform/loop/cadence.h), said in the status
    // when it is not every tick.
    void frameShown(std::uint64_t frames, std::uint64_t skippedTicks, int everyNthTick = 1);
    void stopping();

private:
    void send(const std::string& message);

    std::uint64_t watchdogUs_ = 0;
    bool ready_ = false;
    std::chrono::steady_clock::time_point lastPing_{};
};

} // namespace replica::platform
