// The HID eye/head tracker's reading of what a descriptor says about its values (HID 1.11
// 6.2.2.7; the Eye and Head Trackers page 0x12 of the HID Usage Tables): the Unit Exponent
// nibble in items of any size and exponents no device can mean. Each descriptor is written here
// byte by byte; the expected values follow from the spec's formulas applied by hand to those
// bytes. The cases are those of an independent probe of this path (F3-F5 of its report).
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

} // namespace hid_units
} // namespace replica::tests
