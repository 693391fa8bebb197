// Re-deriving samples from their recorded raw inputs.
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include <fmt/format.h>
#include <fmt/ranges.h>

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

// A tracked eye and whether it was tracked, as the live reader decoded them from one raw input.
struct EyeReading {
    glm::dvec3 eye{0.0};
    bool tracked = false;
    std::int64_t timestampNs = 0;
};

Expected<EyeReading> decodeOpentrackInput(const hal::RawTrackerInput& raw, std::uint32_t sequence)
{
    const auto pose = hal::tracker::decodeOpentrack(raw.bytes);
    if (!pose) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("raw input of pose {}: a {}-byte datagram that is not an "
                                     "opentrack pose (48 bytes, six finite doubles)",
                                     sequence, raw.bytes.size()));
    }
    hal::tracker::TrackerMounting mounting;
    mounting.zSign = raw.zSign;
    mounting.eyeOffsetHeadM = raw.eyeOffsetHeadM;
    return EyeReading{hal::tracker::eyeFromHeadPose(*pose, mounting), true, 0};
}

// HID: one processor per opening of the device (a descriptor object each), in order, so the
// device-clock anchoring runs over the reports exactly as the live reader ran over them.
class HidReplay
{
public:
    explicit HidReplay(const std::optional<std::string>& trackerAxes) : trackerAxes_(trackerAxes) {}

    Expected<EyeReading> decode(const hal::RawTrackerInput& raw, std::uint32_t sequence)
    {
        if (!raw.hidDescriptor) {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("raw input of pose {}: a HID report without its report "
                                         "descriptor",
                                         sequence));
        }
        if (raw.hidDescriptor != descriptor_) {
            auto layout = hal::tracker::trackerLayout(*raw.hidDescriptor);
            if (!layout) {
                return makeError(ErrorCode::Corrupt,
                                 fmt::format("raw input of pose {}: the recorded HID report "
                                             "descriptor: {}",
                                             sequence, layout.error().message));
            }
            auto m = reprocessAxes(trackerAxes_, raw.axes, "pose", sequence);
            if (!m) {
                return tl::unexpected(m.error());
            }
            hid_.emplace(std::move(*layout), *m, raw.reanchorNs);
            descriptor_ = raw.hidDescriptor;
        }
        hal::PoseSample p;
        const auto result = hid_->process(raw.bytes, raw.arrivalNs, p);
        if (result != hal::hid::eht::DecodeResult::Ok) {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("raw input of pose {}: a {}-byte HID report that is {} "
                                         "for its descriptor",
                                         sequence, raw.bytes.size(),
                                         result == hal::hid::eht::DecodeResult::Short
                                                 ? "too short"
                                                 : "not the tracking report"));
        }
        return EyeReading{p.eyeTrackerM, p.tracked, p.timestampNs};
    }

private:
    std::optional<std::string> trackerAxes_;
    std::shared_ptr<const std::vector<std::uint8_t>> descriptor_;
    std::optional<hal::tracker::HidReportProcessor> hid_;
};

Expected<void>
reprocessPoses(recordings::Recording& rec, const ReprocessOptions& options, ReprocessReport& report)
{
    HidReplay hid(options.trackerAxes);
    for (auto& s : rec.samples(recordings::trackerKind())) {
        ++report.poses;
        if (!s.raw) {
            continue;
        }
        const bool opentrack = s.raw->kind == hal::RawTrackerInput::Kind::OpentrackDatagram;
        auto reading = opentrack ? decodeOpentrackInput(*s.raw, s.sequence)
                                 : hid.decode(*s.raw, s.sequence);
        if (!reading) {
            return tl::unexpected(reading.error());
        }
        if (!opentrack) {
            report.poseTimesDiffer += reading->timestampNs != s.timestampNs ? 1 : 0;
        }
        ++report.posesReprocessed;
        if (!sameBits(reading->eye, s.eyeTrackerM) || reading->tracked != s.tracked) {
            ++report.posesChanged;
        }
        report.posesNonFinite += finite(reading->eye) ? 0 : 1;
        s.eyeTrackerM = reading->eye;
        s.tracked = reading->tracked;
    }
    return {};
}

// What the live source accepts (hal/accel: IioAccelDevice::open): scales positive and finite,
// offsets finite.
bool usableScale(const hal::RawAccelInput& raw)
{
    for (std::size_t k = 0; k < 3; ++k) {
        if (!(raw.scale[k] > 0.0) || !std::isfinite(raw.scale[k]) ||
            !std::isfinite(raw.offset[k])) {
            return false;
        }
    }
    return true;
}

Expected<void>
reprocessAccel(recordings::Recording& rec, const ReprocessOptions& options, ReprocessReport& report)
{
    const auto info = rec.session.devices.find(&recordings::accelKind());
    const std::string device =
            info != rec.session.devices.end()
                    ? fmt::format("'{} {}'", info->second.model, info->second.serial)
                    : std::string("(not named in the session)");
    for (auto& s : rec.samples(recordings::accelKind())) {
        ++report.accel;
        if (!s.raw) {
            continue;
        }
        auto m = reprocessAxes(options.accelAxes, s.raw->axes, "accelerometer sample", s.sequence);
        if (!m) {
            return tl::unexpected(m.error());
        }
        glm::dvec3 g = hal::accel::gravityFromRaw(*s.raw, *m);
        const bool usable = usableScale(*s.raw);
        if (!usable) {
            ++report.accelBadScale; // a zero scale would give a finite but meaningless (0,0,0)
            g = glm::dvec3(std::numeric_limits<double>::quiet_NaN());
        }
        ++report.accelReprocessed;
        report.accelChanged += sameBits(g, s.gravity) ? 0 : 1;
        if (!finite(g)) {
            ++report.accelNonFinite;
            if (report.accelFirstNonFinite.empty()) {
                report.accelFirstNonFinite = fmt::format(
                        "accelerometer {} sample {}: raw {}, scale {}, offset {} ({})", device,
                        s.sequence, fmt::join(s.raw->raw, ","), fmt::join(s.raw->scale, ","),
                        fmt::join(s.raw->offset, ","),
                        usable ? "the product overflows"
                               : "the scale is not a positive finite number or the offset not "
                                 "finite");
            }
        }
        s.gravity = g;
    }
    return {};
}

void reprocessLamps(recordings::Recording& rec, ReprocessReport& report)
{
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
}

} // namespace

Expected<ReprocessReport> reprocess(recordings::Recording& rec, const ReprocessOptions& options)
{
    ReprocessReport report;
    if (auto ok = reprocessPoses(rec, options, report); !ok) {
        return tl::unexpected(ok.error());
    }
    if (auto ok = reprocessAccel(rec, options, report); !ok) {
        return tl::unexpected(ok.error());
    }
    reprocessLamps(rec, report);
    return report;
}

} // namespace replica::platform
