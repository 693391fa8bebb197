// The tilt estimator: gravity -> the panel's tilt (the specular term's, each sample), and the tilt
// of the booth pass's cached diffuse term: a hold filter against sensor noise, then the sliced
// refresh that spreads a new held tilt's recomputation over K frames. Both used to live inside the
// renderer; as state they make a frame a function of its SceneState.
#pragma once

#include <array>
#include <cstdint>
#include <optional>

#include <nlohmann/json_fwd.hpp>

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
// light (CPU model, booth_cache_test.cpp; docs/rendering.md): about what one sample's noise costs.
constexpr std::size_t kTiltWindow = 16;
constexpr double kTiltHoldRad = 0.15 * 3.14159265358979323846 / 180.0;

struct TiltEstimatorSetup {
    double defaultTiltRad = 0.0; // shown until the first usable sample
    // RenderSettings::cacheSlices: a new held tilt is drawn in this many bands, one a frame.
    int cacheSlices = 1;
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
    }
    // The frame's tilts: the sensed one, the held one (re-taken when the light changed, since
    // the renderer then draws the diffuse term whole anyway) and the diffuse term's.
    void write(pipeline::scene::SceneState& state);

    bool sensed() const { return haveTilt_; }
    std::uint64_t rejectedTilts() const { return rejected_; }

    nlohmann::json save() const;
    Expected<void> restore(const nlohmann::json& j);

private:
    TiltEstimatorSetup setup_;
    double tilt_;
    std::optional<std::uint32_t> lastAccel_;
    bool haveTilt_ = false;
    std::uint64_t rejected_ = 0;
    // The hold filter.
    std::array<double, kTiltWindow> window_{};
    std::size_t next_ = 0;
    std::size_t count_ = 0;
    double held_ = 0.0;
    bool heldValid_ = false;
    // The diffuse term of the last frame (none before the first):
    // pipeline/scene/diffuse_schedule.h.
    std::optional<pipeline::scene::DiffuseTilt> diffuse_;
};

} // namespace replica::state
