// Raw in, processed out (format 5): the opentrack datagram and the accelerometer's sysfs reading
// recorded beside their samples come back bit for bit, reprocess to the same samples, and a
// changed processing parameter changes them by what a hand computation says; malformed raw
// messages are one-line errors.
#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <string>

#include <fmt/format.h>

#include <hal/accel/iio_accel.h>
#include <hal/tracker/opentrack_udp.h>
#include <platform/reprocess.h>
#include <recordings/mcap/writer.h>
#include <recordings/recording.h>
#include <recordings/sample_codec.h>

#include <gtest/gtest.h>

namespace replica::recordings {
namespace {

std::filesystem::path rawTestFile(const std::string& name)
{
    return std::filesystem::temp_directory_path() /
           (name + "-" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
            ".mcap");
}

std::vector<std::uint8_t> rawTestDatagram(const std::array<double, 6>& v)
{
    std::vector<std::uint8_t> out(48);
    std::memcpy(out.data(), v.data(), 48);
    return out;
}

bool bitsEqual(const glm::dvec3& a, const glm::dvec3& b)
{
    for (int i = 0; i < 3; ++i) {
        if (std::bit_cast<std::uint64_t>(a[i]) != std::bit_cast<std::uint64_t>(b[i])) {
            return false;
        }
    }
    return true;
}

TEST(RawInputs, DatagramsAndSysfsReadingsComeBackAndReprocessBitExactly)
{
    // Poses as the opentrack source makes them (with an eye offset, so the head rotation
    // matters), one staleness marker without raw input; accel samples as the IIO source makes
    // them, one without raw input (simulated).
    hal::tracker::TrackerMounting mounting;
    mounting.eyeOffsetHeadM = {0.0, -0.04, -0.09};
    std::vector<hal::PoseSample> poses;
    for (std::uint32_t i = 0; i < 6; ++i) {
        hal::PoseSample p;
        p.sequence = i;
        p.timestampNs = 8'333'333LL * (i + 1);
        if (i != 4) {
            const auto bytes =
                    rawTestDatagram({1.0 + 0.1 * i, -2.5, 61.0 / 3.0, 10.0 * i, -5.0, 2.5});
            const auto head = hal::tracker::decodeOpentrack(bytes);
            ASSERT_TRUE(head);
            p.eyeTrackerM = hal::tracker::eyeFromHeadPose(*head, mounting);
            p.tracked = true;
            auto raw = std::make_shared<hal::RawTrackerInput>();
            raw->bytes = bytes;
            raw->arrivalNs = p.timestampNs;
            raw->zSign = mounting.zSign;
            raw->eyeOffsetHeadM = mounting.eyeOffsetHeadM;
            p.raw = raw;
        }
        poses.push_back(p);
    }
    const auto mapping = hal::accel::parseAxisMapping("-y,x,z");
    ASSERT_TRUE(mapping);
    std::vector<hal::AccelSample> accel;
    for (std::uint32_t i = 0; i < 5; ++i) {
        hal::AccelSample a;
        a.sequence = i;
        a.timestampNs = 10'000'000LL * (i + 1);
        a.gravity = {0.1, -9.8, 0.3};
        if (i != 2) {
            auto raw = std::make_shared<hal::RawAccelInput>();
            raw->raw = {-12.0 + i, 1000.0, 40.0};
            raw->scale = {0.00980665, 0.00980665, 0.0095};
            raw->offset = {0.0, 3.0, -0.5};
            raw->axes = "-y,x,z";
            a.gravity = hal::accel::gravityFromRaw(*raw, *mapping);
            a.raw = raw;
        }
        accel.push_back(a);
    }
    const auto path = rawTestFile("raw-inputs");
    {
        SessionInfo session;
        session.softwareVersion = "test";
        auto w = RecordingWriter::create(path, session);
        ASSERT_TRUE(w) << w.error().message;
        for (const auto& p : poses) {
            (*w)->write(p);
        }
        for (const auto& a : accel) {
            (*w)->write(a);
        }
        ASSERT_TRUE((*w)->close());
    }
    auto report = inspectRecording(path);
    auto rec = readRecording(path);
    std::filesystem::remove(path);
    ASSERT_TRUE(report);
    ASSERT_TRUE(rec) << rec.error().message;
    EXPECT_EQ(rec->formatVersion, kFormatVersion); // written today: format 6, raw inputs since 5
    std::map<std::string, std::uint64_t> counts;
    for (const auto& c : report->channels) {
        counts[c.topic] = c.messages;
    }
    EXPECT_EQ(counts["/replica/raw/tracker"], 5u);
    EXPECT_EQ(counts["/replica/raw/accel"], 4u);
    ASSERT_EQ(rec->samples(recordings::trackerKind()).size(), poses.size());
    ASSERT_EQ(rec->samples(recordings::accelKind()).size(), accel.size());
    for (std::size_t i = 0; i < poses.size(); ++i) {
        ASSERT_EQ(rec->samples(recordings::trackerKind())[i].raw != nullptr,
                  poses[i].raw != nullptr)
                << i;
        if (poses[i].raw) {
            EXPECT_EQ(rec->samples(recordings::trackerKind())[i].raw->bytes, poses[i].raw->bytes);
            EXPECT_EQ(rec->samples(recordings::trackerKind())[i].raw->arrivalNs,
                      poses[i].raw->arrivalNs);
            EXPECT_TRUE(bitsEqual(rec->samples(recordings::trackerKind())[i].raw->eyeOffsetHeadM,
                                  mounting.eyeOffsetHeadM));
        }
    }
    for (std::size_t i = 0; i < accel.size(); ++i) {
        ASSERT_EQ(rec->samples(recordings::accelKind())[i].raw != nullptr, accel[i].raw != nullptr)
                << i;
        if (accel[i].raw) {
            EXPECT_EQ(rec->samples(recordings::accelKind())[i].raw->raw, accel[i].raw->raw);
            EXPECT_EQ(rec->samples(recordings::accelKind())[i].raw->scale, accel[i].raw->scale);
            EXPECT_EQ(rec->samples(recordings::accelKind())[i].raw->offset, accel[i].raw->offset);
            EXPECT_EQ(rec->samples(recordings::accelKind())[i].raw->axes, "-y,x,z");
        }
    }

    // Processed values wiped: reprocessing computes them again, bit for bit; the samples without
    // raw input stay as recorded.
    auto wiped = *rec;
    for (auto& p : wiped.samples(recordings::trackerKind())) {
        if (p.raw) {
            p.eyeTrackerM = glm::dvec3(7.0);
        }
    }
    for (auto& a : wiped.samples(recordings::accelKind())) {
        if (a.raw) {
            a.gravity = glm::dvec3(7.0);
        }
    }
    auto r = platform::reprocess(wiped, {});
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_EQ(r->poses, 6u);
    EXPECT_EQ(r->posesReprocessed, 5u);
    EXPECT_EQ(r->accelReprocessed, 4u);
    for (std::size_t i = 0; i < poses.size(); ++i) {
        EXPECT_TRUE(bitsEqual(wiped.samples(recordings::trackerKind())[i].eyeTrackerM,
                              poses[i].eyeTrackerM))
                << i;
        EXPECT_EQ(wiped.samples(recordings::trackerKind())[i].tracked, poses[i].tracked) << i;
    }
    for (std::size_t i = 0; i < accel.size(); ++i) {
        EXPECT_TRUE(bitsEqual(wiped.samples(recordings::accelKind())[i].gravity, accel[i].gravity))
                << i;
    }
    auto same = *rec;
    r = platform::reprocess(same, {});
    ASSERT_TRUE(r);
    EXPECT_EQ(r->posesChanged + r->accelChanged, 0u);

    // A changed processing parameter: the accelerometer taken as mounted straight. Gravity is
    // then -(raw + offset) * scale per axis, computed here by hand.
    auto straight = *rec;
    platform::ReprocessOptions o;
    o.accelAxes = "x,y,z";
    r = platform::reprocess(straight, o);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->accelChanged, 4u);
    EXPECT_EQ(r->posesChanged, 0u);
    EXPECT_DOUBLE_EQ(straight.samples(recordings::accelKind())[0].gravity.x,
                     -(-12.0 + 0.0) * 0.00980665);
    EXPECT_DOUBLE_EQ(straight.samples(recordings::accelKind())[0].gravity.y,
                     -(1000.0 + 3.0) * 0.00980665);
    EXPECT_DOUBLE_EQ(straight.samples(recordings::accelKind())[0].gravity.z,
                     -(40.0 - 0.5) * 0.0095);
    EXPECT_EQ(straight.samples(recordings::accelKind())[2].gravity,
              accel[2].gravity); // no raw input: as recorded

