// Recover keeps only what the reader accepts: a message that inspect and replay would refuse is
// dropped, counted and named (exit 3), never copied into a recording that then does not read; and
// what recover cannot read (a chunk nested in a chunk, a session it cannot rebuild) is said.
#include <functional>
#include <regex>

#include <recordings/mcap/crc.h>
#include <recordings/mcap/reader.h>
#include <recordings/mcap/writer.h>
#include <recordings/recording.h>
#include <recordings/recover.h>
#include <recordings/sample_codec.h>

#include <gtest/gtest.h>

#include "../support/files.h"

// A namespace of its own: the unit tests build in unity batches, where another file's anonymous
// helpers (tempPath, ...) would clash.
namespace replica::recordings::recover_checks {
namespace {

using tests::slurp;
using tests::spit;

std::filesystem::path tempPath(const std::string& name)
{
    return tests::tempRecordingPath("recover-checks-" + name);
}

// A small sound recording with a message on every channel replay reads.
const std::string& soundRecording()
{
    static const std::string bytes = [] {
        const auto path = tempPath("sound");
        SessionInfo session;
        session.softwareVersion = "replica test";
        session.wallClockStartNs = 1'700'000'000'000'000'000;
        session.devices[&lampSelectorKind()] = {"gpio", "gpiochip0:17,27,22", "",
                                                hal::SourceKind::Live};
        WriterOptions options;
        options.chunkBytes = 2 * 1024; // several chunks
        auto w = RecordingWriter::create(path, session, options);
        EXPECT_TRUE(w) << w.error().message;
        for (std::uint32_t i = 0; i < 12; ++i) {
            const std::int64_t t = i * 16'666'667LL;
            hal::PoseSample p;
            p.timestampNs = t;
            p.sequence = i;
            p.tracked = true;
            p.eyeTrackerM = {0.01 * i, 0.1, 0.6};
            (*w)->write(p);
            hal::AccelSample a;
            a.timestampNs = t;
            a.sequence = i;
            a.gravity = {0.0, -9.80665, 0.25};
            (*w)->write(a);
            if (i % 4 == 0) {
                hal::SpectrumSample sp;
                sp.timestampNs = t;
                sp.sequence = i / 4;
                sp.integrationTimeUs = 10'000;
                sp.counts.assign(256, static_cast<std::uint16_t>(1000 + i));
                sp.wavelengthCoeffs = {340.0, 0.38, -1.5e-5, 1e-9};
                (*w)->write(sp);
                (*w)->write(hal::LampSample{t, i / 4, 1, 0b010u, 3});
                (*w)->write(ThumbnailRecord{t, i, {0x89, 'P', 'N', 'G'}});
            }
            (*w)->write(FrameRecord{i, t, {{&trackerKind(), i}, {&accelKind(), i}}});
            (*w)->write(DisplayDigestRecord{i, t, 0x0123456789abcdefULL + i});
        }
        EXPECT_TRUE((*w)->close());
        auto out = slurp(path);
        std::filesystem::remove(path);
        return out;
    }();
    return bytes;
}

// The recording `bytes` written again, whole and indexed, with each message through `edit` (its
// topic, and its index among that topic's messages) and each Metadata record through `editMeta`:
// what a recording damaged inside its messages, but intact as MCAP, looks like.
using MessageEdit = std::function<bool(const std::string& topic, std::size_t n, mcap::Message&)>;
std::string rewritten(const std::string& bytes,
                      const MessageEdit& edit,
                      const std::function<void(mcap::Metadata&)>& editMeta = {})
{
    const auto s = mcap::scan(bytes);
    EXPECT_TRUE(s.damage.empty());
    const auto path = tempPath("rewritten");
    auto w = mcap::FileWriter::create(path, s.library);
    EXPECT_TRUE(w);
    for (auto md : s.metadata) {
        if (editMeta) {
            editMeta(md);
        }
        EXPECT_TRUE((*w)->addMetadata(md));
    }
    for (const auto& [id, schema] : s.schemas) {
        (*w)->addSchema(schema);
    }
    for (const auto& [id, c] : s.channels) {
        (*w)->addChannel(c);
    }
    std::map<std::string, std::size_t> seen;
    for (auto m : s.messages) {
        const auto& topic = s.channels.at(m.channelId).topic;
        if (edit(topic, seen[topic]++, m)) {
            (*w)->addMessage(m);
        }
    }
    EXPECT_TRUE((*w)->finish());
    auto out = slurp(path);
    std::filesystem::remove(path);
    return out;
}

// `bytes` with the payload of message n on `topic` replaced by what `change` makes of it.
std::string withMessage(std::string_view topic,
                        std::size_t n,
                        const std::function<std::string(const std::string&)>& change)
{
    return rewritten(soundRecording(), [&](const std::string& t, std::size_t i, mcap::Message& m) {
        if (t == topic && i == n) {
            m.data = change(m.data);
        }
        return true;
    });
}

// The first match of `pattern` in `s` replaced.
std::function<std::string(const std::string&)> replaced(const std::string& pattern,
                                                        const std::string& with)
{
    return [=](const std::string& s) {
        return std::regex_replace(s, std::regex(pattern), with,
                                  std::regex_constants::format_first_only);
    };
}

struct Recovered {
    Expected<RecoverReport> report;
    Expected<Recording> output; // the recovered file, read back (when recover wrote one)
};

Recovered recover(const std::string& bytes)
{
    const auto in = tempPath("in");
    const auto out = tempPath("out");
    spit(in, bytes);
    std::error_code ec;
    std::filesystem::remove(out, ec);
    Recovered r{recoverRecording(in, out, ExistingOutput::Replace),
                makeError(ErrorCode::NotFound, "not written")};
    if (r.report) {
        r.output = readRecording(out);
    }
    std::filesystem::remove(in, ec);
    std::filesystem::remove(out, ec);
    return r;
}

Expected<Recording> read(const std::string& bytes)
{
    const auto path = tempPath("read");
    spit(path, bytes);
    auto r = readRecording(path);
    std::filesystem::remove(path);
    return r;
}

bool mentions(const std::vector<std::string>& lines, const std::string& what)
{
    return std::any_of(lines.begin(), lines.end(),
                       [&](const auto& l) { return l.find(what) != std::string::npos; });
}

TEST(RecoverChecks, TheSoundRecordingReadsAndRecoversWithNothingLost)
{
    ASSERT_TRUE(read(soundRecording())) << read(soundRecording()).error().message;
    const auto r = recover(soundRecording());
    ASSERT_TRUE(r.report) << r.report.error().message;
    EXPECT_FALSE(r.report->lossy());
    ASSERT_TRUE(r.output) << r.output.error().message;
    EXPECT_EQ(r.output->frames.size(), 12u);
}

// Each message the reader refuses (the hostile recordings of the prober): inspect and replay
// refuse the file, and recover drops that one message, says which, exits lossy, and writes a file
// that reads.
TEST(RecoverChecks, AMessageTheReaderRefusesIsDroppedCountedAndNamed)
{
    const std::string tracker(kTrackerTopic), frame(kFrameTopic);
    const struct {
        const char* what;
        std::string topic;
        std::size_t n;
        std::function<std::string(const std::string&)> change;
    } cases[] = {
            {"eye x a string", tracker, 5, replaced(R"("x":[^,]+)", R"("x":"a")")},
            {"eye x NaN", tracker, 5, replaced(R"("x":[^,]+)", R"("x":NaN)")},
            {"eye x 1e999", tracker, 5, replaced(R"("x":[^,]+)", R"("x":1e999)")},
            {"wavelength coeffs short", std::string(kSpectrometerTopic), 1,
             replaced(R"("wavelength_coeffs":\[[^\]]*\])", R"("wavelength_coeffs":[340])")},
            {"lamp -7", std::string(kLampSelectorTopic), 1,
             replaced(R"("lamp":1)", R"("lamp":-7)")},
            {"lamp 100000 levels", std::string(kLampSelectorTopic), 0,
             [](const std::string& s) {
                 std::string levels(200'000, '1');
                 for (std::size_t i = 1; i < levels.size(); i += 2) {
                     levels[i] = ',';
                 }
                 return std::regex_replace(s, std::regex(R"("levels":\[[^\]]*\])"),
                                           R"("levels":[)" + levels + "1]");
             }},
            {"thumbnail not base64", std::string(kThumbnailTopic), 1,
             replaced(R"("data":"[^"]*")", R"("data":"!!!!")")},
            {"digest not hex", std::string(kDisplayDigestTopic), 4,
             replaced(R"("rgba":")", R"("rgba":"zz)")},
            {"nested 100000 deep", tracker, 7,
             [](const std::string& s) {
                 return s.substr(0, s.size() - 1) + R"(,"zz":)" + std::string(100'000, '[') +
                        std::string(100'000, ']') + "}";
             }},
            {"empty", frame, 3, [](const std::string&) { return std::string(); }},
            {"not JSON", std::string(kAccelTopic), 3,
             [](const std::string&) { return std::string("\x00\x01garbage", 9); }},
            {"invalid UTF-8", tracker, 2,
             [](const std::string& s) {
                 return s.substr(0, s.size() - 1) + ",\"n\":\"\xff\xfe\"}";
             }},
            {"1.2 MB", std::string(kSpectrometerTopic), 2,
             [](const std::string& s) { return s + std::string(1'200'000, ' '); }},
    };
    for (const auto& c : cases) {
        SCOPED_TRACE(c.what);
        const auto bytes = withMessage(c.topic, c.n, c.change);
        ASSERT_NE(bytes, soundRecording());
        const auto direct = read(bytes);
        ASSERT_FALSE(direct) << "the reader accepts it: not a case for recover";
        const auto r = recover(bytes);
        ASSERT_TRUE(r.report) << r.report.error().message;
        EXPECT_TRUE(r.report->lossy()) << "recover said nothing lost";
        EXPECT_EQ(r.report->messagesDropped, 1u);
        EXPECT_TRUE(mentions(r.report->problems, c.topic + " message"))
                << (r.report->problems.empty() ? "" : r.report->problems.back());
        ASSERT_TRUE(r.output) << "recovered file does not read: " << r.output.error().message;
    }
}

// Frames going backwards: replay refused them, and now the reader does (inspect says damaged);
// recover drops the frames that go back.
TEST(RecoverChecks, FramesOutOfTickOrderAreDamage)
{
    const auto backwards =
            withMessage(kFrameTopic, 6, replaced(R"("tick_ns":\d+)", R"("tick_ns":5)"));
    const auto direct = read(backwards);
    ASSERT_FALSE(direct);
    EXPECT_NE(direct.error().message.find("frame 6 has tick_ns 5, before 83333335"),
              std::string::npos)
            << direct.error().message;
    const auto r = recover(backwards);
    ASSERT_TRUE(r.report) << r.report.error().message;
    EXPECT_TRUE(r.report->lossy());
    EXPECT_EQ(r.report->messagesDropped, 1u);
    ASSERT_TRUE(r.output) << r.output.error().message;
    EXPECT_EQ(r.output->frames.size(), 11u);
    // A tick far ahead: every later frame goes back from it.
    const auto huge = withMessage(kFrameTopic, 9,
                                  replaced(R"("tick_ns":\d+)", R"("tick_ns":9223372036854775807)"));
    ASSERT_FALSE(read(huge));
    const auto h = recover(huge);
    ASSERT_TRUE(h.report) << h.report.error().message;
    EXPECT_TRUE(h.report->lossy());
    ASSERT_TRUE(h.output) << h.output.error().message;
}

// The session's chunk lost and the copy in the metadata unusable: recover says the session could
// not be rebuilt and writes nothing (it used to write a file inspect refused, and exit 0).
TEST(RecoverChecks, ASessionThatCannotBeRebuiltIsNothingRecoverable)
{
    const auto bytes = rewritten(
            soundRecording(),
            [](const std::string& topic, std::size_t, mcap::Message&) {
                return topic != kSessionTopic;
            },
            [](mcap::Metadata& md) {
                auto& session = md.metadata["session"];
                session = std::regex_replace(session, std::regex(R"("format_version":\d+)"),
                                             R"("format_version":"x")");
            });
    const auto r = recover(bytes);
    ASSERT_FALSE(r.report);
    EXPECT_NE(r.report.error().message.find("the session could not be rebuilt"), std::string::npos)
            << r.report.error().message;
    EXPECT_NE(r.report.error().message.find("format_version"), std::string::npos)
            << r.report.error().message;
    // With the metadata's copy intact, the session is restored and the rest kept.
    const auto restorable =
            rewritten(soundRecording(), [](const std::string& topic, std::size_t, mcap::Message&) {
                return topic != kSessionTopic;
            });
    const auto ok = recover(restorable);
    ASSERT_TRUE(ok.report) << ok.report.error().message;
    EXPECT_TRUE(ok.report->sessionRestored);
    EXPECT_TRUE(ok.report->lossy()) << "the session's chunk, with the first samples, is gone";
    ASSERT_TRUE(ok.output) << ok.output.error().message;
}

// A session of a format newer than this build reads: recover refuses and writes nothing (it said
// "nothing lost", exit 0, and wrote a file inspect then refused as newer than it reads).
TEST(RecoverChecks, ANewerFormatIsRefusedNotCalledWhole)
{
    const auto newer = withMessage(kSessionTopic, 0,
                                   replaced(R"("format_version":\d+)", R"("format_version":99)"));
    const auto direct = read(newer);
    ASSERT_FALSE(direct);
    EXPECT_NE(direct.error().message.find("newer than this replica reads"), std::string::npos);
    const auto in = tempPath("newer-in");
    const auto out = tempPath("newer-out");
    spit(in, newer);
    std::error_code ec;
    std::filesystem::remove(out, ec);
    const auto r = recoverRecording(in, out, ExistingOutput::Replace);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("recording format 99 is newer than this replica reads"),
              std::string::npos)
            << r.error().message;
    EXPECT_NE(r.error().message.find("nothing was written"), std::string::npos);
    EXPECT_FALSE(std::filesystem::exists(out));
    std::filesystem::remove(in, ec);
}

// Values no Replica build writes, that the reader used to take after a cast (3.5 as frame 3, a pose
// time of 2^64-1 as -1) or pass on unused (lamp 99 of a three-lamp switch): damage, naming the
// field, and dropped by recover.
TEST(RecoverChecks, IntegersThatDoNotFitAndImpossibleLampsAreDamage)
{
    const struct {
        const char* what;
        std::string topic;
        std::function<std::string(const std::string&)> change;
        const char* says;
    } cases[] = {
            {"frame 3.5", std::string(kFrameTopic), replaced(R"("frame":\d+)", R"("frame":3.5)"),
             "frame: expected an integer, found number 3.5"},
            {"frame 10^29", std::string(kFrameTopic),
             replaced(R"("frame":\d+)", R"("frame":123456789012345678901234567890)"),
             "frame: expected an integer"},
            {"pose t 2^64-1", std::string(kTrackerTopic),
             replaced(R"("t":\d+)", R"("t":18446744073709551615)"),
             "t: 18446744073709551615 is out of range"},
            {"lamp 99", std::string(kLampSelectorTopic), replaced(R"("lamp":1)", R"("lamp":99)"),
             "lamp 99"},
            // A detector count past 16 bits would wrap (70000 read as 4464, -1 as 65535): a light
            // the instrument never saw.
            {"count 70000", std::string(kSpectrometerTopic),
             replaced(R"("counts":\[\d+)", R"("counts":[70000)"),
             "counts[0]: 70000 is out of range [0, 65535]"},
            {"count -1", std::string(kSpectrometerTopic),
             replaced(R"("counts":\[\d+)", R"("counts":[-1)"), "counts[0]: -1 is out of range"},
            {"count 12.5", std::string(kSpectrometerTopic),
             replaced(R"("counts":\[\d+)", R"("counts":[12.5)"),
             "counts[0]: expected an integer, found number 12.5"},
    };
    for (const auto& c : cases) {
        SCOPED_TRACE(c.what);
        const auto bytes = withMessage(c.topic, 2, c.change);
        const auto direct = read(bytes);
        ASSERT_FALSE(direct) << "the reader accepts it";
        EXPECT_NE(direct.error().message.find(c.says), std::string::npos) << direct.error().message;
        const auto r = recover(bytes);
        ASSERT_TRUE(r.report) << r.report.error().message;
        EXPECT_TRUE(r.report->lossy());
        EXPECT_EQ(r.report->messagesDropped, 1u);
        ASSERT_TRUE(r.output) << r.output.error().message;
    }
}

// A chunk nested inside another (uncompressed, CRC intact): MCAP chunks do not nest, so what the
// inner one holds is not read; that is said and counted, not silently lost.
TEST(RecoverChecks, AChunkInsideAChunkIsCountedAsDropped)
{
    const std::string& bytes = soundRecording();
    const auto chunks = mcap::scan(bytes).chunks;
    ASSERT_GT(chunks.size(), 2u);
    const auto& c = chunks[1];
    const std::string inner = bytes.substr(c.offset, c.length);
    auto u64 = [](std::uint64_t v) { return std::string(reinterpret_cast<const char*>(&v), 8); };
    auto u32 = [](std::uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
    const std::string body = u64(0) + u64(0) + u64(inner.size()) + u32(mcap::crc32(0, inner)) +
                             u32(0) + u64(inner.size()) + inner;
    const std::string nested = bytes.substr(0, c.offset) + std::string(1, '\x06') +
                               u64(body.size()) + body + bytes.substr(c.offset + c.length);
    const auto s = mcap::scan(nested);
    EXPECT_TRUE(mentions(s.damage, "chunks do not nest"));
    const auto r = recover(nested);
    ASSERT_TRUE(r.report) << r.report.error().message;
    EXPECT_TRUE(r.report->lossy()) << "recover said nothing lost";
    EXPECT_GE(r.report->chunksDamaged, 1u);
    EXPECT_TRUE(mentions(r.report->problems, "chunks do not nest"));
    ASSERT_TRUE(r.output) << r.output.error().message;
}

} // namespace
} // namespace replica::recordings::recover_checks
