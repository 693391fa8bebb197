// Hand-made frames through the state stage (state/): what the estimators give the renderer for a
// sequence of sensed tilts, eyes and lights, without spectra or gravity samples. The light counts
// as changed as the light estimator sees it; the held and diffuse tilts come from the tilt
// estimator; the encoding from the re-encode decision (a light-adaptive encoder only).
#pragma once

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
    explicit StateSequence(int cacheSlices = 1, state::EncodingDecision encoding = {})
        : tilt_({0.0, cacheSlices}), encoding_(std::move(encoding))
    {}

    // The next frame: 'st' with its lamp (or illuminant and luminance), eye and sensed tilt set.
    pipeline::scene::SceneState next(pipeline::scene::SceneState st)
    {
        st.lightChanged =
                first_ || st.lampIndex != last_.lampIndex ||
                (st.lampIndex < 0 && (st.illuminant.v != last_.illuminant.v ||
                                      st.emitterLuminanceCdM2 != last_.emitterLuminanceCdM2));
        first_ = false;
        last_ = st;
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
    pipeline::scene::SceneState last_;
};

} // namespace replica::tests
