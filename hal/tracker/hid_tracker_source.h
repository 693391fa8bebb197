// The HID head/eye tracker (usage page 0x12) as a tracker source: open the device, parse its
// report descriptor, read its capabilities, calibrated screen and status, switch it into
// reporting head and eye positions with a Device Mode Request feature report, and turn its
// tracking-data reports into poses stamped with the device's own timestamps mapped into session
// time. The threaded source survives unplugging: Lost, one error line, retry every second.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <hal/accel/iio_accel.h>
#include <hal/clock.h>
#include <hal/log_limiter.h>
#include <hal/sources.h>
#include <hal/tracker/hid_device.h>
#include <hal/tracker/hid_eye_head.h>

namespace replica::hal::tracker {

// What the device said about itself when it was opened.
struct HidTrackerDescription {
    hid::eht::Layout layout;
    std::string where;
    std::optional<int> status;          // Configuration Status (1 ready)
    std::optional<int> quality;         // Tracker Quality
    std::optional<double> screenWidthM; // the calibrated screen the positions refer to
    std::optional<double> screenHeightM;
    std::optional<double> samplingHz;
    int modeSent = 0; // the Device Mode Request written (0: the device has none)
};

struct HidTrackerOptions {
    // Tracker axes to the tracker frame of PoseSample (x right, y up, z towards the viewer):
    // for each PoseSample axis, which device axis and sign, e.g. "x,-y,z" for a device whose y
    // points down the screen.
    accel::AxisMapping axes;
    std::string label = "auto"; // DeviceInfo::serial: the node asked for, "auto" for the first
    std::int64_t reconnectNs = 1'000'000'000;
    std::int64_t staleNs = 500'000'000; // no report for this long: Stalled, an untracked sample
    int readTimeoutMs = 50;
    // A device clock more than this behind the host's earliest arrival is re-anchored (its
    // clock drifted or was reset).
    std::int64_t reanchorNs = 50'000'000;
};

// The report descriptor parsed and the tracker found in it; fails naming the byte offset or what
// is missing.
Expected<hid::eht::Layout> trackerLayout(std::span<const std::uint8_t> descriptor);

// The processing of tracking reports into poses, without the device: decoding, the eye point,
// and the device clock anchored into session time through the least-delayed arrival. The live
// reader runs it on each report as it arrives; 'replay --reprocess' runs it on the recorded
// reports with their arrival times, and so gets the same poses bit for bit.
class HidReportProcessor
{
public:
    HidReportProcessor(hid::eht::Layout layout, accel::AxisMapping axes, std::int64_t reanchorNs)
        : layout_(std::move(layout)), axes_(axes), reanchorNs_(reanchorNs)
    {}
    // Ok: 'out' holds the pose (time, tracked, eye; sequence untouched).
    hid::eht::DecodeResult
    process(std::span<const std::uint8_t> report, std::int64_t arrivalNs, PoseSample& out);
    const hid::eht::Layout& layout() const { return layout_; }

private:
    std::int64_t sessionTime(std::optional<std::int64_t> deviceNs, std::int64_t hostNs);

    hid::eht::Layout layout_;
    accel::AxisMapping axes_;
    std::int64_t reanchorNs_;
    std::optional<std::int64_t> offsetNs_; // session time - device time, smallest seen
    std::int64_t lastDeviceNs_ = 0;
    std::int64_t lastNs_ = 0;
};

// The deterministic part: one opened device, read report by report (tests drive it directly).
class HidTrackerReader
{
public:
    static Expected<HidTrackerReader>
    open(std::unique_ptr<hid::HidDevice> device, const Clock& clock, HidTrackerOptions options);

    // Waits up to the read timeout for a report. A sample when one arrived (tracked or not); none
    // on timeout or a report of no use (counted in rejectedReports when too short or of an ID the
    // descriptor does not declare); an error when
    // the device is gone (NotFound) or failing.
    Expected<std::optional<PoseSample>> next();

    const HidTrackerDescription& description() const { return description_; }
    long rejectedReports() const { return rejected_; }

private:
    HidTrackerReader(std::unique_ptr<hid::HidDevice> device,
                     const Clock& clock,
                     HidTrackerOptions options)
        : device_(std::move(device)), clock_(&clock), options_(std::move(options))
    {}
    Expected<void> configure();
    Expected<std::vector<std::uint8_t>>
    getFeature(const hid::ReportDescriptor& d, std::uint8_t id, const char* doing);
    std::optional<int> wholeFeature(std::optional<double> v, const char* what) const;
    Expected<void> readFeatures(const hid::ReportDescriptor& d);
    Expected<void> requestMode(const hid::ReportDescriptor& d);

    std::unique_ptr<hid::HidDevice> device_;
    const Clock* clock_;
    HidTrackerOptions options_;
    HidTrackerDescription description_;
    std::optional<HidReportProcessor> processor_;
    std::shared_ptr<const std::vector<std::uint8_t>> descriptorBytes_; // handed up as raw
    std::string axesText_;
    std::vector<std::uint8_t> buffer_;
    // Reports dropped: shorter than the descriptor says, or numbered with an ID it does not
    // declare. A line for the first, then one per 10 s with the count.
    void reject(const std::string& why, std::size_t bytes, std::int64_t nowNs);
    std::array<bool, 256> knownIds_{}; // report IDs the descriptor declares
    long rejected_ = 0;
    LogLimiter rejectedLog_;
};

// The eye point a tracking report gives: the midpoint of the eyes when both are tracked, else
// the head position; in PoseSample's tracker frame.
std::optional<glm::dvec3> eyePoint(const hid::eht::TrackingReport& r,
                                   const accel::AxisMapping& axes);

class HidTrackerSource : public TrackerSource
{
public:
    virtual long rejectedReports() const = 0;
    // The last opened device's description, empty 'where' before the first open.
    virtual HidTrackerDescription description() const = 0;
};

// Starts the reader thread at once; state() is Lost until a device has been opened.
std::unique_ptr<HidTrackerSource>
makeHidTrackerSource(hid::HidOpener opener, const Clock& clock, HidTrackerOptions options = {});

} // namespace replica::hal::tracker
