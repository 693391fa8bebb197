// Eye and Head Trackers usage page: layout discovery and report decoding.
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

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

const char* positionName(std::uint16_t collection)
{
    return collection == kHeadPosition      ? "Head Position"
           : collection == kLeftEyePosition ? "Left Eye Position"
                                            : "Right Eye Position";
}

Error fieldError(const HidField& f, const std::string& name, const std::string& what)
{
    return Error{ErrorCode::Corrupt,
                 fmt::format("HID report descriptor byte {}: {} {}", f.itemAt, name, what)};
}

// What makes a position field unusable. Each of these once decoded silently into a wrong place:
// a Relative field as if absolute; Logical Minimum 100 over Maximum 50 read unsigned (x = 2147 m);
// a unit of area read as "um (assumed)".
Expected<double> metresPerUnit(const HidField& f, const std::string& name)
{
    if (f.relative) {
        return tl::unexpected(fieldError(f, name,
                                         "is Relative (Input item bit 2): an eye tracker's "
                                         "positions must be absolute"));
    }
    if (f.logicalMin > f.logicalMax) {
        return tl::unexpected(fieldError(
                f, name,
                fmt::format("has Logical Minimum {} above its Logical Maximum {} (HID 1.11 "
                            "6.2.2.7: the minimum may not exceed the maximum)",
                            f.logicalMin, f.logicalMax)));
    }
    if ((f.physicalMin != 0 || f.physicalMax != 0) && f.logicalMin == f.logicalMax) {
        return tl::unexpected(fieldError(
                f, name,
                fmt::format("has physical range {}..{} over the empty logical range {}..{}: its "
                            "values cannot be scaled",
                            f.physicalMin, f.physicalMax, f.logicalMin, f.logicalMax)));
    }
    if (f.unit.system() == UnitSystem::None) {
        return 0.0; // no unit: the caller assumes micrometres
    }
    const double m = f.unit.metresPerUnit();
    if (m <= 0.0) {
        return tl::unexpected(fieldError(
                f, name,
                fmt::format("has Unit 0x{:x}, which is not a length (centimetre or inch)",
                            f.unit.raw)));
    }
    return m;
}

