// Re-deriving samples from their recorded raw inputs.
#include <bit>
#include <cmath>
#include <cstdint>
#include <memory>

#include <fmt/format.h>

#include <hal/accel/iio_accel.h>
#include <hal/lamp/lamp_debouncer.h>
#include <hal/tracker/hid_tracker_source.h>
#include <hal/tracker/opentrack_udp.h>
#include <platform/reprocess.h>

namespace replica::platform {
namespace {

bool sameBits(const glm::dvec3& a, const glm::dvec3& b)
{
    return std::bit_cast<std::uint64_t>(a.x) == std::bit_cast<std::uint64_t>(b.x) &&
           std::bit_cast<std::uint64_t>(a.y) == std::bit_cast<std::uint64_t>(b.y) &&
           std::bit_cast<std::uint64_t>(a.z) == std::bit_cast<std::uint64_t>(b.z);
}

bool finite(const glm::dvec3& v)
{
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

Expected<hal::accel::AxisMapping> reprocessAxes(const std::optional<std::string>& chosen,
                                                const std::string& recorded,
                                                const char* what,
                                                std::uint32_t sequence)
{
    auto m = hal::accel::parseAxisMapping(chosen ? *chosen : recorded);
    if (!m) {
        return makeError(ErrorCode::Corrupt,
                         chosen ? m.error().message
                                : fmt::format("raw input of {} {}: recorded axes: {}", what,
                                              sequence, m.error().message));
    }
    return m;
}

} // namespace

Expected<ReprocessReport> reprocess(recordings::Recording& rec, const ReprocessOptions& options)
{
    ReprocessReport report;
    // HID: one processor per opening of the device (a descriptor object each), in order, so the
    // device-clock anchoring runs over the reports exactly as the live reader ran over them.
    std::shared_ptr<const std::vector<std::uint8_t>> descriptor;
    std::optional<hal::tracker::HidReportProcessor> hid;
    for (auto& s : rec.samples(recordings::trackerKind())) {
        ++report.poses;
        if (!s.raw) {
            continue;
        }
        const hal::RawTrackerInput& raw = *s.raw;
        glm::dvec3 eye{0.0};
        bool tracked = false;
        if (raw.kind == hal::RawTrackerInput::Kind::OpentrackDatagram) {
            const auto pose = hal::tracker::decodeOpentrack(raw.bytes);
            if (!pose) {
                return makeError(ErrorCode::Corrupt,
                                 fmt::format("raw input of pose {}: a {}-byte datagram that is "
                                             "not an opentrack pose (48 bytes, six finite "
                                             "doubles)",
                                             s.sequence, raw.bytes.size()));
            }
            hal::tracker::TrackerMounting mounting;
            mounting.zSign = raw.zSign;
            mounting.eyeOffsetHeadM = raw.eyeOffsetHeadM;
            eye = hal::tracker::eyeFromHeadPose(*pose, mounting);
            tracked = true;
        } else {
            if (!raw.hidDescriptor) {
                return makeError(ErrorCode::Corrupt,
                                 fmt::format("raw input of pose {}: a HID report without its "
                                             "report descriptor",
                                             s.sequence));
            }
            if (raw.hidDescriptor != descriptor) {
                auto layout = hal::tracker::trackerLayout(*raw.hidDescriptor);
                if (!layout) {
                    return makeError(ErrorCode::Corrupt,
                                     fmt::format("raw input of pose {}: the recorded HID report "
                                                 "descriptor: {}",
                                                 s.sequence, layout.error().message));
                }
                auto m = reprocessAxes(options.trackerAxes, raw.axes, "pose", s.sequence);
                if (!m) {
                    return tl::unexpected(m.error());
                }
                hid.emplace(std::move(*layout), *m, raw.reanchorNs);
                descriptor = raw.hidDescriptor;
            }
            hal::PoseSample p;
            const auto result = hid->process(raw.bytes, raw.arrivalNs, p);
            if (result != hal::hid::eht::DecodeResult::Ok) {
                return makeError(ErrorCode::Corrupt,
                                 fmt::format("raw input of pose {}: a {}-byte HID report that "
                                             "is {} for its descriptor",
                                             s.sequence, raw.bytes.size(),
                                             result == hal::hid::eht::DecodeResult::Short
                                                     ? "too short"
                                                     : "not the tracking report"));
            }
            eye = p.eyeTrackerM;
            tracked = p.tracked;
            report.poseTimesDiffer += p.timestampNs != s.timestampNs ? 1 : 0;
        }
        ++report.posesReprocessed;
        if (!sameBits(eye, s.eyeTrackerM) || tracked != s.tracked) {
            ++report.posesChanged;
        }
        report.posesNonFinite += finite(eye) ? 0 : 1;
        s.eyeTrackerM = eye;
        s.tracked = tracked;
    }
    for (auto& s : rec.samples(recordings::accelKind())) {
        ++report.accel;
        if (!s.raw) {
            continue;
        }
        auto m = reprocessAxes(options.accelAxes, s.raw->axes, "accelerometer sample", s.sequence);
        if (!m) {
            return tl::unexpected(m.error());
        }
        const glm::dvec3 g = hal::accel::gravityFromRaw(*s.raw, *m);
        ++report.accelReprocessed;
        report.accelChanged += sameBits(g, s.gravity) ? 0 : 1;
        report.accelNonFinite += finite(g) ? 0 : 1;
        s.gravity = g;
    }
    for (auto& s : rec.samples(recordings::lampSelectorKind())) {
        ++report.lamp;
        if (s.lamp == hal::kLampLost || s.lineCount == 0) {
            continue;
        }
        const int lamp = hal::lamp::decodeOneHot(s.lineLevels & hal::lamp::lineMask(s.lineCount));
        ++report.lampReprocessed;
        report.lampChanged += lamp != s.lamp ? 1 : 0;
        s.lamp = lamp;
    }
    return report;
}

} // namespace replica::platform
