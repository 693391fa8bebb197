// The HID eye/head tracker: configuration on open, report decoding, and the reader thread.
#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <thread>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <hal/live_queue.h>
#include <hal/log.h>
#include <hal/tracker/hid_tracker_source.h>

namespace replica::hal::tracker {
namespace {

namespace eht = hid::eht;

// A feature report's buffer as hidapi takes it: the ID byte first (0 when reports are not
// numbered), then the report as the descriptor declares it; at least 2 bytes.
std::size_t featureBufferBytes(const hid::ReportDescriptor& d, std::uint8_t id)
{
    const std::size_t n = d.reportBytes(hid::ReportType::Feature, id) + (d.numberedReports ? 0 : 1);
    return std::max<std::size_t>(n, 2);
}

Error deviceError(hid::HidStatus s, const std::string& where, const std::string& doing)
{
    return Error{s == hid::HidStatus::Gone ? ErrorCode::NotFound : ErrorCode::DeviceFailure,
                 fmt::format("HID tracker {}: {} failed ({})", where, doing, hid::toString(s))};
}

glm::dvec3 mapAxes(const glm::dvec3& v, const accel::AxisMapping& m)
{
    glm::dvec3 out;
    for (int i = 0; i < 3; ++i) {
        const auto k = static_cast<std::size_t>(i);
        out[i] = m.sign[k] * v[m.axis[k]];
    }
    return out;
}

} // namespace

std::optional<glm::dvec3> eyePoint(const eht::TrackingReport& r, const accel::AxisMapping& axes)
{
    if (r.leftEyeM && r.rightEyeM) {
        return mapAxes(0.5 * (*r.leftEyeM + *r.rightEyeM), axes);
    }
    if (r.headM) {
        return mapAxes(*r.headM, axes);
    }
    return std::nullopt;
}

Expected<HidTrackerReader> HidTrackerReader::open(std::unique_ptr<hid::HidDevice> device,
                                                  const Clock& clock,
                                                  HidTrackerOptions options)
{
    HidTrackerReader r(std::move(device), clock, std::move(options));
    if (auto ok = r.configure(); !ok) {
        return tl::unexpected(ok.error());
    }
    return r;
}

Expected<void> HidTrackerReader::configure()
{
    const std::string where = device_->describe();
    auto bytes = device_->reportDescriptor();
    if (!bytes) {
        return tl::unexpected(bytes.error());
    }
    auto descriptor = hid::parseReportDescriptor(*bytes);
    if (!descriptor) {
        return makeError(ErrorCode::DeviceFailure, fmt::format("{}: {}; the device cannot be used",
                                                               where, descriptor.error().message));
    }
    auto layout = eht::findLayout(*descriptor);
    if (!layout) {
        return makeError(layout.error().code, fmt::format("{}: {}", where, layout.error().message));
    }
    description_ = {};
    description_.layout = *layout;
    description_.where = where;
    processor_.emplace(*layout, options_.axes, options_.reanchorNs);
    descriptorBytes_ =
            std::make_shared<const std::vector<std::uint8_t>>(bytes->begin(), bytes->end());
    axesText_ = accel::toString(options_.axes);
    buffer_.assign(std::max<std::size_t>(layout->inputReportBytes, 1) + 64, 0);
    knownIds_ = {};
    for (const auto& f : descriptor->fields) {
        knownIds_[f.reportId] = true;
    }
    if (auto ok = readFeatures(*descriptor); !ok) {
        return ok;
    }
    return requestMode(*descriptor);
}

// A feature report as hidapi reads it, sized as the descriptor declares it (ID byte first, 0 when
// not numbered): a fixed 256-byte buffer cut longer reports short, and the mode request then
// wrote zeros over the rest of the control report.
Expected<std::vector<std::uint8_t>>
HidTrackerReader::getFeature(const hid::ReportDescriptor& d, std::uint8_t id, const char* doing)
{
    std::vector<std::uint8_t> report(featureBufferBytes(d, id), 0);
    const auto got = device_->getFeature(id, report);
    if (got.status == hid::HidStatus::Gone) {
        return tl::unexpected(deviceError(got.status, description_.where, doing));
    }
    if (got.status != hid::HidStatus::Ok) {
        return std::vector<std::uint8_t>();
    }
    report.resize(std::min(got.bytes, report.size()));
    return report;
}

// A feature value that is a whole number (status, quality). An infinite or huge value (a unit
// exponent of 400 made one; casting it to int is undefined) is taken as not reported, and said.
std::optional<int> HidTrackerReader::wholeFeature(std::optional<double> v, const char* what) const
{
    if (!v) {
        return std::nullopt;
    }
    if (!std::isfinite(*v) || *v < static_cast<double>(std::numeric_limits<int>::min()) ||
        *v > static_cast<double>(std::numeric_limits<int>::max())) {
        deviceLog("hal.tracker")
                ->warn("HID tracker {}: {} reads {:g}, which is no value it can have; taken as "
                       "not reported",
                       description_.where, what, *v);
        return std::nullopt;
    }
    return static_cast<int>(*v);
}

// Status, quality, calibrated screen and rate; a device that refuses a feature request is still
// usable.
Expected<void> HidTrackerReader::readFeatures(const hid::ReportDescriptor& d)
{
    const eht::Layout& layout = description_.layout;
    auto read = [&](const std::optional<hid::HidField>& f) -> Expected<std::optional<double>> {
        if (!f) {
            return std::optional<double>();
        }
        auto report = getFeature(d, f->reportId, "a get-feature request");
        if (!report) {
            return tl::unexpected(report.error());
        }
        return report->empty() ? std::nullopt : eht::featureValue(*f, *report);
    };
    auto asLength = [](const std::optional<hid::HidField>& f, std::optional<double> v) {
        // Without a length unit the page's convention, micrometres, applies.
        if (v && f && f->unit.metresPerUnit() <= 0.0) {
            *v *= 1e-6;
        }
        return v;
    };
    auto status = read(layout.configurationStatus);
    auto quality = read(layout.quality);
    auto width = read(layout.calibratedWidth);
    auto height = read(layout.calibratedHeight);
    auto rate = read(layout.samplingFrequency);
    for (const auto* e : {&status, &quality, &width, &height, &rate}) {
        if (!*e) {
            return tl::unexpected(e->error());
        }
    }
    description_.status = wholeFeature(*status, "Configuration Status");
    description_.quality = wholeFeature(*quality, "Tracker Quality");
    description_.screenWidthM = asLength(layout.calibratedWidth, *width);
    description_.screenHeightM = asLength(layout.calibratedHeight, *height);
    description_.samplingHz = *rate;
    return {};
}

// Device Mode Request: read the control report (other values in it stay as they are), set the
// streams wanted, write it back.
Expected<void> HidTrackerReader::requestMode(const hid::ReportDescriptor& d)
{
    const eht::Layout& layout = description_.layout;
    if (!layout.modeRequest) {
        return {};
    }
    const hid::HidField& f = *layout.modeRequest;
    auto report = getFeature(d, f.reportId, "reading the control report");
    if (!report) {
        return tl::unexpected(report.error());
    }
    // What the device did not return (all of it, if it refused the request) is written as 0.
    report->resize(featureBufferBytes(d, f.reportId), 0);
    (*report)[0] = f.reportId;
    const int mode = layout.wantedMode();
    if (f.logicalMin < f.logicalMax && (mode < f.logicalMin || mode > f.logicalMax)) {
        // Microsoft's reference descriptor declares 0..1 and its driver expects 2 (eye
        // position, as the usage page defines it): no value in such a range asks for the
        // positions, so the value is sent as it is, and the log says so.
        deviceLog("hal.tracker")
                ->warn("HID tracker {}: device mode request {} is outside the field's logical "
                       "range {}..{}; sent as it is, since no value in the range asks for the "
                       "positions",
                       description_.where, mode, f.logicalMin, f.logicalMax);
    }
    hid::insertField(f, std::span<std::uint8_t>(*report).subspan(1), mode);
    if (const auto s = device_->sendFeature(*report); s != hid::HidStatus::Ok) {
        return tl::unexpected(deviceError(s, description_.where,
                                          fmt::format("the device mode request ({})", mode)));
    }
    description_.modeSent = mode;
    return {};
}

Expected<eht::Layout> trackerLayout(std::span<const std::uint8_t> bytes)
{
    auto descriptor = hid::parseReportDescriptor(bytes);
    if (!descriptor) {
        return tl::unexpected(descriptor.error());
    }
    return eht::findLayout(*descriptor);
}

eht::DecodeResult HidReportProcessor::process(std::span<const std::uint8_t> report,
                                              std::int64_t arrivalNs,
                                              PoseSample& out)
{
    eht::TrackingReport r;
    const auto result = eht::decodeTracking(layout_, report, r);
    if (result != eht::DecodeResult::Ok) {
        return result;
    }
    out.timestampNs = sessionTime(r.deviceTimeNs, arrivalNs);
    const auto eye = eyePoint(r, axes_);
    out.tracked = eye.has_value();
    out.eyeTrackerM = eye ? *eye : glm::dvec3(0.0);
    return result;
}

std::int64_t HidReportProcessor::sessionTime(std::optional<std::int64_t> deviceNs,
                                             std::int64_t hostNs)
{
    if (!deviceNs) {
        lastNs_ = std::max(lastNs_, hostNs);
        return lastNs_;
    }
    // The device's clock, anchored so that no report is stamped later than it arrived: the offset
    // is the smallest (arrival - device time) seen, i.e. the least delayed report. A device clock
    // that stepped back (reset) or fell far behind (drift, a pause) is re-anchored.
    const std::int64_t lag = hostNs - *deviceNs;
    if (!offsetNs_ || *deviceNs < lastDeviceNs_ || lag < *offsetNs_ ||
        lag - *offsetNs_ > reanchorNs_) {
        offsetNs_ = lag;
    }
    lastDeviceNs_ = *deviceNs;
    lastNs_ = std::max(lastNs_, *deviceNs + *offsetNs_);
    return lastNs_;
}

void HidTrackerReader::reject(const std::string& why, std::size_t bytes, std::int64_t nowNs)
{
    ++rejected_;
    if (const auto n = rejectedLog_.add(1, nowNs); n > 0) {
        deviceLog("hal.tracker")
                ->warn("HID tracker {}: dropped {} report{}, the last {} bytes {}; {} in all (at "
                       "most one line per 10 s)",
                       description_.where, n, n == 1 ? "" : "s", bytes, why, rejected_);
    }
}

Expected<std::optional<PoseSample>> HidTrackerReader::next()
{
    const auto got = device_->readInput(buffer_, options_.readTimeoutMs);
    if (got.status == hid::HidStatus::Timeout) {
        return std::optional<PoseSample>();
    }
    if (got.status != hid::HidStatus::Ok) {
        return tl::unexpected(deviceError(got.status, description_.where, "reading a report"));
    }
    const std::int64_t host = clock_->nowNs();
    const std::span<const std::uint8_t> report{buffer_.data(), got.bytes};
    PoseSample s;
    switch (processor_->process(report, host, s)) {
    case eht::DecodeResult::OtherReport:
        // Another report the descriptor declares is of no use here; an ID it does not declare is
        // a device (or an attacker on the USB port) not keeping to its own descriptor: counted.
        if (!knownIds_[report[0]]) {
            reject(fmt::format("with report ID {}, which the descriptor does not declare",
                               report[0]),
                   got.bytes, host);
        }
        return std::optional<PoseSample>();
    case eht::DecodeResult::Short:
        reject(fmt::format("shorter than the descriptor says ({} bytes)",
                           description_.layout.inputReportBytes),
               got.bytes, host);
        return std::optional<PoseSample>();
    case eht::DecodeResult::Ok:
        break;
    }
    // Raw in, processed out: the report as received, the descriptor of this opening, the axes.
    auto raw = std::make_shared<RawTrackerInput>();
    raw->kind = RawTrackerInput::Kind::HidReport;
    raw->arrivalNs = host;
    raw->bytes.assign(report.begin(), report.end());
    raw->hidDescriptor = descriptorBytes_;
    raw->axes = axesText_;
    raw->reanchorNs = options_.reanchorNs;
    s.raw = std::move(raw);
    return std::optional<PoseSample>(std::move(s));
}

namespace {

class HidTrackerThread final : public HidTrackerSource
{
public:
    HidTrackerThread(hid::HidOpener opener, const Clock& clock, HidTrackerOptions options)
        : opener_(std::move(opener)), clock_(clock), options_(std::move(options))
    {
        info_.model = "hid-eye-head-tracker";
        info_.serial = options_.label;
        info_.kind = SourceKind::Live;
        thread_ = std::thread([this] { run(); });
    }

