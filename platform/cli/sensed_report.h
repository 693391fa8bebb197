// The end-to-end table from the sensed light, shared by 'replica display study --sensed' and
// 'replica spectral eval --sensed': each impairment of the simulated spectrometer turned off in
// turn, then the corrections, for every light.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include <pipeline/offline/display/colorchecker_study.h>

namespace replica::platform {

// The table's row that is the appliance's own chain (pipeline/spectral/live_chain.h, its defaults).
inline constexpr const char* kApplianceRow = "appliance: live chain (the kiosk's)";

struct SensedReportOptions {
    bool sensed = false;
    std::string mode = "direct";
    int draws = 20;
    std::uint64_t seed = 1;
    bool json = false;
};

// Adds --sensed, --mode, --draws, --sensed-seed to a command.
void addSensedOptions(CLI::App* cmd, SensedReportOptions& o);

// Prints the ablation table (or JSON). Returns the process exit code.
int sensedReport(const pipeline::display::DisplayInverse& inverse,
                 const std::function<glm::dvec3(const glm::dvec3&)>& panel,
                 const std::vector<pipeline::spectral::FineLight>& lights,
                 const pipeline::display::SensedSamples& samples,
                 double lux,
                 pipeline::display::FlareHandling flare,
                 const SensedReportOptions& o);

} // namespace replica::platform
