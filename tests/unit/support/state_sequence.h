// Hand-made frames through the state stage (state/): what the estimators give the renderer for a
// sequence of sensed tilts, eyes and lights, without spectra or gravity samples. The light counts
// as changed as the light estimator sees it; the held and diffuse tilts come from the tilt
// estimator; the encoding from the re-encode decision (a light-adaptive encoder only).
#pragma once

#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include <state/light_estimator.h>
#include <state/tilt_estimator.h>

#include <pipeline/scene/scene_state.h>

namespace replica::tests {

class StateSequence
{
public:
    explicit StateSequence(int cacheSlices = 1,
                           state::EncodingDecision encoding = {},
                           double tiltNodesRad = 0.0)
        : tilt_({0.0, cacheSlices, tiltNodesRad}), encoding_(std::move(encoding))
    {}

    // The next frame: 'st' with its lamp (or illuminant and luminance), eye and sensed tilt set.
    pipeline::scene::SceneState next(pipeline::scene::SceneState st)
    {
        // Changed as the light estimator says it: by the light's content key.
        const std::uint64_t key = pipeline::scene::lightKey(st);
        st.lightChanged = first_ || key != lastKey_;
        first_ = false;
        lastKey_ = key;
        encoding_.write(st);
        tilt_.sense(st.tiltRad);
        tilt_.write(st);
        return st;
    }
    pipeline::scene::SceneState next(double tiltRad, glm::dvec3 eye, int lamp = 2)
    {
        pipeline::scene::SceneState st;
        st.lampIndex = lamp;
        st.tiltRad = tiltRad;
        st.eyeBoothM = eye;
        return next(st);
    }

private:
    state::TiltEstimator tilt_;
    state::EncodingDecision encoding_;
    bool first_ = true;
    std::uint64_t lastKey_ = 0;
};

} // namespace replica::tests