    ~HidTrackerThread() override
    {
        queue_.stop();
        thread_.join();
    }

    HidTrackerThread(const HidTrackerThread&) = delete;
    HidTrackerThread& operator=(const HidTrackerThread&) = delete;

    const DeviceInfo& info() const override { return info_; }
    long rejectedReports() const override { return rejected_.load(); }
    HidTrackerDescription description() const override
    {
        std::lock_guard lock(mutex_);
        return description_;
    }

    LinkState state() const override
    {
        const LinkState s = state_.load();
        const std::int64_t last = lastNs_.load();
        if (s == LinkState::Connected && last >= 0 && clock_.nowNs() - last > options_.staleNs) {
            return LinkState::Stalled;
        }
        return s;
    }

    void poll(std::int64_t untilNs, std::vector<PoseSample>& out) override
    {
        queue_.drain(untilNs, out);
        std::lock_guard lock(mutex_);
        // A tracker that went quiet (or away) must not leave the last pose standing as tracked.
        const std::int64_t last = lastNs_.load();
        if (last >= 0 && untilNs - last > options_.staleNs && !reportedStale_ &&
            (out.empty() || out.back().timestampNs < last + options_.staleNs)) {
            PoseSample s;
            s.timestampNs = last + options_.staleNs;
            s.sequence = staleSequence();
            s.tracked = false;
            out.push_back(s);
            reportedStale_ = true;
        }
    }

private:
    std::uint32_t staleSequence() { return sequence_.fetch_add(1); }

