// Eye and Head Trackers usage page: layout discovery and report decoding.
#include <cmath>

#include <fmt/format.h>

#include <hal/tracker/hid_eye_head.h>

namespace replica::hal::hid::eht {
namespace {

constexpr std::uint32_t u(std::uint16_t id)
{
    return usage(kPage, id);
}

// Micrometres: what trackers of this page report positions in (Microsoft's reference HID eye
// tracker uses int32 um); assumed only when the descriptor gives no length unit.
constexpr double kAssumedMetresPerUnit = 1e-6;

std::optional<PositionFields> positionIn(const ReportDescriptor& d, std::uint16_t collection)
{
    const HidField* x = d.find(ReportType::Input, u(kPositionX), u(collection));
    const HidField* y = d.find(ReportType::Input, u(kPositionY), u(collection));
    const HidField* z = d.find(ReportType::Input, u(kPositionZ), u(collection));
    if (x == nullptr || y == nullptr || z == nullptr) {
        return std::nullopt;
    }
    PositionFields p{*x, *y, *z, x->unit.metresPerUnit(), false};
    if (p.metresPerUnit <= 0.0) {
        p.metresPerUnit = kAssumedMetresPerUnit;
        p.unitAssumed = true;
    }
    return p;
}

std::optional<HidField> feature(const ReportDescriptor& d, std::uint16_t id)
{
    const HidField* f = d.find(ReportType::Feature, u(id));
    return f != nullptr ? std::optional<HidField>(*f) : std::nullopt;
}

bool inRange(const HidField& f, std::int64_t v)
{
    // A field whose logical range is empty or unset gives no validity information.
    if (f.logicalMax <= f.logicalMin) {
        return true;
    }
    return v >= f.logicalMin && v <= f.logicalMax;
}

std::optional<glm::dvec3> position(const PositionFields& p, std::span<const std::uint8_t> data)
{
    const auto x = extractField(p.x, data);
    const auto y = extractField(p.y, data);
    const auto z = extractField(p.z, data);
    if (!x || !y || !z || !inRange(p.x, *x) || !inRange(p.y, *y) || !inRange(p.z, *z)) {
        return std::nullopt;
    }
    return glm::dvec3(static_cast<double>(*x), static_cast<double>(*y), static_cast<double>(*z)) *
           p.metresPerUnit;
}

std::string unitName(double metresPerUnit)
{
    if (std::abs(metresPerUnit - 1e-6) < 1e-12) {
        return "um";
    }
    if (std::abs(metresPerUnit - 1e-3) < 1e-9) {
        return "mm";
    }
    return fmt::format("{:g} m", metresPerUnit);
}

} // namespace

const char* statusName(int status)
{
    switch (status) {
    case kStatusReady:
        return "ready";
    case kStatusConfiguring:
        return "configuring";
    case kStatusScreenSetupNeeded:
        return "screen setup needed";
    case kStatusUserCalibrationNeeded:
        return "user calibration needed";
    default:
        return "unknown";
    }
}

int Layout::wantedMode() const
{
    return (head ? kModeHeadPosition : 0) | (leftEye && rightEye ? kModeEyePosition : 0);
}

std::string Layout::summary() const
{
    std::string what;
    if (head) {
        what = fmt::format("head in {}{}", unitName(head->metresPerUnit),
                           head->unitAssumed ? " (assumed)" : "");
    }
    if (leftEye && rightEye) {
        what += fmt::format("{}left and right eye in {}{}", what.empty() ? "" : ", ",
                            unitName(leftEye->metresPerUnit),
                            leftEye->unitAssumed ? " (assumed)" : "");
    }
    return fmt::format("{}, input report {} ({} bytes): {}; {}",
                       application == u(kHeadTracker) ? "head tracker" : "eye tracker",
                       inputReportId, inputReportBytes, what,
                       timestamp ? fmt::format("timestamp every {:g} s{}", secondsPerTick,
                                               timestampUnitAssumed ? " (assumed)" : "")
                                 : std::string("no timestamp (host time used)"));
}

Expected<Layout> findLayout(const ReportDescriptor& d)
{
    Layout l;
    for (const auto& c : d.collections) {
        if (c.type == 1 && (c.usage == u(kEyeTracker) || c.usage == u(kHeadTracker))) {
            l.application = c.usage;
            break;
        }
    }
    if (l.application == 0) {
        return makeError(ErrorCode::Unsupported,
                         "not an eye or head tracker: the report descriptor has no application "
                         "collection of usage page 0x12 (Eye and Head Trackers)");
    }
    l.numberedReports = d.numberedReports;
    l.head = positionIn(d, kHeadPosition);
    l.leftEye = positionIn(d, kLeftEyePosition);
    l.rightEye = positionIn(d, kRightEyePosition);
    if (!l.head && !(l.leftEye && l.rightEye)) {
        return makeError(ErrorCode::Unsupported,
                         "this eye/head tracker reports neither a head position (usage 0x27 with "
                         "X, Y, Z) nor both eye positions (0x25 and 0x26): Replica needs the "
                         "viewer's position, not only a gaze point");
    }
    // Everything used must arrive in one report: the tracking data.
    const PositionFields& any = l.head ? *l.head : *l.leftEye;
    l.inputReportId = any.x.reportId;
    for (const auto* p : {&l.head, &l.leftEye, &l.rightEye}) {
        if (*p && ((*p)->x.reportId != l.inputReportId || (*p)->y.reportId != l.inputReportId ||
                   (*p)->z.reportId != l.inputReportId)) {
            return makeError(ErrorCode::Unsupported,
                             "this tracker splits its positions over several input reports; "
                             "only one tracking-data report is supported");
        }
    }
    l.inputReportBytes = d.reportBytes(ReportType::Input, l.inputReportId);
    if (const HidField* t = d.find(ReportType::Input, u(kSensorTimestamp));
        t != nullptr && t->reportId == l.inputReportId) {
        l.timestamp = *t;
        l.secondsPerTick = t->unit.secondsPerUnit();
        if (l.secondsPerTick <= 0.0) {
            l.secondsPerTick = 1e-6; // microseconds, as the reference implementations use
            l.timestampUnitAssumed = true;
        }
    }
    l.quality = feature(d, kTrackerQuality);
    l.calibratedWidth = feature(d, kCalibratedScreenWidth);
    l.calibratedHeight = feature(d, kCalibratedScreenHeight);
    l.samplingFrequency = feature(d, kSamplingFrequency);
    l.configurationStatus = feature(d, kConfigurationStatus);
    l.modeRequest = feature(d, kDeviceModeRequest);
    return l;
}

DecodeResult
decodeTracking(const Layout& layout, std::span<const std::uint8_t> report, TrackingReport& out)
{
    std::span<const std::uint8_t> data = report;
    if (layout.numberedReports) {
        if (report.empty()) {
            return DecodeResult::Short;
        }
        if (report[0] != layout.inputReportId) {
            return DecodeResult::OtherReport;
        }
        data = report.subspan(1);
    }
    if (report.size() < layout.inputReportBytes) {
        return DecodeResult::Short;
    }
    out = {};
    if (layout.timestamp) {
        if (const auto t = extractField(*layout.timestamp, data)) {
            // A device time beyond 2^62 ns (146 years) is garbage (a hostile or broken device):
            // rounding it would overflow, and so would the anchoring's arithmetic. The arrival
            // time stands in, as for a device without a timestamp.
            const double ns = static_cast<double>(*t) * layout.secondsPerTick * 1e9;
            if (std::isfinite(ns) && std::abs(ns) < 0x1p62) {
                out.deviceTimeNs = static_cast<std::int64_t>(std::llround(ns));
            }
        }
    }
    if (layout.head) {
        out.headM = position(*layout.head, data);
    }
    if (layout.leftEye && layout.rightEye) {
        out.leftEyeM = position(*layout.leftEye, data);
        out.rightEyeM = position(*layout.rightEye, data);
    }
    return DecodeResult::Ok;
}

std::optional<double> featureValue(const HidField& field, std::span<const std::uint8_t> report)
{
    if (report.empty()) {
        return std::nullopt;
    }
    const auto v = extractField(field, report.subspan(1));
    if (!v) {
        return std::nullopt;
    }
    const double x = static_cast<double>(*v);
    if (const double m = field.unit.metresPerUnit(); m > 0.0) {
        return x * m;
    }
    if (field.unit.power(3) == -1 && (field.unit.raw & 0xFFFF0FF0u) == 0) { // hertz
        return x * std::pow(10.0, field.unit.exponent);
    }
    return x;
}

} // namespace replica::hal::hid::eht
