// Where 'replica run' takes each device's samples from: --hal's default, overridden per device,
// and the sources built for that choice (simulated, replayed, live, or a mix).
#pragma once

#include <algorithm>
#include <map>
#include <string>

#include <hal/clock.h>
#include <pipeline/base/expected.h>
#include <platform/appliance.h>
#include <platform/cli/run_options.h>
#include <recordings/device_kind.h>

namespace replica::platform::run_cli {

// Where each device kind's source comes from (kind name -> "live", "opentrack", "hid", "gpio",
// "sim", "sim-miswired", "replay" or "none").
struct DeviceChoice {
    std::map<std::string, std::string> from;
    const std::string& of(const recordings::DeviceKindBase& kind) const
    {
        static const std::string kNone = "none";
        const auto it = from.find(kind.name());
        return it != from.end() ? it->second : kNone;
    }
    static bool isSim(const std::string& v) { return v.rfind("sim", 0) == 0; }
    static bool isLive(const std::string& v) { return v != "none" && v != "replay" && !isSim(v); }
    template <typename Pred>
    bool any(Pred p) const
    {
        return std::any_of(from.begin(), from.end(), [&p](const auto& e) { return p(e.second); });
    }
    bool anyLive() const { return any(isLive); }
    bool anyReplay() const
    {
        return any([](const std::string& v) { return v == "replay"; });
    }
    bool anySim() const { return any(isSim); }
};

// Each device's source: --hal gives the default, --spectrometer/--tracker/--accel/--lamp-selector
// override it per device. Usage errors come back as InvalidArgument.
Expected<DeviceChoice> chooseDevices(const RunOptions& o);

// The sources of chooseDevices' choice; live devices stamp their samples on 'liveClock'.
Expected<Sources>
makeRunSources(const RunOptions& o, const Appliance& appliance, const hal::Clock& liveClock);

} // namespace replica::platform::run_cli
