// The USB HID "Eye and Head Trackers" usage page (0x12, HUTRR74; in the HID Usage Tables since
// 1.2x), which near-IR eye and head trackers implement so that an operating system can use them
// without a vendor driver. From a parsed report descriptor: where the head and eye positions,
// the sensor timestamp, the capabilities, the calibrated screen size, the status and the mode
// request sit, with their units; and the decoding of input reports into positions in metres.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>

#include <glm/vec3.hpp>

#include <hal/tracker/hid_descriptor.h>

namespace replica::hal::hid::eht {

constexpr std::uint16_t kPage = 0x12;
// Collections.
constexpr std::uint16_t kEyeTracker = 0x01;  // application
constexpr std::uint16_t kHeadTracker = 0x02; // application
constexpr std::uint16_t kTrackingData = 0x10;
constexpr std::uint16_t kCapabilities = 0x11;
constexpr std::uint16_t kConfiguration = 0x12;
constexpr std::uint16_t kStatus = 0x13;
constexpr std::uint16_t kControl = 0x14;
// Tracking data.
constexpr std::uint16_t kSensorTimestamp = 0x20;
constexpr std::uint16_t kPositionX = 0x21;
constexpr std::uint16_t kPositionY = 0x22;
constexpr std::uint16_t kPositionZ = 0x23;
constexpr std::uint16_t kGazePoint = 0x24;
constexpr std::uint16_t kLeftEyePosition = 0x25;
constexpr std::uint16_t kRightEyePosition = 0x26;
constexpr std::uint16_t kHeadPosition = 0x27;
constexpr std::uint16_t kHeadDirectionPoint = 0x28;
// Capabilities, configuration, status, control.
constexpr std::uint16_t kTrackerQuality = 0x100;
constexpr std::uint16_t kMinimumTrackingDistance = 0x101;
constexpr std::uint16_t kOptimumTrackingDistance = 0x102;
constexpr std::uint16_t kMaximumTrackingDistance = 0x103;
constexpr std::uint16_t kCalibratedScreenWidth = 0x204;
constexpr std::uint16_t kCalibratedScreenHeight = 0x205;
constexpr std::uint16_t kSamplingFrequency = 0x300;
constexpr std::uint16_t kConfigurationStatus = 0x301;
constexpr std::uint16_t kDeviceModeRequest = 0x400;

// Configuration Status values.
constexpr int kStatusReady = 1;
constexpr int kStatusConfiguring = 2;
constexpr int kStatusScreenSetupNeeded = 3;
constexpr int kStatusUserCalibrationNeeded = 4;
const char* statusName(int status);

// Device Mode Request bits: which streams the host wants.
constexpr int kModeGazePoint = 1;
constexpr int kModeEyePosition = 2;
constexpr int kModeHeadPosition = 4;

// X, Y and Z of one position, each with its own unit: a descriptor may give each axis (and each
// eye) its own unit, exponent and physical range.
struct PositionFields {
    HidField x;
    HidField y;
    HidField z;
    // Metres per physical unit of x, y and z (the unit times 10^exponent).
    std::array<double, 3> metresPerUnit{};
    // Per axis: the descriptor gave no unit (Unit 0): micrometres assumed.
    std::array<bool, 3> unitAssumed{};
    // "um", "mm (x, y), cm (z)", "um (assumed)": the units, for the layout's summary.
    std::string units() const;
};

// Where everything this driver uses sits in the device's reports.
struct Layout {
    std::uint32_t application = 0; // usage of the eye- or head-tracker application collection
    bool numberedReports = false;
    std::uint8_t inputReportId = 0;   // the tracking-data report
    std::size_t inputReportBytes = 0; // on the wire, with the ID byte when numbered
    std::optional<HidField> timestamp;
    double secondsPerTick = 1e-6; // of the timestamp
    bool timestampUnitAssumed = false;
    std::optional<PositionFields> head;
    std::optional<PositionFields> leftEye;
    std::optional<PositionFields> rightEye;
    // Features (each in some feature report; read with a get-feature request).
    std::optional<HidField> quality;
    std::optional<HidField> calibratedWidth;
    std::optional<HidField> calibratedHeight;
    std::optional<HidField> samplingFrequency;
    std::optional<HidField> configurationStatus;
    std::optional<HidField> modeRequest;

    // The mode request that turns on what this driver reads.
    int wantedMode() const;
    // One line: "eye tracker, report 1 (45 bytes): head, left and right eye in um, timestamp us".
    std::string summary() const;
};

// Finds the tracker in a descriptor. Fails, saying what is missing, for a device that is not an
// eye/head tracker or that reports neither a head nor both eye positions; and, naming the byte
// offset of the field's Input item, for a position field that is Relative, whose Logical
// Minimum exceeds its Maximum, whose unit is not a length, or that has a physical range over an
// empty logical range.
Expected<Layout> findLayout(const ReportDescriptor& descriptor);

// One decoded tracking-data report. Positions are in the tracker's own frame, metres, as the
// device reports them; a position that is absent, or out of its logical range (the usage page's
// way of saying "not tracked"), is nullopt.
struct TrackingReport {
    std::optional<std::int64_t> deviceTimeNs;
    std::optional<glm::dvec3> headM;
    std::optional<glm::dvec3> leftEyeM;
    std::optional<glm::dvec3> rightEyeM;
};

enum class DecodeResult { Ok, OtherReport, Short };

// Decodes an input report as hidapi delivers it (its report ID first when the device numbers its
// reports). OtherReport: a report this driver does not use; Short: too few bytes.
DecodeResult
decodeTracking(const Layout& layout, std::span<const std::uint8_t> report, TrackingReport& out);

// A feature value in physical units (metres for lengths, Hz for the sampling frequency, the
// physical value otherwise; HID 1.11 6.2.2.7) from a feature report as read (ID byte first, 0
// when not numbered). Nullopt when the report is too short or the value cannot be scaled.
std::optional<double> featureValue(const HidField& field, std::span<const std::uint8_t> report);

} // namespace replica::hal::hid::eht
