// Recording round trip: every sample type and frame record comes back bit-exactly.
#include <bit>
#include <cmath>
#include <filesystem>
#include <limits>

#include <recordings/recording.h>

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
    session.spectrometer = {"USB2000+", "S1", "fw", hal::SourceKind::Live};
    session.tracker = {"TrackIR", "T1", "", hal::SourceKind::Sim};
    session.accel = {"accel", "A1", "", hal::SourceKind::Replay};

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
    FrameRecord f{3, 50'000'001, 7, std::nullopt, 2};
    {
        auto w = RecordingWriter::create(path, session);
        ASSERT_TRUE(w) << w.error().message;
        (*w)->write(s);
        (*w)->write(p);
        (*w)->write(a);
        (*w)->write(f);
        ASSERT_TRUE((*w)->close());
    }
    auto r = readRecording(path);
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_EQ(r->formatVersion, kFormatVersion);
    EXPECT_EQ(r->session.configJson, session.configJson);
    EXPECT_EQ(r->session.wallClockStartNs, session.wallClockStartNs);
    EXPECT_EQ(r->session.spectrometer.serial, "S1");
    EXPECT_EQ(r->session.accel.kind, hal::SourceKind::Replay);
    ASSERT_EQ(r->spectra.size(), 1u);
    EXPECT_EQ(r->spectra[0].counts, s.counts);
    EXPECT_EQ(r->spectra[0].sequence, 7u);
    EXPECT_TRUE(r->spectra[0].saturated);
    for (std::size_t i = 0; i < 4; ++i) {
        EXPECT_EQ(std::bit_cast<std::uint64_t>(r->spectra[0].wavelengthCoeffs[i]),
                  std::bit_cast<std::uint64_t>(s.wavelengthCoeffs[i]));
    }
    for (std::size_t i = 0; i < 8; ++i) {
        EXPECT_EQ(std::bit_cast<std::uint64_t>(r->spectra[0].nonlinearityCoeffs[i]),
                  std::bit_cast<std::uint64_t>(s.nonlinearityCoeffs[i]));
    }
    ASSERT_EQ(r->poses.size(), 1u);
    EXPECT_EQ(r->poses[0].eyeTrackerM, p.eyeTrackerM);
    ASSERT_EQ(r->accel.size(), 1u);
    EXPECT_EQ(r->accel[0].gravity, a.gravity);
    ASSERT_EQ(r->frames.size(), 1u);
    EXPECT_EQ(r->frames[0].tickNs, f.tickNs);
    EXPECT_EQ(r->frames[0].spectrumSequence, f.spectrumSequence);
    EXPECT_FALSE(r->frames[0].poseSequence.has_value());
    EXPECT_EQ(r->frames[0].accelSequence, f.accelSequence);
    std::filesystem::remove(path);
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
    std::filesystem::remove(path);
}

} // namespace
} // namespace replica::recordings
