// The sources the appliance's loop reads when no device is live: the simulated sensors playing
// the scripted scenario, or exactly what a recording holds.
#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <iterator>
#include <numbers>
#include <span>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <hal/replay/replay_source.h>
#include <hal/sim/sim_devices.h>
#include <pipeline/base/data_dir.h>
#include <pipeline/base/input_file.h>
#include <pipeline/booth/booth_model.h>
#include <pipeline/colour/spectral_table.h>
#include <pipeline/display/display_inverse.h>
#include <pipeline/display/display_profile.h>
#include <pipeline/display/nominal_display.h>
#include <pipeline/render/gles_renderer.h>
#include <pipeline/shading/realtime_model.h>
#include <pipeline/spectral/adaptive_encoding.h>
#include <pipeline/spectral/representation_catalogue.h>
#include <platform/appliance.h>
#include <platform/booth_dimmer.h>
#include <platform/logging.h>
#include <platform/loop/frame_digest.h>
#include <platform/run_config_schema.h>

namespace replica::platform {

Expected<std::vector<hal::sim::SimLamp>> simLamps(const pipeline::booth::Booth& booth)
{
    std::vector<hal::sim::SimLamp> lamps;
    for (const auto& lamp : booth.lights) {
        auto table = pipeline::colour::loadSpectralCsv(dataDir() / "spectra" / lamp.referenceFile);
        if (!table) {
            return tl::unexpected(table.error());
        }
        auto power = table->values(lamp.referenceColumn);
        if (!power) {
            return tl::unexpected(power.error());
        }
        lamps.push_back({lamp.name, table->wavelengthNm, std::move(*power)});
    }
    return lamps;
}

Expected<Sources> makeSimSources(const Appliance& appliance, const std::string& lampSelector)
{
    if (lampSelector != "none" && lampSelector != "sim" && lampSelector != "sim-miswired") {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("--lamp-selector {}: expected none, sim or sim-miswired",
                                     lampSelector));
    }
    hal::sim::ScenarioParams scenario;
    scenario.lampCount = static_cast<int>(appliance.booth.lights.size());

    hal::sim::SimSpectrometerParams spec;
    auto lamps = simLamps(appliance.booth);
    if (!lamps) {
        return tl::unexpected(lamps.error());
    }
    spec.lamps = std::move(*lamps);
    auto cal = pipeline::spectral::loadSpectrometerCalibration(
            dataDir() / appliance.config.spectrometerCalibration);
    if (!cal) {
        return tl::unexpected(cal.error());
    }
    spec.responsivityNm = cal->wavelengthNm;
    spec.responsivity = cal->responsivity;

    Sources s;
    s.set(recordings::spectrometerKind(), hal::sim::makeSimSpectrometer(scenario, std::move(spec)));
    s.set(recordings::trackerKind(), hal::sim::makeSimTracker(scenario, {}));
    s.set(recordings::accelKind(), hal::sim::makeSimAccel(scenario, {}));
    if (lampSelector != "none") {
        hal::sim::SimLampSelectorParams selector;
        if (lampSelector == "sim-miswired") {
            selector.wiring = {0, 2, 1};
        }
        s.set(recordings::lampSelectorKind(), hal::sim::makeSimLampSelector(scenario, selector));
    }
    return s;
}

Sources makeReplaySources(const recordings::Recording& recording,
                          const recordings::DeviceKinds& kinds)
{
    Sources s;
    for (const auto* kind : kinds) {
        const auto* samples = recording.samplesOf(*kind);
        const auto& info = recording.session.device(*kind);
        // An optional device the session did not have (no model, no samples) gets no source.
        if (kind->names().optional && info.model.empty() && recording.count(*kind) == 0) {
            continue;
        }
        s.set(*kind,
              kind->replaySource(info, samples != nullptr ? *samples : kind->emptySamples()));
    }
    return s;
}

} // namespace replica::platform
