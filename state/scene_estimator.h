// The state stage: the latest sensor samples -> the frame's SceneState, through three named
// estimators (light_estimator.h: spectrum chain, classifier, lamp selector, re-encode decision;
// eye_estimator.h: tracker pose -> booth; tilt_estimator.h: gravity -> tilt, the hold filter and
// the diffuse term's sliced refresh). Each holds the last good value when a sample is missing,
// untracked or undefined. The renderer keeps no history: what a frame needs is here.
//
// save()/restore(): the estimators' whole state as JSON, written at the head of each rotated
// session file (the run configuration's "state_at_start") so that the file replays alone, bit for
// bit, as the live run showed it.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>
#include <state/eye_estimator.h>
#include <state/light_estimator.h>
#include <state/tilt_estimator.h>

#include <hal/samples.h>
#include <pipeline/base/expected.h>
#include <pipeline/scene/scene_state.h>

namespace replica::state {

struct SceneEstimatorSetup {
    LightEstimatorSetup light;
    EyeEstimatorSetup eye;
    TiltEstimatorSetup tilt;
};

class SceneEstimator
{
public:
    // The booth's lamps become the classifier's stored lights, named as in the booth, with the full
    // hysteresis of setup.light.classifier (pipeline/spectral/light_classifier.h): a lamp must win
    // confirmSamples spectra in a row before it replaces the current answer, also at start, so the
    // first spectra render in direct-sensor mode. Fails for a lamp without energy or thresholds
    // out of order.
    static Expected<SceneEstimator> create(SceneEstimatorSetup setup);

    // Updates the estimators from whichever samples are present (nullptr = none yet; a sample is
    // used once: the same sequence number again changes nothing; unusable ones are counted and
    // skipped) and writes every field of 'state' but frameIndex and tickNs. The lamp selector,
    // when there is one, is reconciled with the classifier by LampArbiter.
    void update(pipeline::scene::SceneState& state,
                const hal::SpectrumSample* spectrum,
                const hal::PoseSample* pose,
                const hal::AccelSample* accel,
                const hal::LampSample* selector = nullptr);

    std::uint64_t rejectedSpectra() const { return light_.rejectedSpectra(); }
    std::uint64_t rejectedPoses() const { return eye_.rejectedPoses(); }
    std::uint64_t rejectedTilts() const { return tilt_.rejectedTilts(); }

    // The classifier's current answer (name "unknown" in direct-sensor mode).
    pipeline::spectral::Classification classification() const { return light_.classification(); }
    const LampArbiter& lampArbiter() const { return light_.lampArbiter(); }
    // The tracker's pose in the booth (T_booth_tracker).
    const pipeline::RigidTransform& trackerInBooth() const { return eye_.trackerInBooth(); }
    const LightEstimator& light() const { return light_; }
    const EyeEstimator& eye() const { return eye_; }
    const TiltEstimator& tilt() const { return tilt_; }

    // Whether the first frame has been estimated (before it, save() has nothing to say).
    bool started() const { return started_; }
    nlohmann::json save() const;
    // Fails with a one-line reason naming the estimator and the field.
    Expected<void> restore(const nlohmann::json& j);

private:
    SceneEstimator(SceneEstimatorSetup setup, LightEstimator light)
        : setup_(std::move(setup)), light_(std::move(light)), eye_(setup_.eye), tilt_(setup_.tilt)
    {}

    SceneEstimatorSetup setup_;
    LightEstimator light_;
    EyeEstimator eye_;
    TiltEstimator tilt_;
    bool started_ = false;
};

} // namespace replica::state
