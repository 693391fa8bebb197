// What 'replica replay' reports besides the checks: the reprocessing and the recorded display
// digests.
#include <fmt/format.h>

#include <platform/cli/replay.h>
#include <platform/logging.h>

namespace replica::platform {

void ShownDigests::frame(std::uint64_t frameIndex,
                         const std::vector<std::uint8_t>& rgba,
                         std::optional<std::uint64_t> rgbaXxh3)
{
    const auto it = byFrame.find(frameIndex);
    if (it == byFrame.end() || rgba.empty()) {
        return;
    }
    if ((rgbaXxh3 ? *rgbaXxh3 : xxh3_64(rgba)) == it->second) {
        ++matched;
    } else {
        ++differing;
        if (firstDiffering < 0) {
            firstDiffering = static_cast<long>(frameIndex);
        }
    }
}

void reportReprocess(const ReprocessReport& r,
                     nlohmann::json& summary,
                     const std::function<void(const std::string&)>& say)
{
    summary["reprocess"] = {{"poses", r.poses},
                            {"poses_reprocessed", r.posesReprocessed},
                            {"poses_changed", r.posesChanged},
                            {"pose_times_differ", r.poseTimesDiffer},
                            {"accel", r.accel},
                            {"accel_reprocessed", r.accelReprocessed},
                            {"accel_changed", r.accelChanged},
                            {"lamp", r.lamp},
                            {"lamp_reprocessed", r.lampReprocessed},
                            {"lamp_changed", r.lampChanged},
                            {"poses_non_finite", r.posesNonFinite},
                            {"accel_non_finite", r.accelNonFinite},
                            {"accel_bad_scale", r.accelBadScale}};
    say(fmt::format("reprocessed: {} of {} poses ({} changed) and {} of {} accelerometer "
                    "samples ({} changed) from their raw inputs; the rest as recorded",
                    r.posesReprocessed, r.poses, r.posesChanged, r.accelReprocessed, r.accel,
                    r.accelChanged));
    if (r.lamp > 0) {
        say(fmt::format("reprocessed: {} of {} lamp selector positions decoded again from "
                        "their line levels ({} changed)",
                        r.lampReprocessed, r.lamp, r.lampChanged));
    }
    if (r.poseTimesDiffer > 0) {
        say(fmt::format("reprocessed: {} HID reports' device times map to other session "
                        "times than recorded; the samples keep their recorded times",
                        r.poseTimesDiffer));
    }
}

void reportShownDigests(const ReplayOptions& o,
                        const ShownDigests& shown,
                        const std::optional<ReprocessReport>& reprocessed,
                        nlohmann::json& summary,
                        const std::function<void(const std::string&)>& say)
{
    if (shown.byFrame.empty()) {
        return;
    }
    summary["display_digests"] = {{"recorded", shown.byFrame.size()},
                                  {"matched", shown.matched},
                                  {"differing", shown.differing}};
    if (shown.differing == 0) {
        say(fmt::format("shown: all {} frames match the recorded digests of what the panel "
                        "showed",
                        shown.matched));
        return;
    }
    summary["display_digests"]["first_differing_frame"] = shown.firstDiffering;
    const bool reprocessedChanges =
            reprocessed &&
            reprocessed->posesChanged + reprocessed->accelChanged + reprocessed->lampChanged > 0;
    logger("replica")->warn(
            "{}: {} of {} frames differ from the digests of what the panel "
            "showed when recorded (first: frame {}); {}",
            o.file, shown.differing, shown.matched + shown.differing, shown.firstDiffering,
            reprocessedChanges ? "--reprocess changed samples, as expected"
                               : "this machine renders differently (a different Mesa or "
                                 "GPU?)");
}

} // namespace replica::platform
