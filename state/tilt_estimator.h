// The tilt estimator: gravity -> the panel's tilt (the specular term's, each sample), and the tilt
// of the booth pass's cached diffuse term: a hold filter against sensor noise, then the sliced
// refresh that spreads a new held tilt's recomputation over K frames. Both are state, not render:
// the renderer draws what SceneState names, so a frame is a function of its SceneState.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include <nlohmann/json_fwd.hpp>
#include <state/tilt_noise.h>

#include <hal/samples.h>
#include <pipeline/base/expected.h>
#include <pipeline/scene/scene_state.h>

namespace replica::state {

// The cached diffuse term's tilt is the mean of the last kTiltWindow sensed tilts (the
// accelerometer's 0.02 m/s^2 noise is 0.12 degrees a sample, 0.03 degrees in the mean), re-taken
// when it moves more than kTiltHoldRad: 0.15 degrees, 3.5 standard deviations of the difference
// of two such means, so noise alone almost never recomputes the cache. Holding the diffuse term
// 0.15 degrees off costs at most ΔE00 p95 0.25 at a 5-degree tilt (the ceiling light grazes the
// panel there; the painting's relief) and 0.11 from 20 degrees up, on every shipped scene and
// light (CPU model, tilt_cost_test.cpp; docs/rendering.md): about what one sample's noise costs.
//
// The mean lags a panel that is moving: by half the window (8 frames: 0.8 s at 10 Hz, where the
// error probe saw the diffuse term 15 degrees behind under the simulator's sweep). So a sensed tilt
// more than kTiltMotionRad from the window's mean (0.5 degrees: 4 standard deviations of one
// sample's noise about the mean, about once in 5 minutes at 60 Hz on noise alone) is motion: the
// window starts again from that tilt and the held tilt is re-taken at it.
constexpr std::size_t kTiltWindow = 16;
constexpr double kTiltHoldRad = 0.15 * 3.14159265358979323846 / 180.0;
constexpr double kTiltMotionRad = 0.5 * 3.14159265358979323846 / 180.0;
// The most the diffuse term shown may lag the held tilt before it is drawn whole at once rather
// than waiting for a sliced refresh (scene::nextDiffuse): 2 degrees. At 60 Hz the simulator's
// fastest sweep (18 degrees a second) lags at most 1.5 degrees with K = 3, so the bound never
// costs a 60 Hz frame a whole draw; at 10 Hz every other frame is drawn whole. The lag's price
// is linear (docs/rendering.md: ΔE00 p95 0.36 per half degree on the flat scenes from 20 degrees
// up), so 2 degrees is about 1.4 at most; the error probe measured p95 0.45-1.33 at 10 Hz on the
// ColorChecker with this bound, against 0.6-13.6 with the 16-frame mean alone.
constexpr double kDiffuseMaxLagRad = 2.0 * 3.14159265358979323846 / 180.0;
// A refresh takes K frames to show and is then shown for K more, so on a moving panel a refresh
// aimed at the held tilt shows a term K to 2K - 1 frames old, and the lag bound above draws whole
// whenever that passes 2 degrees (with K = 3, from 0.34 degrees a frame: the painting's 40 frames a
// second under the simulator's 18-degree sweep). A refresh started while the panel moves is aimed
// where the panel will be in the middle of the frames it is shown, (3K - 3) / 2 frames ahead at
// the sensed tilts' trend: the least-squares slope of the last kTiltTrend sensed tilts (0.029
// degrees a frame of noise at 0.12 a sample), followed only when that travel is past the motion
// threshold (six times its noise: a still panel never extrapolates), and never further than the
// lag bound.
constexpr std::size_t kTiltTrend = 6;
// The figures above are for the design's 0.12-degree sensor. A noisier one (a cheaper part, a
// stand that hums) crossed the fixed thresholds on noise alone, restarted the window at single
// samples and re-took the held tilt at one of them: at 0.5 degrees a sample the held tilt was no
// steadier than a sample (it moved on 749 of 1200 frames). So once the noise measured (TiltNoise)
// passes kTiltNoiseFitRad the thresholds are as many standard deviations of it as the fixed ones
// are of the design's: the motion threshold 4 of a sample about the window's mean (sigma
// sqrt(17/16)), the hold 3.5 of the difference of two means (sigma sqrt(2/16)). Up to it the fixed
// ones stay: the estimate of a design sensor scatters up to 1.3 times its noise, and 0.18 degrees
// (1.5 times the design's) keeps its thresholds, and the simulator's frames, as they were.
constexpr double kTiltNoiseFitRad = 0.18 * 3.14159265358979323846 / 180.0;
constexpr double kTiltMotionSigmas = 4.0;
constexpr double kTiltHoldSigmas = 3.5;

struct TiltEstimatorSetup {
    double defaultTiltRad = 0.0; // shown until the first usable sample
    // RenderSettings::cacheSlices: a new held tilt is drawn in this many bands, one a frame.
    int cacheSlices = 1;
    // RenderSettings::tiltNodesRad: above 0, the diffuse term is cached at tilt nodes this far
    // apart and interpolated (scene::nextDiffuseNodes); 0, the sliced refresh of the held tilt.
    double tiltNodesRad = 0.0;
};

class TiltEstimator
{
public:
    explicit TiltEstimator(TiltEstimatorSetup setup);