    void run()
    {
        std::string lastError;
        std::optional<HidTrackerReader> reader;
        while (!queue_.stopping()) {
            if (!reader) {
                auto dev = opener_();
                auto r = dev ? HidTrackerReader::open(std::move(*dev), clock_, options_)
                             : Expected<HidTrackerReader>(tl::unexpected(dev.error()));
                if (!r) {
                    state_ = LinkState::Lost;
                    if (r.error().message != lastError) {
                        deviceLog("hal.tracker")
                                ->error("{}; retrying every {} ms", r.error().message,
                                        options_.reconnectNs / 1'000'000);
                        lastError = r.error().message;
                    }
                    if (!queue_.waitFor(options_.reconnectNs)) {
                        return;
                    }
                    continue;
                }
                reader.emplace(std::move(*r));
                lastError.clear();
                const auto& d = reader->description();
                deviceLog("hal.tracker")
                        ->info("HID tracker {}: {}; status {}, calibrated screen {}, {} Hz, mode "
                               "request {}",
                               d.where, d.layout.summary(),
                               d.status ? hid::eht::statusName(*d.status) : "not reported",
                               d.screenWidthM && d.screenHeightM
                                       ? fmt::format("{:.3f} x {:.3f} m", *d.screenWidthM,
                                                     *d.screenHeightM)
                                       : std::string("not reported"),
                               d.samplingHz ? fmt::format("{:g}", *d.samplingHz) : "?", d.modeSent);
                if (d.status && *d.status != hid::eht::kStatusReady) {
                    deviceLog("hal.tracker")
                            ->warn("HID tracker {}: status '{}': run the tracker's own setup "
                                   "(screen and user calibration) before relying on its poses",
                                   d.where, hid::eht::statusName(*d.status));
                }
                {
                    std::lock_guard lock(mutex_);
                    description_ = d;
                }
                state_ = LinkState::Connected;
                lastNs_ = clock_.nowNs();
            }
            auto s = reader->next();
            rejected_ = reader->rejectedReports() + rejectedBefore_;
            if (!s) {
                deviceLog("hal.tracker")
                        ->error("{}; the display keeps the last eye position", s.error().message);
                rejectedBefore_ = rejected_.load();
                reader.reset();
                state_ = LinkState::Lost;
                // A device that fails every read must not be reopened in a tight loop.
                if (!queue_.waitFor(options_.reconnectNs)) {
                    return;
                }
                continue;
            }
            if (!*s) {
                continue;
            }
            PoseSample p = **s;
            {
                std::lock_guard lock(mutex_);
                p.sequence = staleSequence();
                reportedStale_ = false;
            }
            lastNs_ = p.timestampNs;
            queue_.push(p);
        }
    }

    hid::HidOpener opener_;
    const Clock& clock_;
    HidTrackerOptions options_;
    DeviceInfo info_;
    mutable std::mutex mutex_;
    HidTrackerDescription description_; // under mutex_
    bool reportedStale_ = false;        // under mutex_
    std::atomic<std::uint32_t> sequence_{0};
    std::atomic<LinkState> state_{LinkState::Lost};
    std::atomic<std::int64_t> lastNs_{-1};
    std::atomic<long> rejected_{0};
    long rejectedBefore_ = 0; // reader thread only
    LiveQueue<PoseSample> queue_{1024};
    std::thread thread_;
};

} // namespace

std::unique_ptr<HidTrackerSource>
makeHidTrackerSource(hid::HidOpener opener, const Clock& clock, HidTrackerOptions options)
{
    return std::make_unique<HidTrackerThread>(std::move(opener), clock, std::move(options));
}

} // namespace replica::hal::tracker
