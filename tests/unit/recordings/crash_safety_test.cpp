// Crash safety: SIGKILL at random moments loses at most the flush interval; disk full, unwritable
// directory and a deleted file give one clear error while the caller keeps running, and what was
// written stays recoverable.
#include <atomic>
#include <chrono>
#include <ctime>
#include <filesystem>
#include <random>
#include <thread>

#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <recordings/recording.h>
#include <recordings/recover.h>

#include <gtest/gtest.h>

#include "../support/files.h"

namespace replica::recordings {
namespace {

std::int64_t monotonicNs()
{
    timespec ts{};
    ::clock_gettime(CLOCK_MONOTONIC, &ts);
    return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

// Counts that zstd cannot squeeze much (a constant spectrum would compress to nothing and never
// reach the size limit): a pseudo-random sequence seeded by the sample's sequence number.
std::vector<std::uint16_t> noisyCounts(std::uint32_t seed)
{
    std::minstd_rand rng(seed + 1);
    std::vector<std::uint16_t> counts(2048);
    for (auto& c : counts) {
        c = static_cast<std::uint16_t>(rng());
    }
    return counts;
}

using tests::tempRecordingPath;

// The child: records sim-like samples (tracker 120 Hz, accel 100 Hz, a spectrum every 200 ms)
// stamped with CLOCK_MONOTONIC until it is killed. Never returns.
[[noreturn]] void recordUntilKilled(const std::filesystem::path& path,
                                    std::chrono::milliseconds flush)
{
    WriterOptions options;
    options.flushInterval = flush;
    auto w = RecordingWriter::create(path, SessionInfo{}, options);
    if (!w) {
        ::_exit(2);
    }
    std::uint32_t seq = 0;
    for (;;) {
        const auto t = monotonicNs();
        hal::PoseSample p;
        p.timestampNs = t;
        p.sequence = seq;
        p.eyeTrackerM = {0.001 * seq, 0.1, 0.6};
        (*w)->write(p);
        hal::AccelSample a;
        a.timestampNs = t;
        a.sequence = seq;
        a.gravity = {0.0, -9.80665, 1e-3 * seq};
        (*w)->write(a);
        if (seq % 25 == 0) {
            hal::SpectrumSample s;
            s.timestampNs = t;
            s.sequence = seq / 25;
            s.counts.assign(2048, static_cast<std::uint16_t>(seq));
            (*w)->write(s);
        }
        ++seq;
        std::this_thread::sleep_for(std::chrono::milliseconds(8));
    }
}

TEST(CrashSafety, SigkillAtRandomMomentsLosesAtMostTheFlushInterval)
{
    constexpr auto kFlush = std::chrono::milliseconds(100);
    // Slack for scheduling on a loaded 2-core CI machine: the writer thread may wait its turn.
    constexpr std::int64_t kSlackNs = 1'000'000'000;
    constexpr int kKills = 6;
    std::mt19937 rng(::testing::UnitTest::GetInstance()->random_seed());
    std::uniform_int_distribution<int> delayMs(1300, 3000);
    struct Child {
        pid_t pid;
        std::filesystem::path path;
        std::int64_t killAt, killedAt = 0;
    };
    std::vector<Child> children;
    const auto start = monotonicNs();
    for (int k = 0; k < kKills; ++k) {
        const auto path = tempRecordingPath("sigkill-" + std::to_string(k));
        const pid_t pid = ::fork();
        ASSERT_GE(pid, 0);
        if (pid == 0) {
            recordUntilKilled(path, kFlush);
        }
        children.push_back({pid, path, start + delayMs(rng) * 1'000'000LL});
    }
    std::sort(children.begin(), children.end(),
              [](const Child& a, const Child& b) { return a.killAt < b.killAt; });
    for (auto& c : children) {
        std::this_thread::sleep_for(
                std::chrono::nanoseconds(std::max<std::int64_t>(0, c.killAt - monotonicNs())));
        c.killedAt = monotonicNs();
        ASSERT_EQ(::kill(c.pid, SIGKILL), 0);
        int status = 0;
        ASSERT_EQ(::waitpid(c.pid, &status, 0), c.pid);
        ASSERT_TRUE(WIFSIGNALED(status)) << "child exited early with " << WEXITSTATUS(status);
    }
    for (const auto& c : children) {
        SCOPED_TRACE(c.path.string());
        const auto out = tempRecordingPath("sigkill-recovered");
        auto report = recoverRecording(c.path, out, ExistingOutput::Replace);
        ASSERT_TRUE(report) << report.error().message;
        auto rec = readRecording(out);
        ASSERT_TRUE(rec) << rec.error().message;
        ASSERT_FALSE(rec->samples(recordings::trackerKind()).empty());
        // Nothing in the middle is missing: the recovered samples are a gap-free prefix...
        for (std::size_t i = 0; i < rec->samples(recordings::trackerKind()).size(); ++i) {
            ASSERT_EQ(rec->samples(recordings::trackerKind())[i].sequence, i);
        }
        for (std::size_t i = 0; i < rec->samples(recordings::accelKind()).size(); ++i) {
            ASSERT_EQ(rec->samples(recordings::accelKind())[i].sequence, i);
        }
        // ...that reaches to within the flush interval (plus scheduling slack) of the kill.
        const auto newest = rec->samples(recordings::trackerKind()).back().timestampNs;
        EXPECT_GE(newest, c.killedAt - kFlush.count() * 1'000'000 - kSlackNs)
                << "the last " << (c.killedAt - newest) / 1'000'000 << " ms before the kill "
                << "were lost";
        std::filesystem::remove(c.path);
        std::filesystem::remove(out);
    }
}

TEST(CrashSafety, DiskFullGivesOneErrorKeepsRunningAndKeepsWhatWasWritten)
{
    const auto path = tempRecordingPath("fsize");
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
        // A file size limit behaves like a full disk for this file (EFBIG instead of ENOSPC).
        rlimit limit{200 * 1024, 200 * 1024};
        ::setrlimit(RLIMIT_FSIZE, &limit);
        std::atomic<int> errors{0};
        WriterOptions options;
        options.flushInterval = std::chrono::milliseconds(20);
        options.chunkBytes = 16 * 1024;
        options.onError = [&](const Error& e) {
            if (e.message.find(path.string()) != std::string::npos &&
                e.message.find("size limit") != std::string::npos) {
                ++errors;
            } else {
                errors += 100;
            }
        };
        auto w = RecordingWriter::create(path, SessionInfo{}, options);
        if (!w) {
            ::_exit(10);
        }
        hal::SpectrumSample s;
        for (std::uint32_t i = 0; i < 400; ++i) {
            s.sequence = i;
            s.timestampNs = i;
            s.counts = noisyCounts(i);
            (*w)->write(s);
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
        }
        const bool closeFailed = !(*w)->close();
        // Still alive (no SIGXFSZ), exactly one error, and close() reports it too.
        ::_exit(errors == 1 && closeFailed ? 0 : 11 + std::min(errors.load(), 100));
    }
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    ASSERT_TRUE(WIFEXITED(status)) << "the recorder was killed by signal " << WTERMSIG(status);
    ASSERT_EQ(WEXITSTATUS(status), 0);
    EXPECT_LE(std::filesystem::file_size(path), 200u * 1024u);
    auto damaged = readRecording(path);
    ASSERT_FALSE(damaged);
    EXPECT_NE(damaged.error().message.find("replica recover"), std::string::npos);
    const auto out = tempRecordingPath("fsize-recovered");
    auto report = recoverRecording(path, out, ExistingOutput::Replace);
    ASSERT_TRUE(report) << report.error().message;
    auto rec = readRecording(out);
    ASSERT_TRUE(rec) << rec.error().message;
    ASSERT_FALSE(rec->samples(recordings::spectrometerKind()).empty());
    for (std::size_t i = 0; i < rec->samples(recordings::spectrometerKind()).size(); ++i) {
        ASSERT_EQ(rec->samples(recordings::spectrometerKind())[i].sequence, i);
        ASSERT_EQ(rec->samples(recordings::spectrometerKind())[i].counts,
                  noisyCounts(static_cast<std::uint32_t>(i)));
    }
    std::filesystem::remove(path);
    std::filesystem::remove(out);
}

TEST(CrashSafety, FullDeviceIsOneClearErrorAtCreate)
{
    auto w = RecordingWriter::create("/dev/full", SessionInfo{});
    ASSERT_FALSE(w);
    EXPECT_NE(w.error().message.find("/dev/full"), std::string::npos);
    EXPECT_NE(w.error().message.find("disk full"), std::string::npos);
}

TEST(CrashSafety, UnwritableDirectoryIsOneClearErrorAtCreate)
{
    std::filesystem::path dir =
            std::filesystem::temp_directory_path() / ("readonly-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    ::chmod(dir.c_str(), 0555);
    // Root ignores directory permissions; sysfs refuses new files even to root.
    const auto path =
            ::geteuid() == 0 ? std::filesystem::path("/sys/replica-test.mcap") : dir / "x.mcap";
    auto w = RecordingWriter::create(path, SessionInfo{});
    ASSERT_FALSE(w);
    EXPECT_NE(w.error().message.find(path.string()), std::string::npos);
    EXPECT_NE(w.error().message.find("cannot create recording"), std::string::npos);
    ::chmod(dir.c_str(), 0755);
    std::filesystem::remove_all(dir);
}

TEST(CrashSafety, DeletedFileIsOneClearError)
{
    const auto path = tempRecordingPath("deleted");
    int errors = 0;
    std::string message;
    WriterOptions options;
    options.onError = [&](const Error& e) {
        ++errors;
        message = e.message;
    };
    auto w = RecordingWriter::create(path, SessionInfo{}, options);
    ASSERT_TRUE(w);
    hal::AccelSample a;
    (*w)->write(a);
    std::filesystem::remove(path);
    for (std::uint32_t i = 0; i < 100; ++i) {
        a.sequence = i;
        (*w)->write(a);
    }
    auto closed = (*w)->close();
    ASSERT_FALSE(closed);
    EXPECT_EQ(errors, 1);
    EXPECT_NE(message.find("deleted while recording"), std::string::npos);
    EXPECT_NE(closed.error().message.find(path.string()), std::string::npos);
    EXPECT_TRUE((*w)->stats().failed);
}

} // namespace
} // namespace replica::recordings
