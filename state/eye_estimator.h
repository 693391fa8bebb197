// The eye estimator: the tracker's eye position -> the booth frame through T_booth_tracker (one
// rigid transform from the site: pipeline/base/rigid_transform.h), holding the last good eye
// through lost tracking, non-finite poses and poses no head can take (a glitch of the tracker:
// a reflection taken for a marker, a corrupt datagram).
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <glm/vec3.hpp>
#include <nlohmann/json_fwd.hpp>

#include <hal/samples.h>
#include <pipeline/base/expected.h>
#include <pipeline/base/rigid_transform.h>

namespace replica::state {

// A viewer's eye is in front of the booth, within metres of it, and a head moves at walking pace
// (under 2 m/s; a turn of the head moves the eye less): a pose farther than kMaxEyeDistanceM from
// the booth's origin, or one that moved faster than kMaxEyeSpeedMPerS since the last good pose, is
// refused and the last good eye held. A tracker that really jumped (re-centred, a new viewer) is
// followed once the time since the last good pose makes the jump a possible one (0.5 m: 0.1 s).
constexpr double kMaxEyeDistanceM = 5.0;
constexpr double kMaxEyeSpeedMPerS = 5.0;
constexpr double kEyeMinIntervalS = 0.02;

struct EyeEstimatorSetup {
    // T_booth_tracker: eye_booth = trackerInBooth.apply(eye_tracker). Default: the fixed
    // mounting (pipeline/base/rigid_transform.h).
    pipeline::RigidTransform trackerInBooth = pipeline::defaultTrackerInBooth();
    // Shown until the first usable pose.
    glm::dvec3 defaultEyeM{0.0, 0.45, 0.60};
};

class EyeEstimator
{
public:
    explicit EyeEstimator(EyeEstimatorSetup setup);

    void update(const hal::PoseSample* pose);
    glm::dvec3 eyeBoothM() const { return eye_; }

    bool tracked() const { return havePose_; }
    // Poses not used: lost tracking (the markers out of view) and refused ones together.
    std::uint64_t rejectedPoses() const { return rejected_; }
    // Poses refused (not finite, or no head's: kMaxEyeDistanceM, kMaxEyeSpeedMPerS), and why the
    // last one was ("" before the first). Lost tracking is not a refusal: the viewer left.
    std::uint64_t refusedPoses() const { return refused_; }
    const std::string& lastRefusal() const { return lastRefusal_; }
    // Whether the latest pose had the viewer in view (false before the first pose).
    bool viewerInView() const { return inView_; }
    // The tracker's pose in the booth (T_booth_tracker).
    const pipeline::RigidTransform& trackerInBooth() const { return setup_.trackerInBooth; }

    nlohmann::json save() const;
    Expected<void> restore(const nlohmann::json& j);

private:
    // Why 'pose' (tracked) is refused; "" when it is used.
    std::string refusal(const hal::PoseSample& pose) const;
    EyeEstimatorSetup setup_;
    glm::dvec3 eye_;
    std::optional<std::uint32_t> lastPose_;
    bool havePose_ = false;
    std::uint64_t rejected_ = 0;
    std::uint64_t refused_ = 0;
    std::string lastRefusal_;
    bool inView_ = false;
    std::optional<std::int64_t> lastGoodNs_; // the last good pose's time
};

} // namespace replica::state
