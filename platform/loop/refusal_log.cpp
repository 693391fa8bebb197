// The state stage's refusals in the log (refusal_log.h).
#include <algorithm>

#include <fmt/format.h>
#include <state/scene_estimator.h>

#include <pipeline/spectral/spectrometer_chain.h>
#include <platform/logging.h>
#include <platform/loop/frame_loop.h>
#include <platform/loop/refusal_log.h>
#include <recordings/device_kind.h>

namespace replica::platform {

void RefusalLog::report(Device& d,
                        std::uint64_t count,
                        const std::string& kind,
                        const char* one,
                        const char* many,
                        const std::string& why,
                        const std::string& held,
                        std::int64_t tickNs,
                        LoopStats& stats)
{
    const std::uint64_t fresh = count >= d.seen ? count - d.seen : 0;
    d.seen = count;
    if (fresh > 0) {
        stats.refused[kind] += fresh;
        d.limiter.count(fresh);
    }
    if (const std::uint64_t n = d.limiter.flush(tickNs)) {
        logger("state")->warn("{}: {} {} not used (the last: {}); the frame keeps {}", kind, n,
                              n == 1 ? one : many, why, held);
    }
}

void RefusalLog::after(const state::SceneEstimator& estimator,
                       std::int64_t tickNs,
                       LoopStats& stats)
{
    const auto& light = estimator.light();
    report(devices_[recordings::spectrometerKind().name()], light.rejectedSpectra(),
           recordings::spectrometerKind().name(), "spectrum", "spectra", light.lastRefusal(),
           light.sensed() ? "the last good light" : "the starting light", tickNs, stats);
    const std::uint64_t weak = light.weakSpectra();
    weak_.limiter.count(weak - std::min(weak, weak_.seen));
    weak_.seen = weak;
    if (const std::uint64_t n = weak_.limiter.flush(tickNs)) {
        logger("state")->info("spectrometer: {} spectr{} too weak to tell a colour by (the "
                              "brightest pixel under {:g} times the detector's noise above "
                              "dark): the frame shows the colour there was at the reading's level",
                              n, n == 1 ? "um" : "a", pipeline::spectral::kMinPeakOverDarkNoise);
    }
    const auto& tilt = estimator.tilt();
    report(devices_[recordings::accelKind().name()], tilt.rejectedTilts(),
           recordings::accelKind().name(), "tilt reading", "tilt readings", tilt.lastRefusal(),
           "the last good tilt", tickNs, stats);
    const auto& eye = estimator.eye();
    report(devices_[recordings::trackerKind().name()], eye.refusedPoses(),
           recordings::trackerKind().name(), "pose", "poses", eye.lastRefusal(),
           "the last good eye", tickNs, stats);

    // The viewer out of view is no fault (nobody in front of the panel), said once each way.
    if (!eye.tracked() && !inView_) {
        return; // no pose yet: the starting eye
    }
    const bool inView = eye.viewerInView();
    if (inView_ && *inView_ == inView) {
        return;
    }
    const auto e = eye.eyeBoothM();
    if (!inView) {
        outOfViewSinceNs_ = tickNs;
        logger("state")->info("tracker: the viewer is out of view; the frame keeps the eye at "
                              "({:.3f}, {:.3f}, {:.3f}) m",
                              e.x, e.y, e.z);
    } else if (inView_) {
        logger("state")->info("tracker: the viewer is in view again after {:.1f} s",
                              static_cast<double>(tickNs - outOfViewSinceNs_) * 1e-9);
    }
    inView_ = inView;
}

} // namespace replica::platform
