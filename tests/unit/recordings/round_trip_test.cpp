// Recording round trip: every sample type and frame record comes back bit-exactly.
#include <bit>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <thread>

#include <recordings/recording.h>
#include <recordings/sample_codec.h>

#include <gtest/gtest.h>

namespace replica::recordings {
namespace {

std::filesystem::path tempFile(const std::string& name)
{
    return std::filesystem::temp_directory_path() /
           (name + "-" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
            ".mcap");
}

TEST(RecordingRoundTrip, EverySampleTypeComesBackBitExactly)
{
    const auto path = tempFile("round-trip");
    SessionInfo session;
    session.softwareVersion = "replica test";
    session.configJson = R"({"width":4})";
    session.boothModel = "booth";
    session.scene = "scene";
    session.displayProfile = "display";
    session.wallClockStartNs = 1'700'000'000'123'456'789;
    session.devices[&recordings::spectrometerKind()] = {"USB2000+", "S1", "fw",
                                                        hal::SourceKind::Live};
    session.devices[&recordings::trackerKind()] = {"TrackIR", "T1", "", hal::SourceKind::Sim};
    session.devices[&recordings::accelKind()] = {"accel", "A1", "", hal::SourceKind::Replay};
    session.devices[&recordings::lampSelectorKind()] = {
            "lamp selector (GPIO)", "gpiochip0:17,27,22", "", hal::SourceKind::Live};

    hal::SpectrumSample s;
    s.timestampNs = 100'000'000;
    s.sequence = 7;
    s.integrationTimeUs = 12'000;
    s.counts = {0, 1, 65535, 1234};
    s.wavelengthCoeffs = {339.2, 0.1 + 0.2, -1.62e-5, 1e-310};
    s.nonlinearityCoeffs = {1.0, std::numeric_limits<double>::max(), -0.0, 5e-324, 0, 0, 0, 0.3};
    s.saturated = true;
    hal::PoseSample p;
    p.timestampNs = 8'333'333;
    p.sequence = 1;
    p.tracked = true;
    p.eyeTrackerM = {0.1, -1.0 / 3.0, std::nextafter(0.6, 1.0)};
    hal::AccelSample a;
    a.timestampNs = 10'000'000;
    a.sequence = 2;
    a.gravity = {1e-17, -9.80665, 2.0 / 7.0};
    hal::LampSample l;
    l.timestampNs = 2'035'123'456;
    l.sequence = 4;
    l.lamp = 2;
    l.lineCount = 3;
    l.lineLevels = 0b100;
    hal::LampSample invalid = l;
    invalid.sequence = 5;
    invalid.lamp = hal::kLampInvalid;
    invalid.lineLevels = 0b101;
    FrameRecord f{
            3, 50'000'001, {{&spectrometerKind(), 7}, {&accelKind(), 2}, {&lampSelectorKind(), 4}}};
    {
        auto w = RecordingWriter::create(path, session);
        ASSERT_TRUE(w) << w.error().message;
        (*w)->write(s);
        (*w)->write(p);
        (*w)->write(a);
        (*w)->write(l);
        (*w)->write(invalid);
        (*w)->write(f);
        ASSERT_TRUE((*w)->close());
    }
    auto r = readRecording(path);
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_EQ(r->formatVersion, kFormatVersion);
    EXPECT_EQ(r->session.configJson, session.configJson);
    EXPECT_EQ(r->session.wallClockStartNs, session.wallClockStartNs);
    EXPECT_EQ(r->session.device(recordings::spectrometerKind()).serial, "S1");
    EXPECT_EQ(r->session.device(recordings::accelKind()).kind, hal::SourceKind::Replay);
    ASSERT_EQ(r->samples(recordings::spectrometerKind()).size(), 1u);
    EXPECT_EQ(r->samples(recordings::spectrometerKind())[0].counts, s.counts);
    EXPECT_EQ(r->samples(recordings::spectrometerKind())[0].sequence, 7u);
    EXPECT_TRUE(r->samples(recordings::spectrometerKind())[0].saturated);
    for (std::size_t i = 0; i < 4; ++i) {
        EXPECT_EQ(std::bit_cast<std::uint64_t>(
                          r->samples(recordings::spectrometerKind())[0].wavelengthCoeffs[i]),
                  std::bit_cast<std::uint64_t>(s.wavelengthCoeffs[i]));
    }
    for (std::size_t i = 0; i < 8; ++i) {
        EXPECT_EQ(std::bit_cast<std::uint64_t>(
                          r->samples(recordings::spectrometerKind())[0].nonlinearityCoeffs[i]),
                  std::bit_cast<std::uint64_t>(s.nonlinearityCoeffs[i]));
    }
    ASSERT_EQ(r->samples(recordings::trackerKind()).size(), 1u);
    EXPECT_EQ(r->samples(recordings::trackerKind())[0].eyeTrackerM, p.eyeTrackerM);
    ASSERT_EQ(r->samples(recordings::accelKind()).size(), 1u);
    EXPECT_EQ(r->samples(recordings::accelKind())[0].gravity, a.gravity);
    ASSERT_EQ(r->frames.size(), 1u);
    EXPECT_EQ(r->frames[0].tickNs, f.tickNs);
    EXPECT_EQ(r->frames[0].sequence(recordings::spectrometerKind()),
              f.sequence(recordings::spectrometerKind()));
    EXPECT_FALSE(r->frames[0].sequence(recordings::trackerKind()).has_value());
    EXPECT_EQ(r->frames[0].sequence(recordings::accelKind()), f.sequence(recordings::accelKind()));
    EXPECT_EQ(r->frames[0].sequence(recordings::lampSelectorKind()),
              f.sequence(recordings::lampSelectorKind()));
    EXPECT_EQ(r->session.device(recordings::lampSelectorKind()).serial, "gpiochip0:17,27,22");
    EXPECT_EQ(r->session.device(recordings::lampSelectorKind()).kind, hal::SourceKind::Live);
    ASSERT_EQ(r->samples(recordings::lampSelectorKind()).size(), 2u);
    for (std::size_t i = 0; i < 2; ++i) {
        const auto& want = i == 0 ? l : invalid;
        EXPECT_EQ(r->samples(recordings::lampSelectorKind())[i].timestampNs, want.timestampNs);
        EXPECT_EQ(r->samples(recordings::lampSelectorKind())[i].sequence, want.sequence);
        EXPECT_EQ(r->samples(recordings::lampSelectorKind())[i].lamp, want.lamp);
        EXPECT_EQ(r->samples(recordings::lampSelectorKind())[i].lineLevels, want.lineLevels);
        EXPECT_EQ(r->samples(recordings::lampSelectorKind())[i].lineCount, want.lineCount);
    }
    std::filesystem::remove(path);
}

// Format 4: what was shown. Digests and decided lights read back; thumbnails and log lines written
// from other threads arrive whole; the pose channels carry the tilt as a quaternion.
TEST(RecordingRoundTrip, WhatWasShownComesBack)
{
    const auto path = tempFile("shown");
    SessionInfo session;
    session.wallClockStartNs = 1'700'000'000'000'000'000;
    {
        auto w = RecordingWriter::create(path, session);
        ASSERT_TRUE(w) << w.error().message;
        (*w)->write(DisplayDigestRecord{0, 0, 0x0123456789abcdefULL});
        (*w)->write(DisplayDigestRecord{1, 16'666'667, 0xfedcba9876543210ULL});
        LightRecord l;
        l.tNs = 16'666'667;
        l.frameIndex = 1;
        l.mode = "lamp";
        l.lamp = 2;
        l.name = "d65-fluorescent";
        l.cctK = 6500.25;
        l.duv = -0.001;
        l.distance = 0.01;
        l.why = "the booth's lamp selector is set to d65-fluorescent (lamp 2)";
        (*w)->write(l);
        (*w)->write(PosesRecord{16'666'667, {0.0, 0.45, 0.6}, 0.5, {0.0, 0.42, 0.05}});
        std::thread other([&] {
            (*w)->write(ThumbnailRecord{0, 0, {0x89, 'P', 'N', 'G'}});
            (*w)->write(LogRecord{5, 3, "loop", "spectrometer S1: 2 spectra dropped"});
        });
        other.join();
        ASSERT_TRUE((*w)->close());
        EXPECT_EQ((*w)->stats().dropped, 0u);
    }
    auto r = readRecording(path);
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_EQ(r->formatVersion, kFormatVersion);
    ASSERT_EQ(r->displayDigests.size(), 2u);
    EXPECT_EQ(r->displayDigests[1].rgba, 0xfedcba9876543210ULL);
    EXPECT_EQ(r->displayDigests[1].tickNs, 16'666'667);
    ASSERT_EQ(r->lights.size(), 1u);
    EXPECT_EQ(r->lights[0].name, "d65-fluorescent");
    EXPECT_EQ(r->lights[0].cctK, 6500.25);
    EXPECT_EQ(r->lights[0].why, "the booth's lamp selector is set to d65-fluorescent (lamp 2)");
    const auto report = inspectRecording(path);
    ASSERT_TRUE(report);
    std::map<std::string, std::uint64_t> counts;
    for (const auto& c : report->channels) {
        counts[c.topic] = c.messages;
    }
    EXPECT_EQ(counts["/replica/thumbnail"], 1u);
    EXPECT_EQ(counts["/replica/log"], 1u);
    EXPECT_EQ(counts["/tf"], 1u);
    EXPECT_EQ(counts["/replica/eye"], 1u);
    // The transforms: the panel turned by the tilt about x, (sin(a/2), 0, 0, cos(a/2)).
    const auto tf = encodeTransforms(PosesRecord{0, {0.0, 0.45, 0.6}, 0.5, {0.0, 0.42, 0.05}},
                                     session.wallClockStartNs);
    ASSERT_TRUE(tf);
    const auto j = nlohmann::json::parse(*tf);
    EXPECT_EQ(j["transforms"][0]["child_frame_id"], "panel");
    EXPECT_DOUBLE_EQ(j["transforms"][0]["rotation"]["x"].get<double>(), std::sin(0.25));
    EXPECT_DOUBLE_EQ(j["transforms"][0]["rotation"]["w"].get<double>(), std::cos(0.25));
    EXPECT_EQ(j["transforms"][0]["timestamp"]["sec"], 1'700'000'000);
    const auto log = nlohmann::json::parse(
            encodeLog(LogRecord{1'500'000'000, 4, "rec", "x"}, session.wallClockStartNs));
    EXPECT_EQ(log["timestamp"]["sec"], 1'700'000'001);
    EXPECT_EQ(log["timestamp"]["nsec"], 500'000'000);
    EXPECT_EQ(log["level"], 4);
    std::filesystem::remove(path);
}

TEST(RecordingRoundTrip, NonFiniteValuesAreRefusedAndCounted)
{
    const auto path = tempFile("nonfinite");
    {
        auto w = RecordingWriter::create(path, SessionInfo{});
        ASSERT_TRUE(w) << w.error().message;
        hal::AccelSample a;
        a.sequence = 1;
        a.gravity = {0.0, std::numeric_limits<double>::quiet_NaN(), 0.0};
        (*w)->write(a);
        hal::PoseSample p;
        p.eyeTrackerM = {std::numeric_limits<double>::infinity(), 0.0, 0.0};
        (*w)->write(p);
        a.sequence = 2;
        a.gravity = {0.0, -9.8, 0.0};
        (*w)->write(a);
        ASSERT_TRUE((*w)->close());
        EXPECT_EQ((*w)->stats().rejected, 2u);
    }
    auto r = readRecording(path);
    ASSERT_TRUE(r) << r.error().message;
    ASSERT_EQ(r->samples(recordings::accelKind()).size(), 1u);
    EXPECT_EQ(r->samples(recordings::accelKind())[0].sequence, 2u);
    EXPECT_TRUE(r->samples(recordings::trackerKind()).empty());
    EXPECT_EQ(r->rejectedNonFinite, 2u); // recorded on /replica/recorder, not lost silently
    EXPECT_EQ(r->droppedMessages, 0u);
    std::filesystem::remove(path);
}

TEST(RecordingRoundTrip, FullQueueDropsAndRecordsTheDrops)
{
    const auto path = tempFile("drops");
    std::uint64_t dropped = 0;
    {
        WriterOptions options;
        options.queueCapacity = 4;
        auto w = RecordingWriter::create(path, SessionInfo{}, options);
        ASSERT_TRUE(w) << w.error().message;
        hal::SpectrumSample s;
        s.counts.assign(2048, 100);
        // Far more than four spectra at once: the writer thread cannot keep up with a tight loop
        // of large samples, so some must be dropped (write() never waits).
        for (std::uint32_t i = 0; i < 20000; ++i) {
            s.sequence = i;
            (*w)->write(s);
        }
        ASSERT_TRUE((*w)->close());
        dropped = (*w)->stats().dropped;
    }
    auto r = readRecording(path);
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_GT(dropped, 0u);
    EXPECT_EQ(r->droppedMessages, dropped);
    EXPECT_EQ(r->samples(recordings::spectrometerKind()).size(), 20000u - dropped);
    std::filesystem::remove(path);
}

TEST(RecordingRead, FormatVersionOneSampleStillOpens)
{
    // The version policy: every committed sample of an earlier format stays readable.
    const auto sample =
            std::filesystem::path(REPLICA_SOURCE_DIR) / "recordings/samples/walk-v1.mcap";
    auto r = readRecording(sample);
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_EQ(r->formatVersion, 1);
    EXPECT_EQ(r->frames.size(), 90u);
    EXPECT_FALSE(r->samples(recordings::trackerKind()).empty());
    EXPECT_FALSE(r->samples(recordings::spectrometerKind()).empty());
}

TEST(RecordingRead, FormatVersionTwoSampleHoldsTheSameSessionAsVersionOne)
{
    // walk-v1 and walk-v2 were recorded from the same deterministic sim scenario by the two format
    // versions' writers: the timing, poses and tilts must read back identical. (The simulated
    // spectrometer gained a non-linearity and the configuration gained fields between the two, so
    // counts and configuration legitimately differ.)
    const auto dir = std::filesystem::path(REPLICA_SOURCE_DIR) / "recordings/samples";
    auto v1 = readRecording(dir / "walk-v1.mcap");
    auto v2 = readRecording(dir / "walk-v2.mcap");
    ASSERT_TRUE(v1) << v1.error().message;
    ASSERT_TRUE(v2) << v2.error().message;
    EXPECT_EQ(v2->formatVersion, 2);
    ASSERT_EQ(v2->frames.size(), v1->frames.size());
    ASSERT_EQ(v2->samples(recordings::trackerKind()).size(),
              v1->samples(recordings::trackerKind()).size());
    ASSERT_EQ(v2->samples(recordings::accelKind()).size(),
              v1->samples(recordings::accelKind()).size());
    ASSERT_EQ(v2->samples(recordings::spectrometerKind()).size(),
              v1->samples(recordings::spectrometerKind()).size());
    for (std::size_t i = 0; i < v1->frames.size(); ++i) {
        EXPECT_EQ(v2->frames[i].tickNs, v1->frames[i].tickNs);
        EXPECT_EQ(v2->frames[i].sequence(recordings::trackerKind()),
                  v1->frames[i].sequence(recordings::trackerKind()));
        EXPECT_EQ(v2->frames[i].sequence(recordings::spectrometerKind()),
                  v1->frames[i].sequence(recordings::spectrometerKind()));
    }
    for (std::size_t i = 0; i < v1->samples(recordings::trackerKind()).size(); ++i) {
        EXPECT_EQ(v2->samples(recordings::trackerKind())[i].eyeTrackerM,
                  v1->samples(recordings::trackerKind())[i].eyeTrackerM);
        EXPECT_EQ(v2->samples(recordings::trackerKind())[i].timestampNs,
                  v1->samples(recordings::trackerKind())[i].timestampNs);
    }
    for (std::size_t i = 0; i < v1->samples(recordings::accelKind()).size(); ++i) {
        EXPECT_EQ(v2->samples(recordings::accelKind())[i].gravity,
                  v1->samples(recordings::accelKind())[i].gravity);
    }
    for (std::size_t i = 0; i < v1->samples(recordings::spectrometerKind()).size(); ++i) {
        EXPECT_EQ(v2->samples(recordings::spectrometerKind())[i].timestampNs,
                  v1->samples(recordings::spectrometerKind())[i].timestampNs);
        EXPECT_EQ(v2->samples(recordings::spectrometerKind())[i].counts.size(),
                  v1->samples(recordings::spectrometerKind())[i].counts.size());
        EXPECT_EQ(v2->samples(recordings::spectrometerKind())[i].wavelengthCoeffs,
                  v1->samples(recordings::spectrometerKind())[i].wavelengthCoeffs);
    }
}

TEST(RecordingRead, TruncatedFileIsReportedNotCrashed)
{
    const auto path = tempFile("truncated");
    {
        auto w = RecordingWriter::create(path, SessionInfo{});
        ASSERT_TRUE(w);
        hal::AccelSample a;
        for (std::uint32_t i = 0; i < 10; ++i) {
            a.sequence = i;
            (*w)->write(a);
        }
        ASSERT_TRUE((*w)->close());
    }
    std::filesystem::resize_file(path, std::filesystem::file_size(path) / 2);
    auto r = readRecording(path);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find(path.string()), std::string::npos);
    EXPECT_NE(r.error().message.find("replica recover"), std::string::npos);
    std::filesystem::remove(path);
}

} // namespace
} // namespace replica::recordings

namespace replica::recordings {
namespace {

TEST(RecordingRead, RecordingsWithoutALampSelectorHaveNoneAndNoLampSequences)
{
    // Formats 1 and 2 predate the selector: they must read as "no selector", which replays as
    // the classifier alone, exactly as they were recorded.
    const auto dir = std::filesystem::path(REPLICA_SOURCE_DIR) / "recordings/samples";
    for (const char* name : {"walk-v1.mcap", "walk-v2.mcap"}) {
        auto r = readRecording(dir / name);
        ASSERT_TRUE(r) << r.error().message;
        EXPECT_TRUE(r->samples(recordings::lampSelectorKind()).empty()) << name;
        EXPECT_TRUE(r->session.device(recordings::lampSelectorKind()).model.empty()) << name;
        for (const auto& f : r->frames) {
            EXPECT_FALSE(f.sequence(recordings::lampSelectorKind()).has_value()) << name;
        }
    }
}

TEST(RecordingRead, FormatVersionThreeSampleHoldsTheSimulatedSwitch)
{
    const auto dir = std::filesystem::path(REPLICA_SOURCE_DIR) / "recordings/samples";
    auto r = readRecording(dir / "walk-v3.mcap");
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_EQ(r->formatVersion, 3);
    EXPECT_EQ(r->session.device(recordings::lampSelectorKind()).model, "lamp selector (simulated)");
    // The position at t = 0 and the turn to lamp 1 at 2 s (debounced), as the scenario plays it.
    ASSERT_EQ(r->samples(recordings::lampSelectorKind()).size(), 2u);
    EXPECT_EQ(r->samples(recordings::lampSelectorKind())[0].lamp, 0);
    EXPECT_EQ(r->samples(recordings::lampSelectorKind())[1].lamp, 1);
    EXPECT_GE(r->samples(recordings::lampSelectorKind())[1].timestampNs, 2'030'000'000);
    ASSERT_FALSE(r->frames.empty());
    EXPECT_EQ(r->frames.back().sequence(recordings::lampSelectorKind()), 1u);
    EXPECT_EQ(r->frames.front().sequence(recordings::lampSelectorKind()), 0u);
}

} // namespace
} // namespace replica::recordings
