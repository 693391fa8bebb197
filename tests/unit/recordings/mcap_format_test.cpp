// MCAP structure written by the recorder, checked byte by byte against the specification: CRCs,
// chunk indexes, message indexes, statistics, summary offsets, footer, schemas.
#include <fstream>
#include <iterator>

#include <nlohmann/json.hpp>
#include <zstd.h>

#include <recordings/mcap/crc.h>
#include <recordings/mcap/reader.h>
#include <recordings/mcap/records.h>
#include <recordings/recording.h>
#include <recordings/sample_codec.h>

#include <gtest/gtest.h>

#include "../support/files.h"

namespace replica::recordings {
namespace {

using mcap::ByteReader;
using mcap::Op;

using tests::slurp;

struct Rec {
    Op op;
    std::size_t at;
    std::string_view body;
};

// Independent of the scanner under test: a plain record walk over [from, to).
std::vector<Rec> walk(std::string_view f, std::size_t from, std::size_t to)
{
    std::vector<Rec> out;
    while (from < to) {
        ByteReader r(f.substr(from, 9));
        const auto op = static_cast<Op>(r.u8());
        const auto len = static_cast<std::size_t>(r.u64());
        out.push_back({op, from, f.substr(from + 9, len)});
        from += 9 + len;
    }
    return out;
}

std::filesystem::path writeSample(const std::string& name, int spectra, int poses)
{
    const auto path =
            std::filesystem::temp_directory_path() / (name + std::to_string(::getpid()) + ".mcap");
    SessionInfo session;
    session.softwareVersion = "replica test";
    WriterOptions options;
    options.chunkBytes = 16 * 1024; // several chunks
    auto w = RecordingWriter::create(path, session, options);
    EXPECT_TRUE(w);
    for (int i = 0; i < spectra; ++i) {
        hal::SpectrumSample s;
        s.timestampNs = i * 200'000'000LL;
        s.sequence = static_cast<std::uint32_t>(i);
        s.counts.assign(2048, static_cast<std::uint16_t>(i));
        (*w)->write(s);
    }
    for (int i = 0; i < poses; ++i) {
        hal::PoseSample p;
        p.timestampNs = i * 8'333'333LL;
        p.sequence = static_cast<std::uint32_t>(i);
        p.eyeTrackerM = {0.1 * i, 0.2, 0.6};
        (*w)->write(p);
    }
    EXPECT_TRUE((*w)->close());
    return path;
}

TEST(McapCrc, MatchesTheStandardCheckValue)
{
    EXPECT_EQ(mcap::crc32(0, "123456789"), 0xCBF43926u);
    // Chaining equals one pass.
    EXPECT_EQ(mcap::crc32(mcap::crc32(0, "1234"), "56789"), 0xCBF43926u);
}

TEST(McapFormat, LayoutFollowsTheSpecification)
{
    const auto path = writeSample("layout", 30, 200);
    const std::string f = slurp(path);
    ASSERT_GT(f.size(), 100u);
    ASSERT_EQ(f.substr(0, 8), std::string(mcap::kMagic));
    ASSERT_EQ(f.substr(f.size() - 8), std::string(mcap::kMagic));

    // Footer: the last 29 bytes before the magic.
    const std::size_t footerAt = f.size() - 8 - 29;
    ByteReader fr(std::string_view(f).substr(footerAt, 29));
    ASSERT_EQ(fr.u8(), static_cast<std::uint8_t>(Op::Footer));
    ASSERT_EQ(fr.u64(), 20u);
    const auto summaryStart = static_cast<std::size_t>(fr.u64());
    const auto offsetsStart = static_cast<std::size_t>(fr.u64());
    const auto summaryCrc = fr.u32();

    // Data section: header first, ends with Data End whose CRC covers everything before it.
    const auto data = walk(f, 8, summaryStart);
    ASSERT_EQ(data.front().op, Op::Header);
    ASSERT_EQ(data.back().op, Op::DataEnd);
    ByteReader de(data.back().body);
    EXPECT_EQ(de.u32(), mcap::crc32(0, std::string_view(f).substr(0, data.back().at)));
    EXPECT_EQ(summaryCrc, mcap::crc32(0, std::string_view(f).substr(
                                                 summaryStart, footerAt + 9 + 16 - summaryStart)));

    // Every chunk is zstd with a correct uncompressed CRC and is followed by its message indexes.
    std::vector<std::size_t> chunkOffsets;
    std::uint64_t messagesInChunks = 0;
    for (std::size_t i = 0; i < data.size(); ++i) {
        if (data[i].op == Op::Message) {
            ADD_FAILURE() << "message outside a chunk at byte " << data[i].at;
        }
        if (data[i].op != Op::Chunk) {
            continue;
        }
        chunkOffsets.push_back(data[i].at);
        ByteReader c(data[i].body);
        c.u64();
        c.u64();
        const auto usize = c.u64();
        const auto crc = c.u32();
        EXPECT_EQ(c.str(), "zstd");
        const auto compressed = c.bytes(c.u64());
        std::string records(usize, '\0');
        ASSERT_EQ(ZSTD_decompress(records.data(), records.size(), compressed.data(),
                                  compressed.size()),
                  usize);
        EXPECT_EQ(crc, mcap::crc32(0, records));
        // Message index entries point at Message records inside the uncompressed chunk.
        for (std::size_t j = i + 1; j < data.size() && data[j].op == Op::MessageIndex; ++j) {
            ByteReader mi(data[j].body);
            const auto channel = mi.u16();
            ByteReader entries(mi.str());
            while (entries.remaining() > 0) {
                const auto logTime = entries.u64();
                const auto offset = static_cast<std::size_t>(entries.u64());
                ASSERT_LT(offset, records.size());
                EXPECT_EQ(static_cast<Op>(records[offset]), Op::Message);
                ByteReader m(std::string_view(records).substr(offset + 9));
                EXPECT_EQ(m.u16(), channel);
                m.u32();
                EXPECT_EQ(m.u64(), logTime);
                ++messagesInChunks;
            }
        }
    }
    EXPECT_GE(chunkOffsets.size(), 3u);

    // Summary: grouped by opcode, chunk indexes point at the chunks, statistics agree.
    const auto summary = walk(f, summaryStart, offsetsStart);
    std::vector<std::size_t> indexed;
    std::map<Op, std::pair<std::size_t, std::size_t>> groups;
    for (const auto& r : summary) {
        auto& g = groups[r.op];
        if (g.second == 0) {
            g.first = r.at;
        }
        g.second = r.at + 9 + r.body.size() - g.first;
        if (r.op == Op::ChunkIndex) {
            ByteReader ci(r.body);
            ci.u64();
            ci.u64();
            indexed.push_back(static_cast<std::size_t>(ci.u64()));
        } else if (r.op == Op::Statistics) {
            ByteReader st(r.body);
            EXPECT_EQ(st.u64(), messagesInChunks);
            EXPECT_EQ(st.u16(), channelDefinitions().size());
            EXPECT_EQ(st.u32(), channelDefinitions().size());
            st.u32();
            st.u32();
            EXPECT_EQ(st.u32(), chunkOffsets.size());
        } else if (r.op == Op::Schema) {
            auto s = mcap::decodeSchema(r.body);
            ASSERT_TRUE(s);
            EXPECT_EQ(s->encoding, "jsonschema");
            const auto j = nlohmann::json::parse(s->data); // a real JSON Schema document
            EXPECT_EQ(j.at("type"), "object");
            EXPECT_FALSE(j.at("properties").empty());
        }
    }
    EXPECT_EQ(indexed, chunkOffsets);
    const auto offsets = walk(f, offsetsStart, footerAt);
    ASSERT_EQ(offsets.size(), groups.size());
    for (const auto& r : offsets) {
        ByteReader so(r.body);
        const auto op = static_cast<Op>(so.u8());
        EXPECT_EQ(so.u64(), groups.at(op).first);
        EXPECT_EQ(so.u64(), groups.at(op).second);
    }
    // The scanner agrees the file is sound.
    const auto s = mcap::scan(f);
    EXPECT_TRUE(s.damage.empty()) << s.damage.front();
    EXPECT_TRUE(s.summary);
    std::filesystem::remove(path);
}

TEST(McapFormat, MessagesCarryWallClockLogTimesAndPerChannelSequences)
{
    const auto path = std::filesystem::temp_directory_path() /
                      ("logtime" + std::to_string(::getpid()) + ".mcap");
    SessionInfo session;
    session.wallClockStartNs = 1'700'000'000'000'000'000;
    {
        auto w = RecordingWriter::create(path, session);
        ASSERT_TRUE(w);
        for (std::uint32_t i = 0; i < 3; ++i) {
            hal::AccelSample a;
            a.timestampNs = 10'000'000 * i;
            a.sequence = 40 + i;
            (*w)->write(a);
        }
        ASSERT_TRUE((*w)->close());
    }
    const auto s = mcap::scan(slurp(path));
    ASSERT_TRUE(s.damage.empty());
    std::vector<const mcap::Message*> accel;
    for (const auto& m : s.messages) {
        if (s.channels.at(m.channelId).topic == kAccelTopic) {
            accel.push_back(&m);
        }
    }
    ASSERT_EQ(accel.size(), 3u);
    for (std::uint32_t i = 0; i < 3; ++i) {
        EXPECT_EQ(accel[i]->sequence, i);
        EXPECT_EQ(accel[i]->logTime, 1'700'000'000'000'000'000ULL + 10'000'000ULL * i);
        EXPECT_EQ(accel[i]->publishTime, accel[i]->logTime);
    }
    std::filesystem::remove(path);
}

} // namespace
} // namespace replica::recordings