    void update(const hal::AccelSample* accel);
    // A sensed tilt from elsewhere (a test, a tool): what update() does with a usable sample.
    void sense(double tiltRad)
    {
        tilt_ = tiltRad;
        haveTilt_ = true;
        noise_.add(tiltRad);
    }
    // The frame's tilts: the sensed one, the held one (re-taken when the light changed, since
    // the renderer then draws the diffuse term whole anyway) and the diffuse term's.
    void write(pipeline::scene::SceneState& state);

    bool sensed() const { return haveTilt_; }
    std::uint64_t rejectedTilts() const { return rejected_; }
    // The sensor's tilt noise measured so far (radians a sample; 0 before 256 samples), and the
    // motion and hold thresholds it sets.
    double noiseRad() const { return noise_.sigmaRad(); }
    double motionThresholdRad() const;
    // Whether the noise measured is past kTiltNoiseFitRad (the thresholds then follow it).
    bool noisierThanDesign() const;
    double holdThresholdRad() const;
    // Why the last refused reading was refused ("" before the first).
    const std::string& lastRefusal() const { return lastRefusal_; }

    nlohmann::json save() const;
    Expected<void> restore(const nlohmann::json& j);

private:
    TiltEstimatorSetup setup_;
    double tilt_;
    std::optional<std::uint32_t> lastAccel_;
    bool haveTilt_ = false;
    std::uint64_t rejected_ = 0;
    std::string lastRefusal_;
    TiltNoise noise_;
    // The hold filter.
    std::array<double, kTiltWindow> window_{};
    std::size_t next_ = 0;
    std::size_t count_ = 0;
    double held_ = 0.0;
    bool heldValid_ = false;
    // The last kTiltTrend finite sensed tilts, oldest first once full (trendCount_ of them).
    std::array<double, kTiltTrend> trend_{};
    std::size_t trendCount_ = 0;
    // The diffuse term of the last frame (none before the first):
    // pipeline/scene/diffuse_schedule.h.
    std::optional<pipeline::scene::DiffuseTilt> diffuse_;
    // With tilt nodes, what the cache holds instead (none before the first frame).
    std::optional<pipeline::scene::DiffuseNodes> nodes_;

    double windowMean() const;
    // The sensed tilts' trend, radians a frame (none until kTiltTrend of them).
    std::optional<double> trendSlope() const;
    // Where a refresh started this frame aims: the held tilt, or ahead of it on a moving panel.
    double refreshTarget() const;
    // With tilt nodes: the way the panel moves (-1, 0 still, +1), where the next node is drawn.
    int nodeDirection() const;
};

} // namespace replica::state
