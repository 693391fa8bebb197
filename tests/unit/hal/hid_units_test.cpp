// The HID eye/head tracker's reading of what a descriptor says about its values (HID 1.11
// 6.2.2.7; the Eye and Head Trackers page 0x12 of the HID Usage Tables): physical ranges, each
// axis's own unit, the Unit Exponent nibble in items of any size, exponents no device can mean,
// Logical Minimum above Maximum, Relative positions, and one usage spread over byte fields (the
// timestamp of Microsoft's reference tracker). Each descriptor is written here byte by byte; the
// expected values follow from the spec's formulas applied by hand to those bytes. The cases are
// those of an independent probe of this path (F1-F7 and F10 of its report).
#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <hal/tracker/hid_descriptor.h>
#include <hal/tracker/hid_eye_head.h>
#include <hal/tracker/hid_tracker_source.h>

#include <gtest/gtest.h>

namespace replica::tests {
namespace hid_units {

namespace hid = hal::hid;
namespace eht = hal::hid::eht;
using Bytes = std::vector<std::uint8_t>;

// Where the bytes under test start in headTracker's descriptor: the offsets below count from it.
constexpr std::size_t kBodyAt = 16;

// A head tracker, numbered report 1, whose Head Position collection holds 'position' (global
// items, usages and Input items): the frame around the bytes under test.
Bytes headTracker(const Bytes& position)
{
    Bytes b = {
            0x05, 0x12, // Usage Page (Eye and Head Trackers)
            0x09, 0x02, // Usage (Head Tracker)
            0xA1, 0x01, // Collection (Application)
            0x85, 0x01, //   Report ID (1)
            0x09, 0x10, //   Usage (Tracking Data)
            0xA1, 0x00, //   Collection (Physical)
            0x09, 0x27, //     Usage (Head Position)
            0xA1, 0x00, //     Collection (Physical)
    };
    EXPECT_EQ(b.size(), kBodyAt);
    b.insert(b.end(), position.begin(), position.end());
    b.insert(b.end(), {0xC0, 0xC0, 0xC0});
    return b;
}

// Three signed 16-bit values (X, Y, Z) after the ID byte 1.
Bytes report16(std::int16_t x, std::int16_t y, std::int16_t z)
{
    Bytes r{1};
    for (const std::int16_t v : {x, y, z}) {
        const auto w = static_cast<std::uint16_t>(v);
        r.push_back(static_cast<std::uint8_t>(w & 0xFF));
        r.push_back(static_cast<std::uint8_t>(w >> 8));
    }
    return r;
}

eht::Layout layoutOf(const Bytes& descriptor)
{
    auto layout = hal::tracker::trackerLayout(descriptor);
    EXPECT_TRUE(layout) << layout.error().message;
    return layout ? *layout : eht::Layout{};
}

glm::dvec3 headOf(const eht::Layout& layout, const Bytes& report)
{
    eht::TrackingReport r;
    EXPECT_EQ(eht::decodeTracking(layout, report, r), eht::DecodeResult::Ok);
    EXPECT_TRUE(r.headM);
    return r.headM ? *r.headM : glm::dvec3(-99.0);
}

void expectRefused(const Bytes& descriptor, const std::string& what)
{
    auto layout = hal::tracker::trackerLayout(descriptor);
    ASSERT_FALSE(layout) << "taken as a tracker: " << layout->summary() << "; wanted " << what;
    EXPECT_NE(layout.error().message.find(what), std::string::npos) << layout.error().message;
}

// F1: logical 0..4095 over physical -2000..2000, in cm x 10^-1 (mm). The spec's physical value is
// (logical - 0) * (2000 - -2000) / (4095 - 0) + -2000 mm; the product read the logical value as
// millimetres (2.06 m off, finite, inside every plausibility limit).
TEST(HidUnits, PhysicalRangeRescalesTheLogicalValue)
{
    const Bytes d = headTracker({
            0x15, 0x00,                         // Logical Minimum (0)
            0x26, 0xFF, 0x0F,                   // Logical Maximum (4095)
            0x36, 0x30, 0xF8,                   // Physical Minimum (-2000)
            0x46, 0xD0, 0x07,                   // Physical Maximum (2000)
            0x65, 0x11,                         // Unit (SI linear: cm)
            0x55, 0x0F,                         // Unit Exponent (-1)
            0x09, 0x21, 0x09, 0x22, 0x09, 0x23, // Usage (Position X, Y, Z)
            0x75, 0x10, 0x95, 0x03, 0x81, 0x02, // Report Size 16, Count 3, Input (Data, Var, Abs)
    });
    const auto layout = layoutOf(d);
    const glm::dvec3 m = headOf(layout, report16(0, 4095, 2048));
    EXPECT_NEAR(m.x, -2.0, 1e-12);
    EXPECT_NEAR(m.y, 2.0, 1e-12);
    EXPECT_NEAR(m.z, (2048.0 * 4000.0 / 4095.0 - 2000.0) * 1e-3, 1e-12); // 0.000488 m
    const glm::dvec3 mid = headOf(layout, report16(1000, 3000, 4000));
    EXPECT_NEAR(mid.x, (1000.0 * 4000.0 / 4095.0 - 2000.0) * 1e-3, 1e-12);
    EXPECT_NEAR(mid.z, (4000.0 * 4000.0 / 4095.0 - 2000.0) * 1e-3, 1e-12);

    // Physical Minimum and Maximum both 0: physical = logical (the spec's default).
    const Bytes plain = headTracker({0x15, 0x00, 0x26, 0xFF, 0x0F, 0x35, 0x00, 0x45, 0x00,
                                     0x65, 0x11, 0x55, 0x0F, 0x09, 0x21, 0x09, 0x22, 0x09,
                                     0x23, 0x75, 0x10, 0x95, 0x03, 0x81, 0x02});
    EXPECT_NEAR(headOf(layoutOf(plain), report16(0, 4095, 600)).z, 0.6, 1e-12);

    // A physical range over an empty logical range (0..0) cannot be scaled: refused, naming the
    // Input item (byte 18 of the body).
    expectRefused(headTracker({0x36, 0x30, 0xF8, 0x46, 0xD0, 0x07, 0x65, 0x11, 0x09, 0x21,
                               0x09, 0x22, 0x09, 0x23, 0x75, 0x10, 0x95, 0x03, 0x81, 0x02}),
                  "byte " + std::to_string(kBodyAt + 18) +
                          ": Head Position X has physical range -2000..2000 over the empty "
                          "logical range 0..0");
}

// F2: X and Y in cm x 10^-1 (mm), Z in cm x 10^0: each axis its own unit. The product scaled
// Z by X's unit (0.082 m for 0.82 m).
TEST(HidUnits, EachAxisHasItsOwnUnit)
{
    const Bytes d = headTracker({
            0x16, 0x00, 0x80, 0x26, 0xFF, 0x7F, // Logical -32768..32767
            0x65, 0x11, 0x55, 0x0F,             // Unit (cm), Unit Exponent (-1): mm
            0x75, 0x10, 0x95, 0x02,             // Report Size 16, Report Count 2
            0x09, 0x21, 0x09, 0x22, 0x81, 0x02, // Usage (X), Usage (Y), Input
            0x55, 0x00,                         // Unit Exponent (0): cm
            0x95, 0x01, 0x09, 0x23, 0x81, 0x02, // Report Count 1, Usage (Z), Input
    });
    const auto layout = layoutOf(d);
    const glm::dvec3 m = headOf(layout, report16(100, -50, 82));
    EXPECT_NEAR(m.x, 0.1, 1e-12);
    EXPECT_NEAR(m.y, -0.05, 1e-12);
    EXPECT_NEAR(m.z, 0.82, 1e-12);
    EXPECT_NE(layout.summary().find("head in mm (x, y), cm (z)"), std::string::npos)
            << layout.summary();
}

// Both eyes, each in its own unit: left in mm, right in inch x 10^-2. The eye midpoint is of the
// two in metres.
TEST(HidUnits, EachEyeHasItsOwnUnit)
{
    Bytes d = {0x05, 0x12, 0x09, 0x01, 0xA1, 0x01, 0x85, 0x01, // Eye Tracker, report 1
               0x16, 0x00, 0x80, 0x26, 0xFF, 0x7F, 0x75, 0x10, // int16
               0x09, 0x25, 0xA1, 0x00,                         // Left Eye Position
               0x65, 0x11, 0x55, 0x0F,                         //   mm
               0x09, 0x21, 0x09, 0x22, 0x09, 0x23, 0x95, 0x03, 0x81, 0x02,
               0xC0, 0x09, 0x26, 0xA1, 0x00, //   Right Eye Position
               0x65, 0x13, 0x55, 0x0E,       //   Unit (English linear: inch), Unit Exponent (-2)
               0x09, 0x21, 0x09, 0x22, 0x09, 0x23, 0x81, 0x02, 0xC0, 0xC0};
    const auto layout = layoutOf(d);
    Bytes r = report16(-32, 10, 600);            // left: mm
    const Bytes right = report16(126, 39, 2362); // right: 0.01 inch
    r.insert(r.end(), right.begin() + 1, right.end());
    eht::TrackingReport t;
    ASSERT_EQ(eht::decodeTracking(layout, r, t), eht::DecodeResult::Ok);
    ASSERT_TRUE(t.leftEyeM && t.rightEyeM);
    EXPECT_NEAR(t.leftEyeM->z, 0.6, 1e-12);
    EXPECT_NEAR(t.rightEyeM->x, 1.26 * 0.0254, 1e-12);
    EXPECT_NEAR(t.rightEyeM->z, 23.62 * 0.0254, 1e-12);
    EXPECT_NE(layout.summary().find("left eye in mm, right eye in 0.000254 m"), std::string::npos)
            << layout.summary();
}

// F3: the Unit Exponent is a 4-bit two's-complement nibble whatever the item's size: `56 0D 00`
// and `57 0D 00 00 00` are -3, as `55 0D` is; a value with bits above the nibble is a signed
// value (`55 FD`, `56 FD FF`: -3). The product read the 2-byte form as +13 (a head 8e15 m away).
TEST(HidUnits, UnitExponentNibbleInItemsOfEverySize)
{
    const std::vector<Bytes> exponents = {
            {0x55, 0x0D}, {0x56, 0x0D, 0x00}, {0x57, 0x0D, 0x00, 0x00, 0x00},
            {0x55, 0xFD}, {0x56, 0xFD, 0xFF}, {0x57, 0xFD, 0xFF, 0xFF, 0xFF}};
    for (const Bytes& e : exponents) {
        Bytes body = {0x16, 0x00, 0x80, 0x26, 0xFF, 0x7F, 0x65, 0x11}; // int16, cm
        body.insert(body.end(), e.begin(), e.end());
        body.insert(body.end(),
                    {0x09, 0x21, 0x09, 0x22, 0x09, 0x23, 0x75, 0x10, 0x95, 0x03, 0x81, 0x02});
        const glm::dvec3 m = headOf(layoutOf(headTracker(body)), report16(800, -20, 30000));
        SCOPED_TRACE(::testing::Message() << "exponent item of " << e.size() << " bytes");
        EXPECT_NEAR(m.x, 0.008, 1e-12); // 800 x 10^-3 cm
        EXPECT_NEAR(m.y, -0.0002, 1e-12);
        EXPECT_NEAR(m.z, 0.3, 1e-12);
    }
}

// F4, F5: an exponent outside -8..7 (after the nibble rule) is no unit: 400 made positions of
// inf m, 127 of 5e129 m, -400 and -2^31 a unit of 0 m that became "um (assumed)". Refused at the
// Unit Exponent item; every exponent in -8..7 is taken.
TEST(HidUnits, UnitExponentOutsideTheNibbleRangeIsRefusedNamingTheByte)
{
    struct Case {
        Bytes item;
        std::string says;
    };
    const std::vector<Case> cases = {
            {{0x57, 0x90, 0x01, 0x00, 0x00}, "Unit Exponent 400 (0x190 in 4 bytes)"},
            {{0x55, 0x7F}, "Unit Exponent 127 (0x7f in 1 byte)"},
            {{0x57, 0x70, 0xFE, 0xFF, 0xFF}, "Unit Exponent -400"},
            {{0x57, 0x00, 0x00, 0x00, 0x80}, "Unit Exponent -2147483648"},
            {{0x55, 0x10}, "Unit Exponent 16"},
            {{0x55, 0xF7}, "Unit Exponent -9"},
            {{0x56, 0x00, 0x01}, "Unit Exponent 256"},
    };
    for (const Case& c : cases) {
        Bytes body = {0x65, 0x11};
        body.insert(body.end(), c.item.begin(), c.item.end());
        body.insert(body.end(),
                    {0x09, 0x21, 0x09, 0x22, 0x09, 0x23, 0x75, 0x10, 0x95, 0x03, 0x81, 0x02});
        auto d = hid::parseReportDescriptor(headTracker(body));
        ASSERT_FALSE(d) << c.says << ": parsed";
        const std::string want = "byte " + std::to_string(kBodyAt + 2) + ": " + c.says;
        EXPECT_NE(d.error().message.find(want), std::string::npos) << d.error().message;
        EXPECT_NE(d.error().message.find("outside -8..7"), std::string::npos);
    }
    for (int e = -8; e <= 7; ++e) {
        const auto nibble = static_cast<std::uint8_t>(e & 0xF);
        const Bytes body = {0x16, 0x00, 0x80, 0x26, 0xFF, 0x7F, 0x65, 0x11, 0x55, nibble, 0x09,
                            0x21, 0x09, 0x22, 0x09, 0x23, 0x75, 0x10, 0x95, 0x03, 0x81,   0x02};
        const glm::dvec3 m = headOf(layoutOf(headTracker(body)), report16(1, 2, 3));
        const double want = 3.0 * 0.01 * std::pow(10.0, e);
        EXPECT_NEAR(m.z, want, 1e-12 * want) << "exponent " << e;
    }
}

// F6: Logical Minimum above Logical Maximum (HID 1.11 6.2.2.7 asks min <= max). Min 100, max 50
// was read unsigned (-31500 as 4294935796: an eye 2147 m away); min -50, max -100 made every
// value "in range". F10: a Relative position decoded as absolute. A unit that is not a length
// (cm^2) read as "um (assumed)". Each refused naming its Input item (byte 18 of the body).
TEST(HidUnits, PositionFieldsThatCannotBeReadAreRefusedNamingTheByte)
{
    const std::string at = "byte " + std::to_string(kBodyAt + 18) + ": Head Position X ";
    auto body = [](std::initializer_list<std::uint8_t> globals, std::uint8_t flags) {
        Bytes b(globals);
        b.insert(b.end(),
                 {0x09, 0x21, 0x09, 0x22, 0x09, 0x23, 0x75, 0x10, 0x95, 0x03, 0x81, flags});
        return headTracker(b);
    };
    expectRefused(body({0x15, 0x64, 0x25, 0x32, 0x65, 0x11, 0x55, 0x0F}, 0x02),
                  at + "has Logical Minimum 100 above its Logical Maximum 50");
    expectRefused(body({0x15, 0xCE, 0x25, 0x9C, 0x65, 0x11, 0x55, 0x0F}, 0x02),
                  at + "has Logical Minimum -50 above its Logical Maximum -100");
    expectRefused(body({0x15, 0x81, 0x25, 0x7F, 0x65, 0x11, 0x55, 0x0F}, 0x06),
                  at + "is Relative (Input item bit 2)");
    expectRefused(body({0x15, 0x81, 0x25, 0x7F, 0x65, 0x21, 0x55, 0x0F}, 0x02),
                  at + "has Unit 0x21, which is not a length");
    // The same with a valid range, absolute, in cm: taken.
    EXPECT_TRUE(hal::tracker::trackerLayout(
            body({0x15, 0x81, 0x25, 0x7F, 0x65, 0x11, 0x55, 0x0F}, 0x02)));
}

// F7: Microsoft's reference eye tracker (GazeHid) declares its Sensor Timestamp as one usage over
// Report Size 8 x Report Count 8: the bytes of a uint64 microsecond counter, little-endian. The
// product read the first byte only: device times of 64 us, 205 us ... for 5 000 000 000 us, and
// session-time steps of 141 us to 16.5 ms for reports 8.333 ms apart.
TEST(HidUnits, OneUsageOverByteFieldsIsOneLittleEndianInteger)
{
    const Bytes d = {
            0x05, 0x12, 0x09, 0x01, 0xA1, 0x01, // Usage Page (0x12), Usage (Eye Tracker), App
            0xA1, 0x02,                         //   Collection (Logical)
            0x85, 0x10,                         //   Report ID (16)
            0x15, 0x00, 0x25, 0xFF,             //   Logical 0..255 (one unsigned byte)
            0x75, 0x08, 0x95, 0x03, 0x81, 0x01, //   3 bytes of padding (Input, Constant)
            0x09, 0x20, 0x95, 0x08, 0x81, 0x02, //   Usage (Sensor Timestamp), Count 8, Input
            0x95, 0x01, 0x75, 0x20,             //   Report Count 1, Report Size 32
            0x17, 0x00, 0x00, 0x00, 0x80,       //   Logical Minimum (-2^31)
            0x27, 0xFF, 0xFF, 0xFF, 0x7F,       //   Logical Maximum (2^31 - 1)
            0x09, 0x25, 0xA1, 0x00,             //   Left Eye Position, no unit (um)
            0x95, 0x03, 0x09, 0x21, 0x09, 0x22, 0x09, 0x23, 0x81, 0x02, 0xC0,
            0x09, 0x26, 0xA1, 0x00, //   Right Eye Position
            0x09, 0x21, 0x09, 0x22, 0x09, 0x23, 0x81, 0x02, 0xC0, 0xC0, 0xC0};
    const auto layout = layoutOf(d);
    EXPECT_NE(layout.summary().find("64-bit timestamp every 1e-06 s (assumed)"), std::string::npos)
            << layout.summary();
    auto report = [](std::uint64_t us) {
        Bytes r = {0x10, 0xAA, 0xBB, 0xCC}; // ID, padding
        for (int i = 0; i < 8; ++i) {
            r.push_back(static_cast<std::uint8_t>(us >> (8 * i)));
        }
        for (const std::int32_t v : {-31500, 50000, 600000, 31500, 50000, 600000}) {
            for (int i = 0; i < 4; ++i) {
                r.push_back(static_cast<std::uint8_t>(static_cast<std::uint32_t>(v) >> (8 * i)));
            }
        }
        return r;
    };
    eht::TrackingReport t;
    ASSERT_EQ(eht::decodeTracking(layout, report(5'000'000'000), t), eht::DecodeResult::Ok);
    ASSERT_TRUE(t.deviceTimeNs);
    EXPECT_EQ(*t.deviceTimeNs, 5'000'000'000'000);
    ASSERT_TRUE(t.leftEyeM);
    EXPECT_NEAR(t.leftEyeM->z, 0.6, 1e-12);

    // Reports 8.333 ms apart by the device clock, arriving 8.333333 ms apart: each is stamped
    // 8.333 ms after the one before.
    hal::tracker::HidReportProcessor p(layout, {}, 50'000'000);
    std::int64_t last = 0;
    for (int i = 0; i < 10; ++i) {
        hal::PoseSample s;
        const auto us = 5'000'000'000ull + static_cast<std::uint64_t>(i) * 8333;
        ASSERT_EQ(p.process(report(us), 1'000'000'000 + i * 8'333'333, s), eht::DecodeResult::Ok);
        if (i > 0) {
            EXPECT_EQ(s.timestampNs - last, 8'333'000) << "report " << i;
        }
        last = s.timestampNs;
    }
}

} // namespace hid_units
} // namespace replica::tests
