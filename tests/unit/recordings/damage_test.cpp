// Damaged recordings: truncation at every chunk boundary and at random offsets, and random bit
// flips, are all detected (inspect reports damage) or recovered, and nothing crashes.
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>

#include <unistd.h>

#include <recordings/mcap/reader.h>
#include <recordings/recording.h>
#include <recordings/recover.h>
#include <recordings/sample_codec.h>

#include <gtest/gtest.h>

#include "../support/files.h"

namespace replica::recordings {
namespace {

using tests::slurp;
using tests::spit;

std::filesystem::path tempPath(const std::string& name)
{
    return tests::tempRecordingPath("damage-" + name);
}

// A recording of every stream with small chunks, so that there are many chunk boundaries.
struct Sample {
    std::filesystem::path path;
    std::string bytes;
    Recording original;
    std::vector<mcap::ChunkSpan> chunks;
};

const Sample& sample()
{
    static const Sample s = [] {
        Sample out;
        out.path = tempPath("original");
        SessionInfo session;
        session.softwareVersion = "replica test";
        session.wallClockStartNs = 1'700'000'000'000'000'000;
        WriterOptions options;
        options.chunkBytes = 4 * 1024;
        auto w = RecordingWriter::create(out.path, session, options);
        EXPECT_TRUE(w);
        for (std::uint32_t i = 0; i < 240; ++i) {
            const std::int64_t t = i * 8'333'333LL;
            hal::PoseSample p;
            p.timestampNs = t;
            p.sequence = i;
            p.tracked = i % 7 != 0;
            p.eyeTrackerM = {0.01 * i, 0.1 / (i + 1), 0.6};
            (*w)->write(p);
            hal::AccelSample a;
            a.timestampNs = t;
            a.sequence = i;
            a.gravity = {1e-3 * i, -9.80665, 0.25};
            (*w)->write(a);
            if (i % 24 == 0) {
                hal::SpectrumSample sp;
                sp.timestampNs = t;
                sp.sequence = i / 24;
                sp.counts.resize(256);
                for (std::size_t k = 0; k < sp.counts.size(); ++k) {
                    sp.counts[k] = static_cast<std::uint16_t>(k * 31 + i);
                }
                sp.wavelengthCoeffs = {340.0, 0.38, -1.5e-5, 1e-9};
                (*w)->write(sp);
            }
            if (i % 2 == 0) {
                (*w)->write(FrameRecord{i / 2, t, {{&trackerKind(), i}, {&accelKind(), i}}});
            }
        }
        EXPECT_TRUE((*w)->close());
        out.bytes = slurp(out.path);
        auto rec = readRecording(out.path);
        EXPECT_TRUE(rec) << rec.error().message;
        out.original = *rec;
        out.chunks = mcap::scan(out.bytes).chunks;
        // The tests work on the bytes; the file would outlive the process in /tmp (one per run).
        std::error_code ignored;
        std::filesystem::remove(out.path, ignored);
        return out;
    }();
    return s;
}

// Every sample in `got` equals the original sample with that sequence number (the originals are
// numbered 0, 1, 2, ...), in increasing order; with `prefix`, they are a gap-free prefix.
template <typename S>
void expectKept(const std::vector<S>& got,
                const std::vector<S>& original,
                bool prefix,
                const char* what)
{
    ASSERT_LE(got.size(), original.size()) << what;
    for (std::size_t i = 0; i < got.size(); ++i) {
        const auto seq = got[i].sequence;
        ASSERT_LT(seq, original.size()) << what << " #" << i;
        if (prefix) {
            ASSERT_EQ(seq, i) << what << " #" << i;
        } else if (i > 0) {
            ASSERT_GT(seq, got[i - 1].sequence) << what << " #" << i;
        }
        ASSERT_EQ(got[i].timestampNs, original[seq].timestampNs) << what << " #" << i;
    }
}

// Recovers `bytes` and checks the result against the original; returns the poses kept.
std::size_t recoverAndCheck(std::string_view bytes, const std::string& label, bool prefix)
{
    const auto in = tempPath("in");
    const auto out = tempPath("out");
    spit(in, bytes);
    auto report = recoverRecording(in, out, ExistingOutput::Replace);
    std::size_t kept = 0;
    if (report) {
        auto rec = readRecording(out);
        EXPECT_TRUE(rec) << label << ": recovered file does not read: " << rec.error().message;
        if (rec) {
            expectKept(rec->samples(recordings::trackerKind()),
                       sample().original.samples(recordings::trackerKind()), prefix, "poses");
            expectKept(rec->samples(recordings::accelKind()),
                       sample().original.samples(recordings::accelKind()), prefix, "accel");
            expectKept(rec->samples(recordings::spectrometerKind()),
                       sample().original.samples(recordings::spectrometerKind()), prefix,
                       "spectra");
            for (const auto& p : rec->samples(recordings::trackerKind())) {
                EXPECT_EQ(p.eyeTrackerM,
                          sample().original.samples(recordings::trackerKind())[p.sequence]
                                  .eyeTrackerM);
            }
            kept = rec->samples(recordings::trackerKind()).size();
        }
    }
    std::filesystem::remove(in);
    std::filesystem::remove(out);
    return kept;
}

TEST(RecordingDamage, SampleHasManyChunks)
{
    ASSERT_GE(sample().chunks.size(), 10u);
    EXPECT_EQ(sample().original.samples(recordings::trackerKind()).size(), 240u);
}

TEST(RecordingDamage, TruncationAtEveryChunkBoundaryKeepsEveryEarlierChunk)
{
    const auto& s = sample();
    std::size_t posesBefore = 0;
    for (const auto& c : s.chunks) {
        SCOPED_TRACE("cut at byte " + std::to_string(c.offset));
        const std::string_view cut = std::string_view(s.bytes).substr(0, c.offset);
        const auto scan = mcap::scan(cut);
        EXPECT_FALSE(scan.damage.empty()) << "a truncated file must report damage";
        EXPECT_FALSE(scan.dataEnd);
        if (c.offset > s.chunks.front().offset) {
            // Every pose written in an earlier chunk survives.
            EXPECT_EQ(recoverAndCheck(cut, "boundary", true), posesBefore);
        }
        std::size_t posesInChunk = 0;
        for (const auto& m :
             mcap::scan(std::string_view(s.bytes).substr(0, c.offset + c.length)).messages) {
            posesInChunk += m.channelId == static_cast<std::uint16_t>(ChannelId::Tracker) ? 1 : 0;
        }
        posesBefore = posesInChunk;
    }
}

TEST(RecordingDamage, TruncationAtRandomOffsetsIsDetectedAndRecovers)
{
    const auto& s = sample();
    std::mt19937 rng(::testing::UnitTest::GetInstance()->random_seed());
    std::uniform_int_distribution<std::size_t> at(0, s.bytes.size() - 1);
    for (int k = 0; k < 60; ++k) {
        const std::size_t n = at(rng);
        SCOPED_TRACE("cut at byte " + std::to_string(n));
        const std::string_view cut = std::string_view(s.bytes).substr(0, n);
        const auto scan = mcap::scan(cut);
        EXPECT_FALSE(scan.damage.empty());
        // Recovery keeps at least every chunk that lies wholly before the cut.
        std::size_t intact = 0;
        for (const auto& c : s.chunks) {
            intact += c.offset + c.length <= n ? 1 : 0;
        }
        EXPECT_GE(scan.chunks.size(), intact);
        if (k % 4 == 0) {
            recoverAndCheck(cut, "random cut", true);
        }
    }
}

TEST(RecordingDamage, FlipThatMakesAMessageIndexAMessageIsNotRecoveredAsAFrame)
{
    // The record after each chunk is its Message Index (opcode 0x07); bit 1 flipped makes it a
    // Message (0x05) on the index's channel whose payload is the index's own bytes. It lies
    // outside every chunk, so only the data section's CRC covers it; recover must skip it and
    // still keep every message of every chunk.
    const auto& s = sample();
    std::size_t flips = 0;
    for (std::size_t i = 0; i + 1 < s.chunks.size(); ++i) {
        const std::size_t at = s.chunks[i].offset + s.chunks[i].length;
        if (static_cast<std::uint8_t>(s.bytes[at]) != 0x07) {
            continue;
        }
        std::string damaged = s.bytes;
        damaged[at] = static_cast<char>(0x05);
        SCOPED_TRACE("message index at byte " + std::to_string(at));
        const auto scan = mcap::scan(damaged);
        EXPECT_FALSE(scan.damage.empty()); // the data section's CRC
        EXPECT_EQ(recoverAndCheck(damaged, "index made a message", true),
                  sample().original.samples(recordings::trackerKind()).size());
        ++flips;
    }
    EXPECT_GE(flips, 3u) << "the sample has too few message indexes to test";
}

TEST(RecordingDamage, RandomBitFlipsAreDetectedOrHarmless)
{
    const auto& s = sample();
    // The seed in every failure, so that a failing run can be repeated (--gtest_random_seed).
    SCOPED_TRACE("random seed " +
                 std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
    std::mt19937 rng(::testing::UnitTest::GetInstance()->random_seed() + 1);
    std::uniform_int_distribution<std::size_t> at(0, s.bytes.size() - 1);
    std::uniform_int_distribution<int> bit(0, 7);
    const auto path = tempPath("flipped");
    for (int k = 0; k < 150; ++k) {
        std::string damaged = s.bytes;
        const std::size_t where = at(rng);
        damaged[where] = static_cast<char>(damaged[where] ^ (1 << bit(rng)));
        SCOPED_TRACE("bit flip at byte " + std::to_string(where));
        // The data-section and summary CRCs cover every byte of a closed file: nothing slips by.
        const auto scan = mcap::scan(damaged);
        EXPECT_FALSE(scan.damage.empty());
        spit(path, damaged);
        auto report = inspectRecording(path);
        ASSERT_TRUE(report);
        EXPECT_FALSE(report->damage.empty());
        EXPECT_FALSE(readRecording(path)) << "a damaged file must not read as sound";
        if (k % 5 == 0) {
            recoverAndCheck(damaged, "bit flip", false);
        }
    }
    std::filesystem::remove(path);
}

TEST(RecordingDamage, FlippedChunkLosesOnlyThatChunk)
{
    const auto& s = sample();
    ASSERT_GE(s.chunks.size(), 4u);
    const auto& victim = s.chunks[2];
    std::string damaged = s.bytes;
    // A byte in the middle of the compressed records: the chunk CRC (or zstd) must catch it.
    damaged[victim.offset + victim.length / 2] ^= 0x10;
    mcap::ScanOptions resync;
    resync.resync = true;
    const auto scan = mcap::scan(damaged, resync);
    EXPECT_EQ(scan.chunksDamaged, 1u);
    EXPECT_EQ(scan.chunks.size(), s.chunks.size() - 1);
    std::uint64_t lost = 0;
    for (const auto& c : s.chunks) {
        lost += c.offset == victim.offset ? c.messages : 0;
    }
    EXPECT_EQ(scan.messages.size(), mcap::scan(s.bytes).messages.size() - lost);
}

// Chunks nested in chunks, each an uncompressed chunk record holding the next (the hostile
// recordings of issue 32): 'claimZero' makes each claim 0 uncompressed bytes, otherwise each
// claims its true size and fails its CRC. Built here from the MCAP specification's layout.
// Every level is a 49-byte header (opcode, length, start and end time, uncompressed size, CRC,
// compression "", records length) followed by the levels inside it, so the file is the headers
// written outside in: linear in its size. (Wrapping the inner levels one at a time copied
// n^2/90 bytes: 47 s of the test's 78 for 1 MiB, more under ASan; the bytes are the same.)
std::string nestedChunks(std::size_t bytes, bool claimZero)
{
    auto u64 = [](std::uint64_t v) { return std::string(reinterpret_cast<const char*>(&v), 8); };
    auto u32 = [](std::uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
    constexpr std::size_t kLevel = 1 + 8 + 8 + 8 + 8 + 4 + 4 + 8;
    const std::size_t levels = (bytes + kLevel - 1) / kLevel;
    std::string file(mcap::kMagic);
    file.reserve(file.size() + levels * kLevel);
    for (std::size_t k = levels; k-- > 0;) {
        const std::uint64_t inner = k * kLevel; // the k levels inside this one
        file += std::string(1, '\x06') + u64(kLevel - 9 + inner) + u64(0) + u64(0) +
                u64(claimZero ? 0 : inner) + u32(0xDEADBEEF) + u32(0) + u64(inner);
    }
    return file;
}

// Recover tries every plausible chunk header after damage; each attempt's copying and checksumming
// is counted against the decompression budget, so nested chunks cost at most the budget, not the
// square of the file's size (3.9 s for 4 MB before, 16 MB in minutes).
TEST(RecordingDamage, ResyncWorkOnNestedChunksIsBoundedByTheBudget)
{
    mcap::ScanOptions options;
    options.resync = true;
    options.chunkedOnly = true;
    for (const std::size_t n : {std::size_t{64} << 10, std::size_t{1} << 20}) {
        // Claiming 0 bytes: refused before anything is copied. Each of the ~n/45 levels used to
        // copy what it holds: n^2/90 bytes, 12 GB for 1 MiB.
        const auto zero = nestedChunks(n, true);
        const auto s0 = mcap::scan(zero, options);
        EXPECT_EQ(s0.bytesExamined, 0u) << n;
        EXPECT_TRUE(s0.messages.empty());
        // Claiming their true sizes: each attempt is paid for; the scan stops at the budget.
        const auto wrong = nestedChunks(n, false);
        const auto s1 = mcap::scan(wrong, options);
        EXPECT_LE(s1.bytesExamined, mcap::decompressionBudget(wrong.size())) << n;
        EXPECT_GT(s1.bytesExamined, wrong.size()) << "more than one level was tried";
        EXPECT_TRUE(s1.messages.empty());
    }
}

// Scans `bytes` in memory, and from a file through the bounded window with a sink (as recover
// does): the same messages in the same order, the same damage, chunks and work.
void expectStreamedScanMatches(const std::string& bytes,
                               const mcap::ScanOptions& options,
                               const std::string& label)
{
    const auto whole = mcap::scan(bytes, options);
    const auto path = tempPath("stream");
    spit(path, bytes);
    auto source = mcap::FileSource::open(path, kMaxRecordingBytes, "recording");
    ASSERT_TRUE(source) << label;
    std::vector<mcap::Message> got;
    const auto streamed = mcap::scan(**source, options, [&](mcap::Message&& m) {
        got.push_back(std::move(m));
        return true;
    });
    std::filesystem::remove(path);
    EXPECT_TRUE(streamed.readError.empty()) << label << ": " << streamed.readError;
    EXPECT_TRUE(streamed.messages.empty()) << label << ": a sink's messages are not kept";
    ASSERT_EQ(got.size(), whole.messages.size()) << label;
    EXPECT_EQ(streamed.messageCount, whole.messages.size()) << label;
    EXPECT_EQ(whole.messageCount, whole.messages.size()) << label;
    for (std::size_t i = 0; i < got.size(); ++i) {
        ASSERT_EQ(got[i].channelId, whole.messages[i].channelId) << label << " #" << i;
        ASSERT_EQ(got[i].sequence, whole.messages[i].sequence) << label << " #" << i;
        ASSERT_EQ(got[i].logTime, whole.messages[i].logTime) << label << " #" << i;
        ASSERT_EQ(got[i].data, whole.messages[i].data) << label << " #" << i;
    }
    EXPECT_EQ(streamed.damage, whole.damage) << label;
    EXPECT_EQ(streamed.damageCount, whole.damageCount) << label;
    EXPECT_EQ(streamed.chunks.size(), whole.chunks.size()) << label;
    EXPECT_EQ(streamed.bytesSkipped, whole.bytesSkipped) << label;
    EXPECT_EQ(streamed.bytesExamined, whole.bytesExamined) << label;
    EXPECT_EQ(streamed.metadata, whole.metadata) << label;
    EXPECT_EQ(streamed.channelMessages, whole.channelMessages) << label;
    EXPECT_EQ(streamed.summary, whole.summary) << label;
    EXPECT_EQ(streamed.footer, whole.footer) << label;
    // The window never held more than one record and the read-ahead.
    EXPECT_LE((*source)->peakWindow(), mcap::kMaxRecordBytes + (4u << 20)) << label;
}

// recover reads through a window and hands messages to the writer as they come; it must see
// exactly what a scan of the whole file in memory sees, on sound, cut and damaged files.
TEST(RecordingDamage, AStreamedScanSeesWhatAScanInMemorySees)
{
    const auto& s = sample();
    mcap::ScanOptions plain;
    mcap::ScanOptions resync;
    resync.resync = true;
    resync.chunkedOnly = true;
    for (const auto* options : {&plain, &resync}) {
        const std::string mode = options->resync ? " (resync)" : "";
        expectStreamedScanMatches(s.bytes, *options, "whole" + mode);
        expectStreamedScanMatches(s.bytes.substr(0, s.bytes.size() / 2), *options, "cut" + mode);
        std::string flipped = s.bytes;
        const auto& c = s.chunks[s.chunks.size() / 3];
        flipped[c.offset + c.length / 2] ^= 0x10;
        expectStreamedScanMatches(flipped, *options, "flipped" + mode);
        std::mt19937 rng(7);
        for (int i = 0; i < 8; ++i) {
            std::string damaged = s.bytes;
            damaged[rng() % damaged.size()] ^= static_cast<char>(1 << (rng() % 8));
            expectStreamedScanMatches(damaged, *options, "random flip " + std::to_string(i) + mode);
        }
        expectStreamedScanMatches(nestedChunks(256 << 10, false), *options, "nested" + mode);
        expectStreamedScanMatches(nestedChunks(256 << 10, true), *options, "nested zero" + mode);
    }
}

// A file that shrinks after it was opened (something truncating it) is a read error, not damage:
// recover must not write a "recovered" file from half of what it counted.
TEST(RecordingDamage, AFileThatShrinksWhileStreamedIsAReadError)
{
    const auto path = tempPath("shrinks");
    spit(path, sample().bytes);
    auto source = mcap::FileSource::open(path, kMaxRecordingBytes, "recording");
    ASSERT_TRUE(source);
    std::filesystem::resize_file(path, sample().bytes.size() / 2);
    std::uint64_t seen = 0;
    const auto s = mcap::scan(**source, {}, [&](mcap::Message&&) {
        ++seen;
        return true;
    });
    std::filesystem::remove(path);
    EXPECT_NE(s.readError.find("changed while being read"), std::string::npos) << s.readError;
    EXPECT_EQ(seen, s.messageCount);
}

// The sink can stop the scan (recover's writer failing): no message is given after it said no.
TEST(RecordingDamage, ASinkThatSaysNoStopsTheScan)
{
    const auto path = tempPath("stop");
    spit(path, sample().bytes);
    auto source = mcap::FileSource::open(path, kMaxRecordingBytes, "recording");
    ASSERT_TRUE(source);
    std::uint64_t seen = 0;
    const auto s = mcap::scan(**source, {}, [&](mcap::Message&&) { return ++seen < 10; });
    std::filesystem::remove(path);
    EXPECT_EQ(seen, 10u);
    EXPECT_LT(s.chunks.size(), sample().chunks.size());
}

} // namespace
} // namespace replica::recordings
