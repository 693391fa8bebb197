// Turns the latest sensor samples into the scene state: spectrum -> classified lamp (or the sensed
// light itself), tracker pose -> eye in the booth frame, gravity -> screen tilt. Holds the last
// good value of each when a sample is missing, untracked or undefined.
#pragma once

#include <cstdint>
#include <optional>

#include <glm/vec3.hpp>

#include <hal/samples.h>
#include <pipeline/base/expected.h>
#include <pipeline/base/rigid_transform.h>
#include <pipeline/scene/booth.h>
#include <pipeline/scene/calibration.h>
#include <pipeline/scene/scene_state.h>
#include <pipeline/spectral/light_classifier.h>
#include <pipeline/spectral/spectrometer_chain.h>
#include <platform/loop/lamp_arbiter.h>

namespace replica::platform {

struct SceneUpdaterSetup {
    pipeline::booth::Booth booth;
    pipeline::spectral::SpectrometerCalibration calibration;
    // T_booth_tracker: eye_booth = trackerInBooth.apply(eye_tracker). Default: the fixed
    // mounting (pipeline/base/rigid_transform.h).
    pipeline::RigidTransform trackerInBooth = pipeline::defaultTrackerInBooth();
    // Shown until each sensor's first usable sample: a booth lamp index (-1: no light), the eye
    // and the tilt.
    int defaultLamp = -1;
    glm::dvec3 defaultEyeM{0.0, 0.45, 0.60};
    double defaultTiltRad = 0.0;
};

class SceneUpdater
{
public:
    // The booth's lamps become the classifier's stored lights, named as in the booth, with the full
    // hysteresis of 'params' (pipeline/spectral/light_classifier.h): a lamp must win
    // params.confirmSamples spectra in a row before it replaces the current answer, also at start,
    // so the first spectra render in direct-sensor mode. A booth without lamps is always in
    // direct-sensor mode. Fails for a lamp without energy or thresholds out of order.
    static Expected<SceneUpdater>
    create(SceneUpdaterSetup setup, const pipeline::spectral::LightClassifierParams& params = {});

    // Updates state from whichever samples are present (nullptr = none yet). A sample is used once:
    // the same sequence number again changes nothing. Unusable samples are counted and skipped.
    // The lamp selector, when there is one, is reconciled with the classifier by LampArbiter.
    void update(pipeline::scene::SceneState& state,
                const hal::SpectrumSample* spectrum,
                const hal::PoseSample* pose,
                const hal::AccelSample* accel,
                const hal::LampSample* selector = nullptr);

    // Counts of samples ignored because they could not be used.
    std::uint64_t rejectedSpectra() const { return rejectedSpectra_; }
    std::uint64_t rejectedPoses() const { return rejectedPoses_; }
    std::uint64_t rejectedTilts() const { return rejectedTilts_; }

    // The classifier's current answer (name "unknown" in direct-sensor mode).
    pipeline::spectral::Classification classification() const;
    const LampArbiter& lampArbiter() const { return arbiter_; }
    // The tracker's pose in the booth (T_booth_tracker).
    const pipeline::RigidTransform& trackerInBooth() const { return setup_.trackerInBooth; }

private:
    SceneUpdater(SceneUpdaterSetup setup,
                 std::optional<pipeline::spectral::LightClassifier> classifier)
        : setup_(std::move(setup)), classifier_(std::move(classifier)),
          arbiter_(static_cast<int>(setup_.booth.lights.size()))
    {}
    void showLamp(pipeline::scene::SceneState& state, int lamp) const;
    void start(pipeline::scene::SceneState& state);

    SceneUpdaterSetup setup_;
    std::optional<pipeline::spectral::LightClassifier> classifier_; // none: no lamps
    std::optional<std::uint32_t> lastSpectrum_;
    std::optional<std::uint32_t> lastPose_;
    std::optional<std::uint32_t> lastAccel_;
    LampArbiter arbiter_;
    std::optional<std::uint32_t> lastSelector_;
    std::uint64_t rejectedSpectra_ = 0;
    std::uint64_t rejectedPoses_ = 0;
    std::uint64_t rejectedTilts_ = 0;
    bool started_ = false;
    bool haveSpectrum_ = false;
    bool havePose_ = false;
    bool haveTilt_ = false;
};

} // namespace replica::platform
