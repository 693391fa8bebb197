// The eye estimator: the tracker's eye position -> the booth frame through T_booth_tracker (one
// rigid transform from the site: pipeline/base/rigid_transform.h), holding the last good eye
// through lost tracking and non-finite poses.
#pragma once

#include <cstdint>
#include <optional>

#include <glm/vec3.hpp>
#include <nlohmann/json_fwd.hpp>

#include <hal/samples.h>
#include <pipeline/base/expected.h>
#include <pipeline/base/rigid_transform.h>

namespace replica::state {

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
    std::uint64_t rejectedPoses() const { return rejected_; }
    // The tracker's pose in the booth (T_booth_tracker).
    const pipeline::RigidTransform& trackerInBooth() const { return setup_.trackerInBooth; }

    nlohmann::json save() const;
    Expected<void> restore(const nlohmann::json& j);

private:
    EyeEstimatorSetup setup_;
    glm::dvec3 eye_;
    std::optional<std::uint32_t> lastPose_;
    bool havePose_ = false;
    std::uint64_t rejected_ = 0;
};

} // namespace replica::state