    // An accelerometer scale of 1e308 (issue 32): 1000 counts of it overflow a double, so that
    // sample's gravity is not finite. Counted (and replay warns), not hidden.
    auto huge = *rec;
    auto scaled =
            std::make_shared<hal::RawAccelInput>(*huge.samples(recordings::accelKind())[0].raw);
    scaled->scale = {1e308, 1e308, 1e308};
    huge.samples(recordings::accelKind())[0].raw = scaled;
    r = platform::reprocess(huge, {});
    ASSERT_TRUE(r);
    EXPECT_EQ(r->accelNonFinite, 1u);
    EXPECT_EQ(r->posesNonFinite, 0u);
    EXPECT_FALSE(std::isfinite(huge.samples(recordings::accelKind())[0].gravity.y));
    EXPECT_EQ(platform::reprocess(same, {})->accelNonFinite, 0u);
    EXPECT_NE(r->accelFirstNonFinite.find("scale 1e+308,1e+308,1e+308"), std::string::npos)
            << r->accelFirstNonFinite;
    EXPECT_NE(r->accelFirstNonFinite.find("the product overflows"), std::string::npos);
    EXPECT_EQ(r->accelBadScale, 0u);

    // A scale of zero gave gravity (0,0,0), finite, which passed for a reading and showed the
    // default tilt without a word; NaN and a negative scale likewise. Each is now counted as a
    // bad scale, its gravity made not finite (ignored like a device's NaN), and named.
    for (const double bad : {0.0, std::numeric_limits<double>::quiet_NaN(), -0.0098,
                             std::numeric_limits<double>::infinity()}) {
        auto zero = *rec;
        auto z =
                std::make_shared<hal::RawAccelInput>(*zero.samples(recordings::accelKind())[1].raw);
        z->scale = {0.0098, bad, 0.0098};
        zero.samples(recordings::accelKind())[1].raw = z;
        r = platform::reprocess(zero, {});
        ASSERT_TRUE(r);
        EXPECT_EQ(r->accelBadScale, 1u) << bad;
        EXPECT_EQ(r->accelNonFinite, 1u) << bad;
        EXPECT_FALSE(std::isfinite(zero.samples(recordings::accelKind())[1].gravity.x)) << bad;
        EXPECT_NE(r->accelFirstNonFinite.find(fmt::format(
                          "sample {}: raw", zero.samples(recordings::accelKind())[1].sequence)),
                  std::string::npos)
                << r->accelFirstNonFinite;
        EXPECT_NE(r->accelFirstNonFinite.find(fmt::format("scale 0.0098,{},0.0098", bad)),
                  std::string::npos)
                << r->accelFirstNonFinite;
        EXPECT_NE(r->accelFirstNonFinite.find("not a positive finite number"), std::string::npos);
    }

