// Faults injected into the sensor sources for soak tests ('replica run --inject-faults'): NaN
// head poses, saturated spectra, and unplugged devices (no samples for a while, so the loop sees
// the sequence gap and counts the drop). The faulty samples are what gets recorded, so a replay
// reproduces them.
#pragma once

#include <cstdint>
#include <string>

#include <pipeline/base/expected.h>
#include <platform/appliance.h>

namespace replica::platform {

struct FaultPlan {
    std::uint32_t nanPoseEvery = 0;  // every Nth pose has a NaN eye (0: never)
    std::uint32_t saturateEvery = 0; // every Nth spectrum is saturated, all counts at 65535
    double unplugEveryS = 0.0;       // the spectrometer and tracker are unplugged for
    double unplugForS = 0.0;         // unplugForS out of every unplugEveryS (0: never)
    bool any() const { return nanPoseEvery > 0 || saturateEvery > 0 || unplugEveryS > 0.0; }
};

// "nan-pose=N,saturate=N,unplug=EVERY_S/FOR_S", any subset, e.g. "nan-pose=50,unplug=60/5".
Expected<FaultPlan> parseFaultPlan(const std::string& spec);

// Wraps the sources so that they deliver the plan's faults.
void injectFaults(Sources& sources, const FaultPlan& plan);

} // namespace replica::platform
