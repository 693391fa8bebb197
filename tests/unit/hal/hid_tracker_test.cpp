// The HID eye/head tracker (usage page 0x12): the report-descriptor parser, layout discovery and
// the driver, against byte-level fakes built from two hand-written descriptors: A (numbered
// reports, an eye tracker with 64-bit microsecond timestamps and int32 micrometre positions, as
// Microsoft's reference HID eye tracker lays them out) and B (no report IDs, a head tracker with
// padding, a 32-bit millisecond timestamp, int16 positions in 0.1 cm listed Z, X, Y, and its
// calibrated screen in 0.01 inch). Expected values come from the byte layouts as written here,
// not from the parser.
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <thread>

#include <tests/unit/hal/fake_hid_tracker.h>
#include <unistd.h>

#include <hal/tracker/hid_descriptor.h>
#include <hal/tracker/hid_eye_head.h>
#include <hal/tracker/hid_tracker_source.h>
#include <hal/tracker/hidapi_device.h>
#include <platform/reprocess.h>
#include <recordings/recording.h>

#include <gtest/gtest.h>

namespace replica::tests {
namespace {

using namespace hal::hid;
using hal::tracker::HidTrackerOptions;
using hal::tracker::HidTrackerReader;

// clang-format off
const std::vector<std::uint8_t> kDescriptorA = {
    0x05, 0x12,                   // Usage Page (Eye and Head Trackers)
    0x09, 0x01,                   // Usage (Eye Tracker)
    0xA1, 0x01,                   // Collection (Application)
    0x85, 0x01,                   //   Report ID (1)
    0x09, 0x10,                   //   Usage (Tracking Data)
    0xA1, 0x00,                   //   Collection (Physical)
    0x09, 0x20,                   //     Usage (Sensor Timestamp)
    0x15, 0x00,                   //     Logical Minimum (0)
    0x27, 0xFF, 0xFF, 0xFF, 0x7F, //     Logical Maximum (2^31 - 1)
    0x66, 0x01, 0x10,             //     Unit (SI linear: second)
    0x55, 0x0A,                   //     Unit Exponent (-6)
    0x75, 0x40,                   //     Report Size (64)
    0x95, 0x01,                   //     Report Count (1)
    0x81, 0x02,                   //     Input (Data, Var, Abs)
    0x09, 0x24,                   //     Usage (Gaze Point)
    0xA1, 0x00,                   //     Collection (Physical)
    0x09, 0x21, 0x09, 0x22,       //       Usage (Position X), Usage (Position Y)
    0x17, 0x01, 0x00, 0x00, 0x80, //       Logical Minimum (-(2^31 - 1))
    0x27, 0xFF, 0xFF, 0xFF, 0x7F, //       Logical Maximum (2^31 - 1)
    0x65, 0x11,                   //       Unit (SI linear: cm)
    0x55, 0x0C,                   //       Unit Exponent (-4): micrometres
    0x75, 0x20, 0x95, 0x02,       //       Report Size (32), Report Count (2)
    0x81, 0x02,                   //       Input (Data, Var, Abs)
    0xC0,                         //     End Collection
    0x09, 0x25, 0xA1, 0x00,       //     Usage (Left Eye Position), Collection (Physical)
    0x09, 0x21, 0x09, 0x22, 0x09, 0x23, 0x95, 0x03, 0x81, 0x02, 0xC0,
    0x09, 0x26, 0xA1, 0x00,       //     Usage (Right Eye Position), Collection (Physical)
    0x09, 0x21, 0x09, 0x22, 0x09, 0x23, 0x95, 0x03, 0x81, 0x02, 0xC0,
    0x09, 0x27, 0xA1, 0x00,       //     Usage (Head Position), Collection (Physical)
    0x09, 0x21, 0x09, 0x22, 0x09, 0x23, 0x95, 0x03, 0x81, 0x02, 0xC0,
    0xC0,                         //   End Collection (Tracking Data)
    0x85, 0x02,                   //   Report ID (2)
    0x09, 0x11, 0xA1, 0x02,       //   Usage (Capabilities), Collection (Logical)
    0x0A, 0x00, 0x01,             //     Usage (Tracker Quality)
    0x15, 0x00, 0x26, 0xFF, 0x00, //     Logical Minimum (0), Logical Maximum (255)
    0x65, 0x00, 0x55, 0x00,       //     Unit (none), Unit Exponent (0)
    0x75, 0x08, 0x95, 0x01, 0xB1, 0x02, // Report Size (8), Count (1), Feature (Data, Var, Abs)
    0x0A, 0x01, 0x01, 0x0A, 0x02, 0x01, 0x0A, 0x03, 0x01, // Min/Optimum/Max Tracking Distance
    0x27, 0xFF, 0xFF, 0xFF, 0x7F, 0x65, 0x11, 0x55, 0x0C, // 0..2^31-1 um
    0x75, 0x20, 0x95, 0x03, 0xB1, 0x02,
    0xC0,
    0x85, 0x03,                   //   Report ID (3)
    0x09, 0x12, 0xA1, 0x02,       //   Usage (Configuration), Collection (Logical)
    0x0A, 0x04, 0x02, 0x0A, 0x05, 0x02, // Usage (Calibrated Screen Width / Height)
    0x75, 0x20, 0x95, 0x02, 0xB1, 0x02, // um, as above
    0xC0,
    0x85, 0x04,                   //   Report ID (4)
    0x09, 0x13, 0xA1, 0x02,       //   Usage (Status), Collection (Logical)
    0x0A, 0x01, 0x03,             //     Usage (Configuration Status)
    0x15, 0x00, 0x25, 0x04, 0x65, 0x00, 0x55, 0x00,
    0x75, 0x08, 0x95, 0x01, 0xB1, 0x02,
    0x0A, 0x00, 0x03,             //     Usage (Sampling Frequency)
    0x27, 0xFF, 0xFF, 0x00, 0x00, //     Logical Maximum (65535)
    0x66, 0x01, 0xF0,             //     Unit (SI linear: 1/s = Hz)
    0x75, 0x10, 0x95, 0x01, 0xB1, 0x02,
    0xC0,
    0x85, 0x05,                   //   Report ID (5)
    0x09, 0x14, 0xA1, 0x02,       //   Usage (Control), Collection (Logical)
    0x0A, 0x00, 0x04,             //     Usage (Device Mode Request)
    0x15, 0x00, 0x25, 0x07, 0x65, 0x00, 0x55, 0x00,
    0x75, 0x08, 0x95, 0x01, 0xB1, 0x02,
    0xC0,
    0xC0,                         // End Collection (Application)
};

const std::vector<std::uint8_t> kDescriptorB = {
    0x05, 0x12, 0x09, 0x02, 0xA1, 0x01, // Head Tracker application
    0x09, 0x10, 0xA1, 0x00,       //   Tracking Data
    0x75, 0x04, 0x95, 0x02, 0x81, 0x03, // 8 bits of padding (Input, Constant)
    0x09, 0x20,                   //     Usage (Sensor Timestamp)
    0x15, 0x00, 0x27, 0xFF, 0xFF, 0xFF, 0x7F,
    0x66, 0x01, 0x10, 0x55, 0x0D, //     second, exponent -3: milliseconds
    0x75, 0x20, 0x95, 0x01, 0x81, 0x02,
    0x09, 0x27, 0xA1, 0x00,       //     Head Position
    0x09, 0x23, 0x09, 0x21, 0x09, 0x22, // Z, X, Y: in this order in the report
    0x16, 0x01, 0x80, 0x26, 0xFF, 0x7F, // Logical -32767 .. 32767 (-32768 = no value)
    0x65, 0x11, 0x55, 0x0F,       //     cm, exponent -1: millimetres
    0x75, 0x10, 0x95, 0x03, 0x81, 0x42, // Input (Data, Var, Abs, Null State)
    0xC0,
    0xC0,
    0x09, 0x13, 0xA1, 0x02,       //   Status
    0x0A, 0x01, 0x03, 0x15, 0x00, 0x25, 0x04, 0x65, 0x00, 0x55, 0x00,
    0x75, 0x08, 0x95, 0x01, 0xB1, 0x02,
    0xC0,
    0x09, 0x14, 0xA1, 0x02,       //   Control
    0x0A, 0x00, 0x04, 0x25, 0x07, 0xB1, 0x02,
    0xC0,
    0x09, 0x12, 0xA1, 0x02,       //   Configuration
    0x0A, 0x04, 0x02, 0x0A, 0x05, 0x02,
    0x27, 0xFF, 0xFF, 0x00, 0x00, //     0 .. 65535
    0x65, 0x13, 0x55, 0x0E,       //     English linear: inch, exponent -2
    0x75, 0x10, 0x95, 0x02, 0xB1, 0x02,
    0xC0,
    0xC0,
};
// clang-format on

void putLe(std::vector<std::uint8_t>& r, std::size_t at, std::uint64_t v, int bytes)
{
    for (int i = 0; i < bytes; ++i) {
        r[at + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(v >> (8 * i));
    }
}

// Layout A's tracking report: ID 1, then ts u64, gaze 2 x i32, left, right, head 3 x i32 each.
std::vector<std::uint8_t> reportA(std::uint64_t tsUs,
                                  std::array<std::int32_t, 3> left,
                                  std::array<std::int32_t, 3> right,
                                  std::array<std::int32_t, 3> head)
{
    std::vector<std::uint8_t> r(53, 0);
    r[0] = 1;
    putLe(r, 1, tsUs, 8);
    for (std::size_t i = 0; i < 3; ++i) {
        putLe(r, 17 + 4 * i, static_cast<std::uint32_t>(left[i]), 4);
        putLe(r, 29 + 4 * i, static_cast<std::uint32_t>(right[i]), 4);
        putLe(r, 41 + 4 * i, static_cast<std::uint32_t>(head[i]), 4);
    }
    return r;
}

// Layout B's report (no ID): padding byte, ts u32 ms, then Z, X, Y as i16 (0.1 cm).
std::vector<std::uint8_t>
reportB(std::uint32_t tsMs, std::int16_t x, std::int16_t y, std::int16_t z)
{
    std::vector<std::uint8_t> r(11, 0);
    r[0] = 0xEE; // padding: must be ignored
    putLe(r, 1, tsMs, 4);
    putLe(r, 5, static_cast<std::uint16_t>(z), 2);
    putLe(r, 7, static_cast<std::uint16_t>(x), 2);
    putLe(r, 9, static_cast<std::uint16_t>(y), 2);
    return r;
}

std::shared_ptr<FakeHidTrackerState> deviceA()
{
    auto s = std::make_shared<FakeHidTrackerState>();
    s->descriptor = kDescriptorA;
    std::vector<std::uint8_t> caps(14, 0);
    caps[0] = 2;
    caps[1] = 1; // quality: fine gaze
    putLe(caps, 2, 450'000, 4);
    putLe(caps, 6, 650'000, 4);
    putLe(caps, 10, 950'000, 4);
    std::vector<std::uint8_t> config(9, 0);
    config[0] = 3;
    putLe(config, 1, 518'400, 4); // 518.4 mm
    putLe(config, 5, 324'000, 4);
    std::vector<std::uint8_t> status{4, 1, 0, 0}; // ready, then u16 Hz
    putLe(status, 2, 120, 2);
    s->features = {{2, caps}, {3, config}, {4, status}, {5, {5, 0}}};
    s->modeReportId = 5;
    s->modeByte = 1;
    return s;
}

std::shared_ptr<FakeHidTrackerState> deviceB()
{
    auto s = std::make_shared<FakeHidTrackerState>();
    s->descriptor = kDescriptorB;
    // One feature report without ID: status u8, mode u8, width u16, height u16 (0.01 inch).
    std::vector<std::uint8_t> f(7, 0);
    f[1] = 4; // user calibration needed
    f[2] = 0;
    putLe(f, 3, 2040, 2); // 20.40 in = 0.51816 m
    putLe(f, 5, 1276, 2); // 12.76 in = 0.324104 m
    s->features = {{0, f}};
    s->modeReportId = 0;
    s->modeByte = 2;
    return s;
}

TEST(HidDescriptor, NumberedEyeTrackerFieldsSitWhereTheBytesSayWithTheirUnits)
{
    auto d = parseReportDescriptor(kDescriptorA);
    ASSERT_TRUE(d) << d.error().message;
    EXPECT_TRUE(d->numberedReports);
    EXPECT_EQ(d->reportBytes(ReportType::Input, 1), 53u); // 1 + 8 + 8 + 3 * 12
    EXPECT_EQ(d->reportBytes(ReportType::Feature, 2), 14u);
    EXPECT_EQ(d->reportBytes(ReportType::Feature, 5), 2u);
    const HidField* ts = d->find(ReportType::Input, usage(0x12, 0x20));
    ASSERT_NE(ts, nullptr);
    EXPECT_EQ(ts->bitOffset, 0u);
    EXPECT_EQ(ts->bitSize, 64u);
    EXPECT_DOUBLE_EQ(ts->unit.secondsPerUnit(), 1e-6);
    const HidField* hz = d->find(ReportType::Input, usage(0x12, 0x23), usage(0x12, 0x27));
    ASSERT_NE(hz, nullptr);
    EXPECT_EQ(hz->bitOffset, (8u + 8u + 12u + 12u + 8u) * 8u); // head Z: bytes 48..51 of data
    EXPECT_EQ(hz->logicalMin, -2147483647);
    EXPECT_EQ(hz->logicalMax, 2147483647);
    EXPECT_DOUBLE_EQ(hz->unit.metresPerUnit(), 1e-6);
    EXPECT_EQ(hz->unit.exponent, -4);
    const HidField* quality = d->find(ReportType::Feature, usage(0x12, 0x100));
    ASSERT_NE(quality, nullptr);
    EXPECT_EQ(quality->reportId, 2);
    EXPECT_EQ(quality->logicalMax, 255); // written as 0xFF 0x00: unsigned
}

TEST(HidDescriptor, UnnumberedHeadTrackerWithPaddingAndReorderedAxes)
{
    auto d = parseReportDescriptor(kDescriptorB);
    ASSERT_TRUE(d) << d.error().message;
    EXPECT_FALSE(d->numberedReports);
    EXPECT_EQ(d->reportBytes(ReportType::Input, 0), 11u);
    EXPECT_EQ(d->reportBytes(ReportType::Feature, 0), 6u);
    const HidField* x = d->find(ReportType::Input, usage(0x12, 0x21));
    const HidField* z = d->find(ReportType::Input, usage(0x12, 0x23));
    ASSERT_NE(x, nullptr);
    ASSERT_NE(z, nullptr);
    EXPECT_EQ(z->bitOffset, 40u); // after 8 bits of padding and the 32-bit timestamp
    EXPECT_EQ(x->bitOffset, 56u);
    EXPECT_TRUE(x->nullState);
    EXPECT_DOUBLE_EQ(x->unit.metresPerUnit(), 1e-3);
    const HidField* w = d->find(ReportType::Feature, usage(0x12, 0x204));
    ASSERT_NE(w, nullptr);
    EXPECT_DOUBLE_EQ(w->unit.metresPerUnit(), 0.0254e-2);
    EXPECT_EQ(w->bitOffset, 16u);
    // Padding is kept as a constant field with no usage.
    EXPECT_TRUE(d->fields.front().constant);
    EXPECT_EQ(d->fields.front().bitSize, 8u);
}

TEST(HidDescriptor, ExtractsSignedAndUnsignedBitFields)
{
    HidField f;
    f.bitOffset = 4;
    f.bitSize = 12;
    f.logicalMin = -2048;
    f.logicalMax = 2047;
    std::vector<std::uint8_t> data{0x0F, 0xF8}; // bits 4..15 = 0xF80 -> -128
    EXPECT_EQ(*extractField(f, data), -128);
    f.logicalMin = 0;
    f.logicalMax = 4095;
    EXPECT_EQ(*extractField(f, data), 0xF80);
    insertField(f, data, 0x123);
    EXPECT_EQ(data[0], 0x3F); // low nibble kept
    EXPECT_EQ(data[1], 0x12);
    EXPECT_FALSE(extractField(f, std::span<const std::uint8_t>(data).first(1)));
}

TEST(HidDescriptor, MalformedDescriptorsAreRefusedNamingTheByte)
{
    auto expectError = [](std::vector<std::uint8_t> bytes, const std::string& what) {
        auto d = parseReportDescriptor(bytes);
        ASSERT_FALSE(d) << what;
        EXPECT_NE(d.error().message.find(what), std::string::npos) << d.error().message;
    };
    expectError({}, "empty");
    expectError({0x05, 0x12, 0x27, 0xFF, 0xFF},
                "byte 2: item 0x27 needs 4 data bytes, only 2 left");
    expectError({0x05, 0x12, 0xC0}, "byte 2: End Collection without a Collection");
    expectError({0x05, 0x12, 0x09, 0x01, 0xA1, 0x01}, "1 collection(s) never closed");
    expectError({0xB4}, "byte 0: Pop without a Push");
    expectError({0x75, 0x00, 0x95, 0x01, 0x81, 0x02}, "Report Size 0");
    expectError({0x75, 0x41, 0x95, 0x01, 0x81, 0x02}, "Report Size 65");
    expectError({0x85, 0x00}, "report ID 0");
    expectError({0x0C}, "reserved item type");
    expectError({0x75, 0x08, 0x95, 0x01, 0x81, 0x02, 0x85, 0x01, 0x81, 0x02},
                "some reports have IDs and some have none");
    // Cut anywhere after its application collection opens (byte 6), descriptor A is refused (an
    // item cut short or a collection left open); cut before, it is at most no tracker.
    for (std::size_t n = 1; n < kDescriptorA.size(); ++n) {
        auto d = parseReportDescriptor(std::span(kDescriptorA).first(n));
        if (n >= 6 && d) {
            ADD_FAILURE() << "descriptor A cut to " << n << " bytes parsed";
        }
        if (n < 6 && d && eht::findLayout(*d)) {
            ADD_FAILURE() << "descriptor A cut to " << n << " bytes: taken for a tracker";
        }
    }
}

// The descriptors of issue 32, each within 4 KiB, that asked for gigabytes before the parser had
// limits: every limit is named with its value, and a descriptor just inside each one parses.
TEST(HidDescriptor, LimitsAreEnforcedBeforeAnythingGrows)
{
    auto expectError = [](const std::vector<std::uint8_t>& bytes, const std::string& what) {
        auto d = parseReportDescriptor(bytes);
        ASSERT_FALSE(d) << what;
        EXPECT_NE(d.error().message.find(what), std::string::npos) << d.error().message;
    };
    // Nested collections: Usage Page, Usage, then N x Collection (Physical), N x End Collection.
    auto nested = [](std::size_t n) {
        std::vector<std::uint8_t> b{0x05, 0x01, 0x09, 0x01};
        for (std::size_t i = 0; i < n; ++i) {
            b.insert(b.end(), {0xA1, 0x00});
        }
        b.insert(b.end(), {0x75, 0x01, 0x95, 0x01, 0x81, 0x02});
        b.insert(b.end(), n, 0xC0);
        return b;
    };
    ASSERT_TRUE(parseReportDescriptor(nested(kMaxCollectionDepth)));
    EXPECT_EQ(parseReportDescriptor(nested(kMaxCollectionDepth))->fields.at(0).collections.size(),
              kMaxCollectionDepth);
    expectError(nested(kMaxCollectionDepth + 1), "collections nested deeper than 32 levels");
    expectError(nested(1000), "byte 68: collections nested deeper than 32");

    // 61 report IDs x 16 Input items of 4,096 one-bit values: 4 million fields in 1 KiB.
    std::vector<std::uint8_t> many{0x05, 0x01, 0x19, 0x01, 0x29, 0x10, 0x75, 0x01,
                                   0x96, 0x00, 0x10, 0x15, 0x00, 0x25, 0x01};
    for (int id = 1; id <= 61; ++id) {
        many.insert(many.end(), {0x85, static_cast<std::uint8_t>(id)});
        for (int k = 0; k < 16; ++k) {
            many.insert(many.end(), {0x81, 0x02});
        }
    }
    ASSERT_LE(many.size(), kMaxDescriptorBytes);
    // 12288 fields is three items of 4096: the fourth item (report 1's) crosses the limit.
    expectError(many, "more than 12288 fields in all (the limit)");
    expectError(std::vector<std::uint8_t>(kMaxDescriptorBytes + 1, 0x00),
                "HID report descriptor of 4097 bytes, more than the 4096");
    expectError({0x75, 0x01, 0x96, 0x01, 0x10, 0x81, 0x02},
                "Report Count 4097 is more than the 4096");
    // 4,096 values of 64 bits: 32 KiB, more than a report may hold.
    expectError({0x75, 0x40, 0x96, 0x00, 0x10, 0x81, 0x02},
                "input report 0 grows beyond 8192 bytes");
    std::vector<std::uint8_t> pushes(kMaxPushDepth + 1, 0xA4);
    expectError(pushes, "Push nested deeper than 16 levels");
    // Collections side by side: 1,025 of them in under 4 KiB.
    std::vector<std::uint8_t> wide;
    for (std::size_t i = 0; i <= kMaxCollections; ++i) {
        wide.insert(wide.end(), {0xA1, 0x00, 0xC0});
    }
    expectError(wide, "more than 1024 collections (the limit)");
    // A usage range is not spelled out: 4,096 values over a 65,536-usage range take their usages
    // from it in order.
    std::vector<std::uint8_t> range{0x05, 0x01, 0x1A, 0x00, 0x00, 0x2A, 0xFF, 0xFF,
                                    0x75, 0x01, 0x96, 0x00, 0x10, 0x81, 0x02};
    auto r = parseReportDescriptor(range);
    ASSERT_TRUE(r) << r.error().message;
    ASSERT_EQ(r->fields.size(), 4096u);
    EXPECT_EQ(r->fields[4095].usage, usage(0x01, 4095));
    EXPECT_EQ(r->fields[4095].bitOffset, 4095u);
}

TEST(HidEyeHead, LayoutsAreFoundAndNonTrackersRefused)
{
    auto a = eht::findLayout(*parseReportDescriptor(kDescriptorA));
    ASSERT_TRUE(a) << a.error().message;
    EXPECT_EQ(a->inputReportId, 1);
    EXPECT_TRUE(a->head && a->leftEye && a->rightEye);
    EXPECT_EQ(a->wantedMode(), eht::kModeEyePosition | eht::kModeHeadPosition);
    EXPECT_DOUBLE_EQ(a->secondsPerTick, 1e-6);
    auto b = eht::findLayout(*parseReportDescriptor(kDescriptorB));
    ASSERT_TRUE(b) << b.error().message;
    EXPECT_EQ(b->wantedMode(), eht::kModeHeadPosition);
    EXPECT_FALSE(b->leftEye);
    EXPECT_DOUBLE_EQ(b->secondsPerTick, 1e-3);

    // A boot mouse (Generic Desktop page): not a tracker.
    const std::vector<std::uint8_t> mouse{0x05, 0x01, 0x09, 0x02, 0xA1, 0x01, 0x09,
                                          0x30, 0x09, 0x31, 0x15, 0x81, 0x25, 0x7F,
                                          0x75, 0x08, 0x95, 0x02, 0x81, 0x06, 0xC0};
    auto m = eht::findLayout(*parseReportDescriptor(mouse));
    ASSERT_FALSE(m);
    EXPECT_NE(m.error().message.find("not an eye or head tracker"), std::string::npos);
    // A gaze-only eye tracker: no viewer position.
    const std::vector<std::uint8_t> gaze{0x05, 0x12, 0x09, 0x01, 0xA1, 0x01, 0x09, 0x24,
                                         0xA1, 0x00, 0x09, 0x21, 0x09, 0x22, 0x75, 0x20,
                                         0x95, 0x02, 0x81, 0x02, 0xC0, 0xC0};
    auto g = eht::findLayout(*parseReportDescriptor(gaze));
    ASSERT_FALSE(g);
    EXPECT_NE(g.error().message.find("neither a head position"), std::string::npos);
}

TEST(HidTracker, NumberedDeviceIsConfiguredAndGivesTheEyeMidpoint)
{
    auto s = deviceA();
    hal::VirtualClock clock;
    auto r = HidTrackerReader::open(std::make_unique<FakeHidTracker>(s), clock, {});
    ASSERT_TRUE(r) << r.error().message;
    const auto& d = r->description();
    ASSERT_TRUE(d.status && d.quality && d.screenWidthM && d.screenHeightM && d.samplingHz);
    EXPECT_EQ(*d.status, eht::kStatusReady);
    EXPECT_EQ(*d.quality, 1);
    EXPECT_NEAR(*d.screenWidthM, 0.5184, 1e-12);
    EXPECT_NEAR(*d.screenHeightM, 0.324, 1e-12);
    EXPECT_DOUBLE_EQ(*d.samplingHz, 120.0);
    // The mode request went to report 5 with eye (2) and head (4) positions on.
    ASSERT_EQ(s->sentFeatures.size(), 1u);
    EXPECT_EQ(s->sentFeatures[0], (std::vector<std::uint8_t>{5, 6}));

    s->inputs.push_back(reportA(1'000'000, {-32'000, 10'000, 600'000}, {32'000, 12'000, 610'000},
                                {0, 60'000, 650'000}));
    clock.set(2'000'000'000);
    auto p = r->next();
    ASSERT_TRUE(p && *p);
    EXPECT_TRUE((*p)->tracked);
    EXPECT_NEAR((*p)->eyeTrackerM.x, 0.0, 1e-12);
    EXPECT_NEAR((*p)->eyeTrackerM.y, 0.011, 1e-12);
    EXPECT_NEAR((*p)->eyeTrackerM.z, 0.605, 1e-12);
    EXPECT_EQ((*p)->timestampNs, 2'000'000'000);

    // One eye lost (the value outside the logical range): the head position stands in.
    s->inputs.push_back(reportA(1'008'333, {INT32_MIN, 0, 0}, {32'000, 12'000, 610'000},
                                {1'000, 60'000, 650'000}));
    clock.set(2'010'000'000);
    p = r->next();
    ASSERT_TRUE(p && *p);
    EXPECT_TRUE((*p)->tracked);
    EXPECT_NEAR((*p)->eyeTrackerM.x, 0.001, 1e-12);
    EXPECT_NEAR((*p)->eyeTrackerM.z, 0.650, 1e-12);
    // Stamped with the device's clock: 8.333 ms after the first, not at its late arrival.
    EXPECT_EQ((*p)->timestampNs, 2'008'333'000);
}

// Hostile input reports (issue 32): longer and shorter than the descriptor says, an ID the
// descriptor does not declare, every field at its type's extremes. Each is a counted drop or a
// sample, finite and untracked where nothing is in range; never a crash, a hang or a NaN.
TEST(HidTracker, HostileReportsAreCountedOrDecodedNeverACrash)
{
    auto s = deviceA();
    hal::VirtualClock clock;
    auto r = HidTrackerReader::open(std::make_unique<FakeHidTracker>(s), clock, {});
    ASSERT_TRUE(r) << r.error().message;
    auto good = reportA(1'000'000, {-32'000, 10'000, 600'000}, {32'000, 12'000, 610'000},
                        {0, 60'000, 650'000});
    auto longer = good;
    longer.resize(4096, 0xAB); // the reader's buffer takes the descriptor's size + 64
    std::vector<std::uint8_t> shorter(good.begin(), good.begin() + 20);
    auto unknownId = good;
    unknownId[0] = 0x7F; // the descriptor declares IDs 1-5
    auto featureId = good;
    featureId[0] = 3; // declared (a feature report): of no use here, not a fault
    // A device time of 2^63-1 us: 9.2e27 ns, which overflowed the rounding and the anchoring.
    // The eyes at the logical minimum's wrong side (out of range), the head at the logical maximum
    // (in range: 2147 m, absurd but finite).
    auto extremes = reportA(0x7FFF'FFFF'FFFF'FFFF, {INT32_MIN, INT32_MAX, INT32_MAX},
                            {INT32_MAX, INT32_MIN, INT32_MIN}, {INT32_MAX, INT32_MAX, INT32_MAX});
    auto allOut = reportA(1'050'000, {INT32_MIN, INT32_MIN, INT32_MIN},
                          {INT32_MIN, INT32_MIN, INT32_MIN}, {INT32_MIN, INT32_MIN, INT32_MIN});
    std::vector<std::uint8_t> idOnly{1};
    std::vector<std::uint8_t> empty;
    for (auto* rep :
         {&longer, &shorter, &unknownId, &featureId, &extremes, &idOnly, &empty, &allOut}) {
        s->inputs.push_back(*rep);
    }
    std::vector<hal::PoseSample> got;
    for (int i = 0; i < 8; ++i) {
        clock.set(2'000'000'000 + i * 10'000'000);
        auto p = r->next();
        ASSERT_TRUE(p) << i << ": " << p.error().message;
        if (*p) {
            got.push_back(**p);
        }
    }
    // The longer report decodes as its first 53 bytes. The extremes give the head's position,
    // finite, stamped at arrival (the device time is refused). Every position out of range: a
    // sample, untracked.
    ASSERT_EQ(got.size(), 3u);
    EXPECT_TRUE(got[0].tracked);
    EXPECT_NEAR(got[0].eyeTrackerM.z, 0.605, 1e-12);
    EXPECT_TRUE(got[1].tracked);
    EXPECT_NEAR(std::abs(got[1].eyeTrackerM.z), 2147.483647, 1e-6);
    EXPECT_TRUE(std::isfinite(got[1].eyeTrackerM.x) && std::isfinite(got[1].eyeTrackerM.y));
    EXPECT_EQ(got[1].timestampNs, 2'040'000'000);
    EXPECT_FALSE(got[2].tracked);
    EXPECT_EQ(got[2].eyeTrackerM, glm::dvec3(0.0));
    // Counted: the short one, the undeclared ID, the ID byte alone, the empty one; a declared
    // feature report's ID is of no use here but not a fault.
    EXPECT_EQ(r->rejectedReports(), 4);
}

TEST(HidTracker, UnnumberedDeviceKeepsOtherFeatureBytesAndReadsMillimetres)
{
    auto s = deviceB();
    hal::VirtualClock clock;
    HidTrackerOptions o;
    o.axes.sign = {1.0, -1.0, 1.0}; // this device's y points down
    auto r = HidTrackerReader::open(std::make_unique<FakeHidTracker>(s), clock, o);
    ASSERT_TRUE(r) << r.error().message;
    const auto& d = r->description();
    EXPECT_EQ(*d.status, eht::kStatusUserCalibrationNeeded);
    EXPECT_NEAR(*d.screenWidthM, 0.51816, 1e-12);
    EXPECT_NEAR(*d.screenHeightM, 0.324104, 1e-12);
    ASSERT_EQ(s->sentFeatures.size(), 1u);
    // ID 0, status kept at 4, mode 4 (head), the screen size bytes unchanged.
    EXPECT_EQ(s->sentFeatures[0], (std::vector<std::uint8_t>{0, 4, 4, 0xF8, 0x07, 0xFC, 0x04}));

    s->inputs.push_back(reportB(5000, 123, -456, 6789));
    clock.set(1'000'000'000);
    auto p = r->next();
    ASSERT_TRUE(p && *p);
    EXPECT_TRUE((*p)->tracked);
    EXPECT_NEAR((*p)->eyeTrackerM.x, 0.123, 1e-12);
    EXPECT_NEAR((*p)->eyeTrackerM.y, 0.456, 1e-12);
    EXPECT_NEAR((*p)->eyeTrackerM.z, 6.789, 1e-12);

    // The null value (-32768): not tracked.
    s->inputs.push_back(reportB(5017, -32768, 0, 0));
    clock.set(1'020'000'000);
    p = r->next();
    ASSERT_TRUE(p && *p);
    EXPECT_FALSE((*p)->tracked);
    EXPECT_EQ((*p)->timestampNs, 1'017'000'000);

    // A short report is dropped and counted; it changes nothing.
    auto shortReport = reportB(5033, 1, 2, 3);
    shortReport.resize(9);
    s->inputs.push_back(shortReport);
    p = r->next();
    ASSERT_TRUE(p);
    EXPECT_FALSE(*p);
    EXPECT_EQ(r->rejectedReports(), 1);
}

TEST(HidTracker, DeviceTimestampsAreAnchoredToTheLeastDelayedArrival)
{
    auto s = deviceB();
    hal::VirtualClock clock;
    auto r = HidTrackerReader::open(std::make_unique<FakeHidTracker>(s), clock, {});
    ASSERT_TRUE(r);
    // Reports every 10 ms of device time; arrivals delayed by 4, 1, 6 ms: the second is the
    // least delayed, so from it on the offset is (arrival - device time) = 1 ms + base.
    const std::int64_t base = 3'000'000'000;
    const std::int64_t delays[] = {4'000'000, 1'000'000, 6'000'000, 2'000'000};
    std::vector<std::int64_t> stamps;
    for (int i = 0; i < 4; ++i) {
        s->inputs.push_back(reportB(static_cast<std::uint32_t>(100 + 10 * i), 1, 1, 1));
        clock.set(base + 10'000'000 * i + delays[i]);
        auto p = r->next();
        ASSERT_TRUE(p && *p);
        stamps.push_back((*p)->timestampNs);
    }
    const std::int64_t dev0 = base - 100'000'000; // session time of device time 0 on 1st report
    EXPECT_EQ(stamps[0], dev0 + 100'000'000 + 4'000'000);
    EXPECT_EQ(stamps[1], dev0 + 110'000'000 + 1'000'000);
    EXPECT_EQ(stamps[2], dev0 + 120'000'000 + 1'000'000);
    EXPECT_EQ(stamps[3], dev0 + 130'000'000 + 1'000'000);
    // The device clock resets (replug without a reopen): re-anchored, still monotonic.
    s->inputs.push_back(reportB(5, 1, 1, 1));
    clock.set(base + 50'000'000);
    auto p = r->next();
    ASSERT_TRUE(p && *p);
    EXPECT_EQ((*p)->timestampNs, base + 50'000'000);
}

bool sameEyeBits(const glm::dvec3& a, const glm::dvec3& b)
{
    for (int i = 0; i < 3; ++i) {
        if (std::bit_cast<std::uint64_t>(a[i]) != std::bit_cast<std::uint64_t>(b[i])) {
            return false;
        }
    }
    return true;
}

// Raw in, processed out: each pose carries its report as received and the descriptor of its
// opening; recorded and read back, reprocessing the reports gives the same poses bit for bit
// (device-clock anchoring included), and another axis mapping changes them.
TEST(HidTracker, RawReportsAreRecordedAndReprocessToTheSamePoses)
{
    hal::VirtualClock clock;
    std::vector<hal::PoseSample> live;
    std::uint32_t seq = 0;
    for (int opening = 0; opening < 2; ++opening) { // a replug: a second opening
        auto s = deviceA();
        auto r = HidTrackerReader::open(std::make_unique<FakeHidTracker>(s), clock, {});
        ASSERT_TRUE(r) << r.error().message;
        // The 90 ms delay re-anchors the device clock (more than 50 ms behind).
        const std::int64_t delays[] = {4'000'000, 1'000'000, 6'000'000, 90'000'000, 2'000'000};
        for (int i = 0; i < 5; ++i) {
            const auto sent = reportA(static_cast<std::uint64_t>(1'000'000 + 8'333 * i),
                                      {-32'000 + 1'000 * (i + 1), 10'000, 600'000},
                                      {32'000, 12'000, 610'000}, {0, 60'000, 650'000});
            s->inputs.push_back(sent);
            clock.set(opening * 5'000'000'000LL + 1'000'000'000 + 8'333'000 * i + delays[i]);
            auto p = r->next();
            ASSERT_TRUE(p && *p);
            hal::PoseSample sample = **p;
            sample.sequence = seq++;
            ASSERT_TRUE(sample.raw);
            EXPECT_EQ(sample.raw->kind, hal::RawTrackerInput::Kind::HidReport);
            EXPECT_EQ(sample.raw->arrivalNs, clock.nowNs());
            EXPECT_EQ(sample.raw->bytes, sent);
            live.push_back(sample);
        }
    }
    ASSERT_EQ(*live[0].raw->hidDescriptor, kDescriptorA);
    EXPECT_EQ(live[0].raw->hidDescriptor, live[4].raw->hidDescriptor);
    EXPECT_NE(live[4].raw->hidDescriptor, live[5].raw->hidDescriptor);

    const auto path = std::filesystem::temp_directory_path() /
                      ("replica-hid-raw-" + std::to_string(::getpid()) + ".mcap");
    {
        recordings::SessionInfo session;
        session.softwareVersion = "test";
        auto w = recordings::RecordingWriter::create(path, session);
        ASSERT_TRUE(w) << w.error().message;
        for (const auto& p : live) {
            (*w)->write(p);
        }
        ASSERT_TRUE((*w)->close());
    }
    auto rec = recordings::readRecording(path);
    std::filesystem::remove(path);
    ASSERT_TRUE(rec) << rec.error().message;
    ASSERT_EQ(rec->samples(recordings::trackerKind()).size(), live.size());
    EXPECT_EQ(rec->unmatchedRaw, 0u);
    for (std::size_t i = 0; i < live.size(); ++i) {
        ASSERT_TRUE(rec->samples(recordings::trackerKind())[i].raw) << i;
        EXPECT_EQ(rec->samples(recordings::trackerKind())[i].raw->bytes, live[i].raw->bytes) << i;
        EXPECT_EQ(rec->samples(recordings::trackerKind())[i].raw->arrivalNs, live[i].raw->arrivalNs)
                << i;
    }
    EXPECT_EQ(*rec->samples(recordings::trackerKind())[0].raw->hidDescriptor, kDescriptorA);
    EXPECT_EQ(rec->samples(recordings::trackerKind())[0].raw->hidDescriptor,
              rec->samples(recordings::trackerKind())[4].raw->hidDescriptor);
    EXPECT_NE(rec->samples(recordings::trackerKind())[4].raw->hidDescriptor,
              rec->samples(recordings::trackerKind())[5].raw->hidDescriptor);

    // The processed values wiped: reprocessing must compute them again, bit for bit.
    auto wiped = *rec;
    for (auto& p : wiped.samples(recordings::trackerKind())) {
        p.eyeTrackerM = glm::dvec3(9.0);
        p.tracked = false;
    }
    auto rep = platform::reprocess(wiped, {});
    ASSERT_TRUE(rep) << rep.error().message;
    EXPECT_EQ(rep->posesReprocessed, live.size());
    EXPECT_EQ(rep->posesChanged, live.size());
    EXPECT_EQ(rep->poseTimesDiffer, 0u); // the anchoring re-ran as live, reanchor included
    for (std::size_t i = 0; i < live.size(); ++i) {
        EXPECT_TRUE(sameEyeBits(wiped.samples(recordings::trackerKind())[i].eyeTrackerM,
                                live[i].eyeTrackerM))
                << i;
        EXPECT_TRUE(wiped.samples(recordings::trackerKind())[i].tracked);
    }
    auto same = *rec;
    rep = platform::reprocess(same, {});
    ASSERT_TRUE(rep);
    EXPECT_EQ(rep->posesChanged, 0u);

    // A changed processing parameter: the device's x mirrored. The eye midpoint's x is
    // (left + right) / 2 = 500 (i + 1) um as the reports were written.
    auto mirrored = *rec;
    platform::ReprocessOptions o;
    o.trackerAxes = "-x,y,z";
    rep = platform::reprocess(mirrored, o);
    ASSERT_TRUE(rep);
    EXPECT_EQ(rep->posesChanged, live.size());
    for (std::size_t i = 0; i < live.size(); ++i) {
        EXPECT_NEAR(live[i].eyeTrackerM.x, 0.0005 * static_cast<double>(i % 5 + 1), 1e-12);
        EXPECT_NEAR(mirrored.samples(recordings::trackerKind())[i].eyeTrackerM.x,
                    -0.0005 * static_cast<double>(i % 5 + 1), 1e-12);
        EXPECT_EQ(mirrored.samples(recordings::trackerKind())[i].eyeTrackerM.z,
                  live[i].eyeTrackerM.z);
    }

    // Raw inputs that today's code cannot process: one line naming the pose, no crash.
    auto cut = *rec;
    auto shortRaw =
            std::make_shared<hal::RawTrackerInput>(*cut.samples(recordings::trackerKind())[2].raw);
    shortRaw->bytes.resize(20);
    cut.samples(recordings::trackerKind())[2].raw = shortRaw;
    rep = platform::reprocess(cut, {});
    ASSERT_FALSE(rep);
    EXPECT_NE(rep.error().message.find("pose 2: a 20-byte HID report that is too short"),
              std::string::npos)
            << rep.error().message;
    auto broken = *rec;
    auto badDescriptor = std::make_shared<hal::RawTrackerInput>(
            *broken.samples(recordings::trackerKind())[0].raw);
    badDescriptor->hidDescriptor =
            std::make_shared<const std::vector<std::uint8_t>>(std::vector<std::uint8_t>{0xC0});
    broken.samples(recordings::trackerKind())[0].raw = badDescriptor;
    rep = platform::reprocess(broken, {});
    ASSERT_FALSE(rep);
    EXPECT_NE(rep.error().message.find("pose 0: the recorded HID report descriptor"),
              std::string::npos)
            << rep.error().message;
    o.trackerAxes = "x,x,z";
    auto badAxes = *rec;
    rep = platform::reprocess(badAxes, o);
    ASSERT_FALSE(rep);
}

TEST(HidTracker, BrokenDevicesAreRefusedWithAReason)
{
    hal::VirtualClock clock;
    auto bad = deviceA();
    bad->descriptor.pop_back(); // the application collection never closes
    auto r = HidTrackerReader::open(std::make_unique<FakeHidTracker>(bad), clock, {});
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("fake hidraw"), std::string::npos) << r.error().message;
    EXPECT_NE(r.error().message.find("never closed"), std::string::npos) << r.error().message;

    auto gone = deviceA();
    gone->unplugged = true;
    r = HidTrackerReader::open(std::make_unique<FakeHidTracker>(gone), clock, {});
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::NotFound);

    // A device that refuses the mode request cannot stream: refused, not silently idle.
    auto stubborn = deviceA();
    stubborn->features[5] = {5, 0, 0}; // the firmware's control report is a byte longer
    r = HidTrackerReader::open(std::make_unique<FakeHidTracker>(stubborn), clock, {});
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("device mode request"), std::string::npos);
}

TEST(HidTracker, SourceGoesLostOnUnplugAndResumesAfterReplug)
{
    auto s = deviceA();
    hal::SteadyClock clock;
    auto opener = [s]() -> Expected<std::unique_ptr<HidDevice>> {
        std::lock_guard lock(s->mutex);
        if (s->unplugged) {
            return makeError(ErrorCode::NotFound, "fake: no HID eye/head tracker");
        }
        ++s->opens;
        return std::unique_ptr<HidDevice>(std::make_unique<FakeHidTracker>(s));
    };
    HidTrackerOptions o;
    o.reconnectNs = 20'000'000;
    auto src = hal::tracker::makeHidTrackerSource(opener, clock, o);
    auto waitFor = [&](auto cond) {
        const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(10);
        while (!cond() && std::chrono::steady_clock::now() < end) {
            std::this_thread::sleep_for(std::chrono::milliseconds(2));
        }
        return cond();
    };
    ASSERT_TRUE(waitFor([&] { return src->state() == hal::LinkState::Connected; }));
    {
        std::lock_guard lock(s->mutex);
        s->inputs.push_back(reportA(10, {0, 0, 500'000}, {0, 0, 500'000}, {0, 0, 0}));
    }
    std::vector<hal::PoseSample> got;
    ASSERT_TRUE(waitFor([&] {
        src->poll(clock.nowNs(), got);
        return !got.empty();
    }));
    EXPECT_NEAR(got.back().eyeTrackerM.z, 0.5, 1e-12);

    {
        std::lock_guard lock(s->mutex);
        s->unplugged = true;
    }
    ASSERT_TRUE(waitFor([&] { return src->state() == hal::LinkState::Lost; }));
    {
        std::lock_guard lock(s->mutex);
        s->unplugged = false;
        s->features[5][1] = 0; // a replugged device starts idle again
        s->inputs.push_back(reportA(20, {0, 0, 700'000}, {0, 0, 700'000}, {0, 0, 0}));
    }
    ASSERT_TRUE(waitFor([&] { return src->state() == hal::LinkState::Connected; }));
    got.clear();
    ASSERT_TRUE(waitFor([&] {
        src->poll(clock.nowNs(), got);
        for (const auto& p : got) {
            if (p.tracked && std::abs(p.eyeTrackerM.z - 0.7) < 1e-12) {
                return true;
            }
        }
        return false;
    }));
    EXPECT_EQ(s->opens, 2);
    EXPECT_EQ(s->mode(), 6); // configured again after the replug
}

TEST(HidTracker, SysfsListingFindsTrackersAndExplainsBrokenOnes)
{
    const auto root = std::filesystem::temp_directory_path() /
                      ("replica-hidraw-" + std::to_string(::getpid()));
    std::filesystem::remove_all(root);
    auto node = [&](const std::string& name, const std::vector<std::uint8_t>& desc,
                    const std::string& uevent) {
        const auto dir = root / name / "device";
        std::filesystem::create_directories(dir);
        std::ofstream(dir / "report_descriptor", std::ios::binary)
                .write(reinterpret_cast<const char*>(desc.data()),
                       static_cast<std::streamsize>(desc.size()));
        std::ofstream(dir / "uevent") << uevent;
    };
    node("hidraw0",
         {0x05, 0x01, 0x09, 0x02, 0xA1, 0x01, 0x09, 0x30, 0x75, 0x08, 0x95, 0x01, 0x81, 0x02, 0xC0},
         "HID_ID=0003:0000046D:0000C52B\nHID_NAME=Logitech Mouse\n");
    node("hidraw1", kDescriptorA,
         "DRIVER=hid-generic\nHID_ID=0003:00002104:00000127\nHID_NAME=Acme Eye Tracker 5\n");
    auto broken = kDescriptorB;
    broken.resize(20);
    node("hidraw2", broken, "HID_ID=0003:00001234:00005678\nHID_NAME=Broken Tracker\n");
    const auto list = listHidTrackers(root, "/dev");
    ASSERT_EQ(list.size(), 2u);
    EXPECT_EQ(list[0].devNode, "/dev/hidraw1");
    EXPECT_EQ(list[0].vendor, 0x2104);
    EXPECT_EQ(list[0].product, 0x0127);
    EXPECT_EQ(list[0].name, "Acme Eye Tracker 5");
    EXPECT_TRUE(list[0].error.empty());
    EXPECT_NE(list[0].layout.find("eye tracker, input report 1 (53 bytes)"), std::string::npos)
            << list[0].layout;
    EXPECT_EQ(list[1].devNode, "/dev/hidraw2");
    EXPECT_NE(list[1].error.find("never closed"), std::string::npos) << list[1].error;

    // The real opener names what is missing.
    auto none = hidapiOpener("", root / "empty")();
    ASSERT_FALSE(none);
    EXPECT_EQ(none.error().code, ErrorCode::NotFound);
    EXPECT_NE(none.error().message.find("--tracker opentrack"), std::string::npos);
    auto missing = hidapiOpener("/dev/hidraw9", root)();
    ASSERT_FALSE(missing);
    EXPECT_NE(missing.error().message.find("/dev/hidraw9: no such HID device"), std::string::npos);
    std::filesystem::remove_all(root);
}

} // namespace
} // namespace replica::tests