    // A datagram that is not a pose: one line naming the pose.
    auto bad = *rec;
    auto cut =
            std::make_shared<hal::RawTrackerInput>(*bad.samples(recordings::trackerKind())[1].raw);
    cut->bytes.resize(40);
    bad.samples(recordings::trackerKind())[1].raw = cut;
    r = platform::reprocess(bad, {});
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().message, "raw input of pose 1: a 40-byte datagram that is not an "
                                 "opentrack pose (48 bytes, six finite doubles)");
    o.accelAxes = "x,y";
    auto badAxes = *rec;
    EXPECT_FALSE(platform::reprocess(badAxes, o));
}

TEST(RawInputs, LampSelectorPositionsAreDecodedAgainFromTheirLineLevels)
{
    // Line levels as recorded (one-hot, line i = lamp i); the lamp fields as a buggy decoder
    // might have written them.
    Recording rec;
    const struct {
        std::uint32_t levels, lines;
        int recorded, want;
    } cases[] = {
            {0b010, 3, 1, 1},                         // lamp 1, decoded right
            {0b100, 3, 0, 2},                         // lamp 2, recorded wrong
            {0b000, 3, hal::kLampOff, hal::kLampOff}, // off
            {0b011, 3, 0, hal::kLampInvalid},         // two lines: a wiring fault, not lamp 0
            {0b1000, 3, 3, hal::kLampOff},            // a level beyond the switch's lines: ignored
            {0, 3, hal::kLampLost, hal::kLampLost},   // lines lost: nothing to decode
    };
    std::uint32_t seq = 0;
    for (const auto& c : cases) {
        hal::LampSample l;
        l.sequence = seq++;
        l.lineLevels = c.levels;
        l.lineCount = c.lines;
        l.lamp = c.recorded;
        rec.samples(recordings::lampSelectorKind()).push_back(l);
    }
    auto r = platform::reprocess(rec, {});
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_EQ(r->lamp, 6u);
    EXPECT_EQ(r->lampReprocessed, 5u);
    EXPECT_EQ(r->lampChanged, 3u);
    for (std::size_t i = 0; i < std::size(cases); ++i) {
        EXPECT_EQ(rec.samples(recordings::lampSelectorKind())[i].lamp, cases[i].want) << i;
    }
}

