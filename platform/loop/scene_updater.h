// Turns the latest sensor samples into the scene state: spectrum -> classified lamp (or the sensed
// light itself), tracker pose -> eye in the booth frame, gravity -> screen tilt. Holds the last
// good value of each when a sample is missing, untracked or undefined.
#pragma once

#include <cstdint>
#include <optional>

#include <glm/vec3.hpp>

#include <hal/samples.h>
#include <pipeline/scene/booth.h>
#include <pipeline/scene/scene_state.h>
#include <pipeline/spectral/light_classifier.h>
#include <pipeline/spectral/spectrometer_chain.h>

namespace replica::platform {

struct SceneUpdaterSetup {
    pipeline::scene::Booth booth;
    pipeline::spectral::SpectrometerCalibration calibration;
    glm::dvec3 trackerInBoothM{0.0, 0.42, 0.05}; // tracker mounted on the stand's base, unrotated
};

class SceneUpdater
{
public:
    explicit SceneUpdater(SceneUpdaterSetup setup);

    // Updates state from whichever samples are present (nullptr = none yet). A sample is used once:
    // the same sequence number again changes nothing. Unusable samples are counted and skipped.
    void update(pipeline::scene::SceneState& state,
                const hal::SpectrumSample* spectrum,
                const hal::PoseSample* pose,
                const hal::AccelSample* accel);

    // Counts of samples ignored because they could not be used.
    std::uint64_t rejectedSpectra() const { return rejectedSpectra_; }
    std::uint64_t rejectedPoses() const { return rejectedPoses_; }
    std::uint64_t rejectedTilts() const { return rejectedTilts_; }

private:
    SceneUpdaterSetup setup_;
    pipeline::spectral::LightClassifier classifier_;
    std::optional<std::uint32_t> lastSpectrum_;
    std::optional<std::uint32_t> lastPose_;
    std::optional<std::uint32_t> lastAccel_;
    std::uint64_t rejectedSpectra_ = 0;
    std::uint64_t rejectedPoses_ = 0;
    std::uint64_t rejectedTilts_ = 0;
};

} // namespace replica::platform
