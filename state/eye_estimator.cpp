// Tracker pose -> eye in the booth frame.
#include <cmath>

#include <state/eye_estimator.h>
#include <state/json_state.h>

namespace replica::state {

EyeEstimator::EyeEstimator(EyeEstimatorSetup setup)
    : setup_(std::move(setup)), eye_(setup_.defaultEyeM)
{}

void EyeEstimator::update(const hal::PoseSample* pose)
{
    if (pose == nullptr || pose->sequence == lastPose_) {
        return;
    }
    lastPose_ = pose->sequence;
    const glm::dvec3 e = pose->eyeTrackerM;
    if (pose->tracked && std::isfinite(e.x) && std::isfinite(e.y) && std::isfinite(e.z)) {
        eye_ = setup_.trackerInBooth.apply(e);
        havePose_ = true;
    } else {
        ++rejected_;
    }
}

nlohmann::json EyeEstimator::save() const
{
    return {{"last_pose", optionalJson(lastPose_)},
            {"have_pose", havePose_},
            {"rejected", rejected_},
            {"eye_m", vec3Json(eye_)}};
}

Expected<void> EyeEstimator::restore(const nlohmann::json& j)
{
    try {
        lastPose_ = optionalFromJson<std::uint32_t>(j.at("last_pose"));
        havePose_ = j.at("have_pose").get<bool>();
        rejected_ = j.at("rejected").get<std::uint64_t>();
        eye_ = vec3FromJson(j.at("eye_m"));
    } catch (const std::exception& e) {
        return makeError(ErrorCode::InvalidArgument, fmt::format("eye: {}", e.what()));
    }
    return {};
}

} // namespace replica::state