// Writes a recording whose one raw message is 'payload' on 'channel' and reads it back.
Expected<Recording> readWithRawMessage(ChannelId channel, const std::string& payload)
{
    const auto path = rawTestFile("raw-malformed");
    {
        auto f = mcap::FileWriter::create(path, "replica test (format 5)");
        if (!f) {
            return tl::unexpected(f.error());
        }
        for (const auto& d : channelDefinitions()) {
            (*f)->addSchema(d.schema);
            (*f)->addChannel(d.channel);
        }
        SessionInfo session;
        session.softwareVersion = "test";
        (*f)->addMessage({static_cast<std::uint16_t>(ChannelId::Session), 0, 0, 0,
                          encodeSession(session, kFormatVersion)});
        (*f)->addMessage({static_cast<std::uint16_t>(channel), 0, 5, 5, payload});
        if (auto ok = (*f)->finish(); !ok) {
            return tl::unexpected(ok.error());
        }
    }
    auto rec = readRecording(path);
    std::filesystem::remove(path);
    return rec;
}

TEST(RawInputs, MalformedRawMessagesAreOneLineErrors)
{
    const struct {
        ChannelId channel;
        std::string payload, expected;
    } cases[] = {
            {ChannelId::RawTracker, R"({"t":5,"seq":0,"kind":"opentrack","bytes":"@@@@"})",
             "damaged /replica/raw/tracker message (sequence 0): bytes: not base64"},
            {ChannelId::RawTracker, R"({"t":5,"seq":0,"kind":"opentrack","bytes":"AAA"})",
             "not a multiple of 4"},
            {ChannelId::RawTracker, R"({"t":5,"seq":0,"kind":"usb","bytes":""})",
             "unknown raw tracker kind 'usb'"},
            {ChannelId::RawTracker,
             R"({"t":5,"kind":"hid-descriptor","descriptor":1,"bytes":")" + std::string(8000, 'A') +
                     R"("})",
             "6000 raw bytes; a device report is at most 4096"},
            {ChannelId::RawAccel,
             R"({"t":5,"seq":0,"raw":[1,2],"scale":[1,1,1],"offset":[0,0,0],"axes":"x,y,z"})",
             "damaged /replica/raw/accel message (sequence 0)"},
            {ChannelId::RawAccel, R"({"t":5,"seq":0,"raw":[1,2,3]})",
             "damaged /replica/raw/accel message (sequence 0)"},
            {ChannelId::RawAccel, R"([1,2,3])", "damaged /replica/raw/accel message"},
    };
    for (const auto& c : cases) {
        auto rec = readWithRawMessage(c.channel, c.payload);
        ASSERT_FALSE(rec) << c.payload;
        EXPECT_NE(rec.error().message.find(c.expected), std::string::npos) << rec.error().message;
        EXPECT_EQ(rec.error().message.find('\n'), std::string::npos);
    }
    // A well-formed one reads (the message names a pose the recording does not hold: counted).
    auto ok = readWithRawMessage(
            ChannelId::RawAccel,
            R"({"t":5,"seq":9,"raw":[1,2,3],"scale":[1,1,1],"offset":[0,0,0],"axes":"x,y,z"})");
    ASSERT_TRUE(ok) << ok.error().message;
    EXPECT_EQ(ok->unmatchedRaw, 1u);
    // A HID report whose descriptor the file does not hold (its chunk lost and dropped by
    // recover): the recording still reads; the report is counted as of no use.
    ok = readWithRawMessage(
            ChannelId::RawTracker,
            R"({"t":5,"seq":0,"kind":"hid","bytes":"AAAA","descriptor":3,"axes":"x,y,z","reanchor_ns":1})");
    ASSERT_TRUE(ok) << ok.error().message;
    EXPECT_EQ(ok->unmatchedRaw, 1u);
}

} // namespace
} // namespace replica::recordings
