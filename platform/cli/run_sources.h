// Where 'replica run' takes each device's samples from: --hal's default, overridden per device,
// and the sources built for that choice (simulated, replayed, live, or a mix).
#pragma once

#include <string>

#include <hal/clock.h>
#include <pipeline/base/expected.h>
#include <platform/appliance.h>
#include <platform/cli/run_options.h>

namespace replica::platform::run_cli {

struct DeviceChoice {
    std::string spectrometer;
    std::string tracker;
    std::string accel;
    std::string lampSelector;
    bool anyLive() const;
    bool anyReplay() const;
    bool anySim() const;
};

// Each device's source: --hal gives the default, --spectrometer/--tracker/--accel/--lamp-selector
// override it per device. Usage errors come back as InvalidArgument.
Expected<DeviceChoice> chooseDevices(const RunOptions& o);

// The sources of chooseDevices' choice; live devices stamp their samples on 'liveClock'.
Expected<Sources>
makeRunSources(const RunOptions& o, const Appliance& appliance, const hal::Clock& liveClock);

} // namespace replica::platform::run_cli