// Absent (nullopt) when the descriptor has no such position; an error when it has one that
// cannot be decoded.
Expected<std::optional<PositionFields>> positionIn(const ReportDescriptor& d,
                                                   std::uint16_t collection)
{
    const HidField* x = d.find(ReportType::Input, u(kPositionX), u(collection));
    const HidField* y = d.find(ReportType::Input, u(kPositionY), u(collection));
    const HidField* z = d.find(ReportType::Input, u(kPositionZ), u(collection));
    if (x == nullptr || y == nullptr || z == nullptr) {
        return std::optional<PositionFields>();
    }
    PositionFields p{*x, *y, *z, {}, {}};
    const std::array<const HidField*, 3> axes{x, y, z};
    for (std::size_t i = 0; i < 3; ++i) {
        const std::string name = fmt::format("{} {}", positionName(collection), "XYZ"[i]);
        const auto m = metresPerUnit(*axes[i], name);
        if (!m) {
            return tl::unexpected(m.error());
        }
        p.unitAssumed[i] = *m <= 0.0;
        p.metresPerUnit[i] = p.unitAssumed[i] ? kAssumedMetresPerUnit : *m;
    }
    return std::optional<PositionFields>(p);
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

std::optional<double>
metres(const HidField& f, double metresPerUnit, std::span<const std::uint8_t> data)
{
    const auto v = extractField(f, data);
    if (!v || !inRange(f, *v)) {
        return std::nullopt;
    }
    const auto physical = physicalValue(f, *v);
    if (!physical || !std::isfinite(*physical * metresPerUnit)) {
        return std::nullopt;
    }
    return *physical * metresPerUnit;
}

std::optional<glm::dvec3> position(const PositionFields& p, std::span<const std::uint8_t> data)
{
    const auto x = metres(p.x, p.metresPerUnit[0], data);
    const auto y = metres(p.y, p.metresPerUnit[1], data);
    const auto z = metres(p.z, p.metresPerUnit[2], data);
    if (!x || !y || !z) {
        return std::nullopt;
    }
    return glm::dvec3(*x, *y, *z);
}

std::string unitName(double metresPerUnit, bool assumed)
{
    std::string name;
    if (std::abs(metresPerUnit - 1e-6) < 1e-12) {
        name = "um";
    } else if (std::abs(metresPerUnit - 1e-3) < 1e-9) {
        name = "mm";
    } else if (std::abs(metresPerUnit - 1e-2) < 1e-8) {
        name = "cm";
    } else {
        name = fmt::format("{:g} m", metresPerUnit);
    }
    return assumed ? name + " (assumed)" : name;
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

std::string PositionFields::units() const
{
    const std::array<std::string, 3> names{unitName(metresPerUnit[0], unitAssumed[0]),
                                           unitName(metresPerUnit[1], unitAssumed[1]),
                                           unitName(metresPerUnit[2], unitAssumed[2])};
    if (names[0] == names[1] && names[1] == names[2]) {
        return names[0];
    }
    // Each unit once, with the axes in it, in the order first named: "mm (x, y), cm (z)".
    std::vector<std::pair<std::string, std::string>> groups; // unit, its axes
    for (std::size_t i = 0; i < 3; ++i) {
        const auto g = std::find_if(groups.begin(), groups.end(),
                                    [&](const auto& e) { return e.first == names[i]; });
        if (g == groups.end()) {
            groups.emplace_back(names[i], std::string(1, "xyz"[i]));
        } else {
            g->second += fmt::format(", {}", "xyz"[i]);
        }
    }
    std::string text;
    for (const auto& [unit, axes] : groups) {
        text += fmt::format("{}{} ({})", text.empty() ? "" : ", ", unit, axes);
    }
    return text;
}

int Layout::wantedMode() const
{
    return (head ? kModeHeadPosition : 0) | (leftEye && rightEye ? kModeEyePosition : 0);
}

std::string Layout::summary() const
{
    std::string what;
    if (head) {
        what = fmt::format("head in {}", head->units());
    }
    if (leftEye && rightEye) {
        const std::string left = leftEye->units();
        const std::string right = rightEye->units();
        what += what.empty() ? "" : ", ";
        what += left == right ? fmt::format("left and right eye in {}", left)
                              : fmt::format("left eye in {}, right eye in {}", left, right);
    }
    return fmt::format("{}, input report {} ({} bytes): {}; {}",
                       application == u(kHeadTracker) ? "head tracker" : "eye tracker",
                       inputReportId, inputReportBytes, what,
                       timestamp ? fmt::format("{}-bit timestamp every {:g} s{}",
                                               timestamp->bitSize, secondsPerTick,
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
    auto head = positionIn(d, kHeadPosition);
    auto left = positionIn(d, kLeftEyePosition);
    auto right = positionIn(d, kRightEyePosition);
    for (const auto* p : {&head, &left, &right}) {
        if (!*p) {
            return tl::unexpected(p->error());
        }
    }
    l.head = *head;
    l.leftEye = *left;
    l.rightEye = *right;
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
        l.timestamp = joinedBytes(d, *t);
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
        const auto t = extractField(*layout.timestamp, data);
        if (const auto ticks = t ? physicalValue(*layout.timestamp, *t) : std::nullopt) {
            // A device time beyond 2^62 ns (146 years) is garbage (a hostile or broken device):
            // rounding it would overflow, and so would the anchoring's arithmetic. The arrival
            // time stands in, as for a device without a timestamp.
            const double ns = *ticks * layout.secondsPerTick * 1e9;
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
    const auto physical = physicalValue(field, *v);
    if (!physical) {
        return std::nullopt;
    }
    const double x = *physical;
    if (const double m = field.unit.metresPerUnit(); m > 0.0) {
        return x * m;
    }
    if (field.unit.power(3) == -1 && (field.unit.raw & 0xFFFF0FF0u) == 0) { // hertz
        return x * std::pow(10.0, field.unit.exponent);
    }
    return x;
}

} // namespace replica::hal::hid::eht
