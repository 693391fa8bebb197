// Tracker pose -> eye in the booth frame.
#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <glm/geometric.hpp>
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
    inView_ = pose->tracked;
    if (!pose->tracked) {
        ++rejected_;
        return;
    }
    const std::string why = refusal(*pose);
    if (!why.empty()) {
        ++rejected_;
        ++refused_;
        lastRefusal_ = why;
        return;
    }
    eye_ = setup_.trackerInBooth.apply(pose->eyeTrackerM);
    havePose_ = true;
    lastGoodNs_ = pose->timestampNs;
}

std::string EyeEstimator::refusal(const hal::PoseSample& pose) const
{
    const glm::dvec3 e = pose.eyeTrackerM;
    if (!std::isfinite(e.x) || !std::isfinite(e.y) || !std::isfinite(e.z)) {
        return "a pose that is not finite";
    }
    const glm::dvec3 booth = setup_.trackerInBooth.apply(e);
    const double distance = std::hypot(booth.x, booth.y, booth.z); // no overflow at 1e300
    if (!(distance <= kMaxEyeDistanceM)) {
        return fmt::format("an eye {:.3g} m from the booth's origin (at most {} m)", distance,
                           kMaxEyeDistanceM);
    }
    if (havePose_ && lastGoodNs_) {
        // Samples out of order count by the time between them either way, and never as less
        // than kEyeMinIntervalS apart (two poses of one batch share a time stamp): a step of
        // up to 10 cm is always a head's.
        const double dt =
                std::max(std::abs(static_cast<double>(pose.timestampNs - *lastGoodNs_)) * 1e-9,
                         kEyeMinIntervalS);
        const double moved = glm::length(booth - eye_);
        if (moved > kMaxEyeSpeedMPerS * dt) {
            return fmt::format("an eye that moved {:.3f} m in {:.0f} ms ({:.0f} m/s; a head moves "
                               "under {} m/s)",
                               moved, dt * 1e3, moved / dt, kMaxEyeSpeedMPerS);
        }
    }
    return "";
}

nlohmann::json EyeEstimator::save() const
{
    return {{"last_pose", optionalJson(lastPose_)},
            {"have_pose", havePose_},
            {"rejected", rejected_},
            {"eye_m", vec3Json(eye_)},
            {"last_good_ns", optionalJson(lastGoodNs_)}};
}

Expected<void> EyeEstimator::restore(const nlohmann::json& j)
{
    try {
        lastPose_ = optionalFromJson<std::uint32_t>(j.at("last_pose"));
        havePose_ = j.at("have_pose").get<bool>();
        rejected_ = j.at("rejected").get<std::uint64_t>();
        eye_ = vec3FromJson(j.at("eye_m"));
        // Saved since the speed gate; a session saved before it starts the gate afresh.
        lastGoodNs_ = j.contains("last_good_ns")
                              ? optionalFromJson<std::int64_t>(j.at("last_good_ns"))
                              : std::nullopt;
    } catch (const std::exception& e) {
        return makeError(ErrorCode::InvalidArgument, fmt::format("eye: {}", e.what()));
    }
    return {};
}

} // namespace replica::state
