// The HID eye/head tracker's feature reports on open (usage page 0x12: Capabilities, Status,
// Control): values no int holds, a control report longer than 256 bytes, a mode request outside
// the field's declared range. Descriptors written byte by byte; the fake device answers with the
// bytes the test writes for them. The cases are those of an independent probe of this path
// (F8, F11 and F13 of its report).
#include <cstdint>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>
#include <tests/unit/hal/fake_hid_tracker.h>

#include <hal/clock.h>
#include <hal/tracker/hid_tracker_source.h>

#include <gtest/gtest.h>

namespace replica::tests {
namespace hid_features {

using Bytes = std::vector<std::uint8_t>;
using hal::tracker::HidTrackerReader;

// An eye tracker's tracking data, report 1: Head Position X, Y, Z as int16 in mm.
const Bytes kTrackingData = {
        0x05, 0x12, 0x09, 0x01, 0xA1, 0x01, // Usage Page (0x12), Usage (Eye Tracker), App
        0x85, 0x01, 0x09, 0x27, 0xA1, 0x00, //   Report ID (1), Usage (Head Position), Physical
        0x16, 0x00, 0x80, 0x26, 0xFF, 0x7F, //     Logical -32768..32767
        0x65, 0x11, 0x55, 0x0F,             //     Unit (cm), Unit Exponent (-1): mm
        0x09, 0x21, 0x09, 0x22, 0x09, 0x23, //     Usage (Position X, Y, Z)
        0x75, 0x10, 0x95, 0x03, 0x81, 0x02, //     16 bits x 3, Input (Data, Var, Abs)
        0xC0,                               //   End Collection
};

Bytes tracker(const Bytes& features)
{
    Bytes d = kTrackingData;
    d.insert(d.end(), features.begin(), features.end());
    d.push_back(0xC0); // End Collection (Application)
    return d;
}

void putLe(Bytes& r, std::size_t at, std::uint64_t v, int bytes)
{
    for (int i = 0; i < bytes; ++i) {
        r.at(at + static_cast<std::size_t>(i)) = static_cast<std::uint8_t>(v >> (8 * i));
    }
}

// Captures what the tracker logs while it lives.
class TrackerLog
{
public:
    TrackerLog()
    {
        spdlog::drop("hal.tracker");
        spdlog::register_logger(std::make_shared<spdlog::logger>(
                "hal.tracker", std::make_shared<spdlog::sinks::ostream_sink_mt>(text_)));
    }
    ~TrackerLog() { spdlog::drop("hal.tracker"); }
    TrackerLog(const TrackerLog&) = delete;
    TrackerLog& operator=(const TrackerLog&) = delete;
    std::string text() const { return text_.str(); }

private:
    std::ostringstream text_;
};

// F8: a Configuration Status of 2^40 (a 64-bit field) and a Tracker Quality declared in cm x 10^7
// (2147483647 of them: 2.1e14 m) are no int: the product cast them (undefined behaviour; UBSan:
// "inf is outside the range of representable values of type 'int'" with an exponent of 400) and
// reported status -2147483648. They are taken as not reported, and the log says so.
TEST(HidFeatures, ValuesNoIntHoldsAreNotReportedAndSaid)
{
    auto s = std::make_shared<FakeHidTrackerState>();
    s->descriptor = tracker({
            0x85, 0x02,                         // Report ID (2)
            0x09, 0x13, 0xA1, 0x02,             // Usage (Status), Collection (Logical)
            0x0A, 0x01, 0x03,                   //   Usage (Configuration Status)
            0x15, 0x00, 0x25, 0x04,             //   Logical 0..4
            0x65, 0x00, 0x55, 0x00,             //   no unit
            0x75, 0x40, 0x95, 0x01, 0xB1, 0x02, //   64 bits, Feature (Data, Var, Abs)
            0x0A, 0x00, 0x01,                   //   Usage (Tracker Quality)
            0x27, 0xFF, 0xFF, 0xFF, 0x7F,       //   Logical Maximum (2^31 - 1)
            0x65, 0x11, 0x55, 0x07,             //   Unit (cm), Unit Exponent (7)
            0x75, 0x20, 0xB1, 0x02,             //   32 bits, Feature
            0xC0,
    });
    Bytes status(13, 0);
    status[0] = 2;
    putLe(status, 1, std::uint64_t{1} << 40, 8);
    putLe(status, 9, 0x7FFFFFFF, 4);
    s->features = {{2, status}};
    TrackerLog log;
    hal::VirtualClock clock;
    auto r = HidTrackerReader::open(std::make_unique<FakeHidTracker>(s), clock, {});
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_FALSE(r->description().status) << *r->description().status;
    EXPECT_FALSE(r->description().quality) << *r->description().quality;
    const std::string text = log.text();
    EXPECT_NE(text.find("Configuration Status reads 1.09951e+12, which is no value it can have; "
                        "taken as not reported"),
              std::string::npos)
            << text;
    EXPECT_NE(text.find("Tracker Quality reads 2.14748e+14"), std::string::npos) << text;
}

// F13: a control report of 305 bytes: the mode request, 299 vendor bytes, then the Calibrated
// Screen Width. The product read feature reports into 256 bytes: the width was lost, and the
// mode request wrote zeros over bytes 256..304 of the report it sent back.
TEST(HidFeatures, ControlReportLongerThan256BytesIsReadAndWrittenWhole)
{
    auto s = std::make_shared<FakeHidTrackerState>();
    s->descriptor = tracker({
            0x85, 0x05,                         // Report ID (5)
            0x09, 0x14, 0xA1, 0x02,             // Usage (Control), Collection (Logical)
            0x0A, 0x00, 0x04,                   //   Usage (Device Mode Request)
            0x15, 0x00, 0x25, 0x07,             //   Logical 0..7
            0x65, 0x00, 0x55, 0x00,             //   no unit
            0x75, 0x08, 0x95, 0x01, 0xB1, 0x02, //   8 bits, Feature (Data, Var, Abs)
            0x06, 0x00, 0xFF, 0x09, 0x01,       //   Usage Page (vendor 0xFF00), Usage (1)
            0x26, 0xFF, 0x00,                   //   Logical Maximum (255)
            0x96, 0x2B, 0x01, 0xB1, 0x02,       //   Report Count (299), Feature
            0x05, 0x12, 0x0A, 0x04, 0x02,       //   Usage Page (0x12), Calibrated Screen Width
            0x27, 0xFF, 0xFF, 0xFF, 0x7F,       //   Logical Maximum (2^31 - 1): um (no unit)
            0x75, 0x20, 0x95, 0x01, 0xB1, 0x02, //   32 bits, Feature
            0xC0,
    });
    Bytes control(1 + 1 + 299 + 4, 0);
    control[0] = 5;
    for (std::size_t i = 2; i < 301; ++i) {
        control[i] = static_cast<std::uint8_t>(i % 251 + 1); // vendor bytes, none zero
    }
    putLe(control, 301, 527'000, 4); // 0.527 m
    s->features = {{5, control}};
    s->modeReportId = 5;
    s->modeByte = 1;
    hal::VirtualClock clock;
    auto r = HidTrackerReader::open(std::make_unique<FakeHidTracker>(s), clock, {});
    ASSERT_TRUE(r) << r.error().message;
    ASSERT_TRUE(r->description().screenWidthM);
    EXPECT_NEAR(*r->description().screenWidthM, 0.527, 1e-12);
    ASSERT_EQ(s->sentFeatures.size(), 1u);
    Bytes want = control;
    want[1] = 4; // head position
    EXPECT_EQ(s->sentFeatures[0], want);
}

// F11: Microsoft's reference descriptor declares the Device Mode Request 0..1 while its driver,
// and the usage page, take 2 for eye positions. No value in 0..1 asks for positions, so the
// request is sent as it is, and the log names the value and the range.
TEST(HidFeatures, ModeRequestOutsideItsLogicalRangeIsSentAndSaid)
{
    auto s = std::make_shared<FakeHidTrackerState>();
    s->descriptor = tracker({
            0x85, 0x14,                         // Report ID (20)
            0x09, 0x14, 0xA1, 0x02,             // Usage (Control), Collection (Logical)
            0x0A, 0x00, 0x04,                   //   Usage (Device Mode Request)
            0x15, 0x00, 0x25, 0x01,             //   Logical 0..1
            0x65, 0x00, 0x55, 0x00,             //   no unit
            0x75, 0x08, 0x95, 0x01, 0xB1, 0x02, //   8 bits, Feature
            0xC0,
    });
    s->features = {{20, {20, 0}}};
    s->modeReportId = 20;
    s->modeByte = 1;
    TrackerLog log;
    hal::VirtualClock clock;
    auto r = HidTrackerReader::open(std::make_unique<FakeHidTracker>(s), clock, {});
    ASSERT_TRUE(r) << r.error().message;
    ASSERT_EQ(s->sentFeatures.size(), 1u);
    EXPECT_EQ(s->sentFeatures[0], (Bytes{20, 4}));
    EXPECT_NE(log.text().find("device mode request 4 is outside the field's logical range 0..1"),
              std::string::npos)
            << log.text();
}

} // namespace hid_features
} // namespace replica::tests
