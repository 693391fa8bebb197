// The summary of a recording checked against its data section: footer, magic, CRC, the chunk and
// metadata indexes, summary offsets and statistics.
#include <algorithm>
#include <map>

#include <fmt/format.h>

#include <recordings/mcap/scan_state.h>

namespace replica::recordings::mcap::detail {
namespace {

class SummaryChecker
{
public:
    explicit SummaryChecker(ScanState& st) : st_(st) {}

    void summary(std::size_t afterDataEnd)
    {
        const std::size_t size = st_.size_;
        if (size < afterDataEnd + kFooterRecordSize + kMagic.size()) {
            st_.problem(
                    "the summary or footer is missing or cut short (the recording was not closed)");
            return;
        }
        const auto magic = st_.read(size - kMagic.size(), kMagic.size());
        if (!magic || *magic != kMagic) {
            if (magic) {
                st_.problem("the file does not end with the MCAP magic bytes");
            }
            return;
        }
        const std::size_t footerAt = size - kMagic.size() - kFooterRecordSize;
        const auto footer = st_.read(footerAt, kFooterRecordSize);
        if (!footer) {
            return;
        }
        ByteReader fr(*footer);
        const auto op = fr.u8();
        const auto len = fr.u64();
        const auto summaryStart = fr.u64();
        const auto offsetsStart = fr.u64();
        const auto summaryCrc = fr.u32();
        if (op != static_cast<std::uint8_t>(Op::Footer) || len != 20) {
            st_.problem(fmt::format("no valid footer at byte {}", footerAt));
            return;
        }
        if (summaryCrc != 0 &&
            st_.crcOf(afterDataEnd, footerAt + kRecordPrefix + 16) != summaryCrc) {
            if (st_.s_.readError.empty()) {
                st_.problem("summary CRC mismatch: the summary or footer was corrupted");
            }
            return;
        }
        if (summaryStart == 0) {
            st_.s_.footer = true; // an unindexed file: nothing more to check
            return;
        }
        const std::size_t summaryEnd = offsetsStart != 0 ? offsetsStart : footerAt;
        if (summaryStart != afterDataEnd || summaryEnd < summaryStart || summaryEnd > footerAt) {
            st_.problem("the footer's summary offsets are inconsistent");
            return;
        }
        st_.s_.footer = true;
        if (!summaryRecords(summaryStart, summaryEnd)) {
            return;
        }
        if (offsetsStart != 0) {
            summaryOffsets(offsetsStart, footerAt, summaryStart, summaryEnd);
        }
    }

    // The records of the summary, [from, to): whether they all could be checked.
    bool summaryRecords(std::size_t from, std::size_t to)
    {
        std::size_t p = from;
        std::uint64_t chunkIndexes = 0;
        while (p < to) {
            if (to - p < kRecordPrefix) {
                st_.problem("the summary ends in a partial record");
                return false;
            }
            const auto prefix = st_.read(p, kRecordPrefix);
            if (!prefix) {
                return false;
            }
            ByteReader r(*prefix);
            const auto rop = static_cast<Op>(r.u8());
            const auto rlen = r.u64();
            if (rlen > to - p - kRecordPrefix) {
                st_.problem(fmt::format("summary record at byte {} overruns the summary", p));
                return false;
            }
            if (rop == Op::ChunkIndex || rop == Op::MetadataIndex || rop == Op::Statistics ||
                rop == Op::Channel) {
                const auto body = st_.content(p, rlen, "summary");
                if (!body) {
                    return false;
                }
                if (rop == Op::ChunkIndex) {
                    ++chunkIndexes;
                    chunkIndex(*body, p);
                } else if (rop == Op::MetadataIndex) {
                    metadataIndex(*body, p);
                } else if (rop == Op::Statistics) {
                    statistics(*body);
                } else if (!summaryChannelMatches(*body)) {
                    st_.problem(fmt::format("summary Channel record at byte {} does not match the "
                                            "data section",
                                            p));
                }
            }
            p += kRecordPrefix + static_cast<std::size_t>(rlen);
        }
        if (chunkIndexes != st_.s_.chunks.size()) {
            st_.problem(fmt::format("the summary indexes {} chunks but the data section holds {}",
                                    chunkIndexes, st_.s_.chunks.size()));
        }
        return true;
    }

    bool summaryChannelMatches(std::string_view body) const
    {
        auto ch = decodeChannel(body);
        return ch && st_.s_.channels.count(ch->id) != 0 && st_.s_.channels.at(ch->id) == *ch;
    }

    // A Chunk Index must point at a chunk the scan found intact, exactly, and its message index
    // offsets into the data section after that chunk: an index is how other readers seek.
    void chunkIndex(std::string_view body, std::size_t at)
    {
        ByteReader r(body);
        r.u64();
        r.u64();
        const auto offset = r.u64();
        const auto length = r.u64();
        ByteReader map(r.str());
        if (r.failed()) {
            st_.problem(fmt::format("malformed Chunk Index record at byte {} in the summary", at));
            return;
        }
        const auto it =
                std::lower_bound(st_.s_.chunks.begin(), st_.s_.chunks.end(), offset,
                                 [](const ChunkSpan& c, std::uint64_t o) { return c.offset < o; });
        if (it == st_.s_.chunks.end() || it->offset != offset || it->length != length) {
            st_.problem(fmt::format("the Chunk Index at byte {} points at bytes {}..+{}, where the "
                                    "data section holds no intact chunk of that length",
                                    at, offset, length));
            return;
        }
        while (map.remaining() > 0 && !map.failed()) {
            map.u16();
            const auto indexAt = map.u64();
            if (!map.failed() && (indexAt < offset + length || indexAt >= st_.s_.dataSectionEnd)) {
                st_.problem(
                        fmt::format("the Chunk Index at byte {} puts a message index at byte {}, "
                                    "outside the data section after its chunk",
                                    at, indexAt));
                return;
            }
        }
    }

    void metadataIndex(std::string_view body, std::size_t at)
    {
        ByteReader r(body);
        const auto offset = r.u64();
        const auto length = r.u64();
        if (r.failed() || offset < kMagic.size() || offset > st_.s_.dataSectionEnd ||
            length > st_.s_.dataSectionEnd - offset) {
            st_.problem(fmt::format("the Metadata Index at byte {} points outside the data section "
                                    "(byte {}, {} bytes)",
                                    at, offset, length));
        }
    }

    // Summary Offset records, between their start and the footer: each group within the summary.
    void summaryOffsets(std::size_t from,
                        std::size_t to,
                        std::size_t summaryStart,
                        std::size_t summaryEnd)
    {
        std::size_t p = from;
        while (p + kRecordPrefix <= to) {
            const auto prefix = st_.read(p, kRecordPrefix);
            if (!prefix) {
                return;
            }
            ByteReader r(*prefix);
            const auto op = static_cast<Op>(r.u8());
            const auto len = r.u64();
            if (len > to - p - kRecordPrefix) {
                st_.problem(fmt::format("summary offset record at byte {} overruns the footer", p));
                return;
            }
            const auto fields = st_.read(p + kRecordPrefix, std::min<std::uint64_t>(len, 17));
            if (!fields) {
                return;
            }
            ByteReader g(*fields);
            g.u8();
            const auto start = g.u64();
            const auto length = g.u64();
            if (op == Op::SummaryOffset && (g.failed() || start < summaryStart ||
                                            start > summaryEnd || length > summaryEnd - start)) {
                st_.problem(fmt::format("the Summary Offset at byte {} points outside the summary "
                                        "(byte {}, {} bytes)",
                                        p, start, length));
                return;
            }
            p += kRecordPrefix + static_cast<std::size_t>(len);
        }
        if (p != to) {
            st_.problem(fmt::format("the summary offsets end in a partial record at byte {}", p));
        }
    }

    void statistics(std::string_view body)
    {
        ByteReader r(body);
        const auto messageCount = r.u64();
        r.u16();
        r.u32();
        r.u32();
        r.u32();
        const auto chunkCount = r.u32();
        r.u64();
        r.u64();
        ByteReader map(r.str());
        if (r.failed()) {
            st_.problem("malformed Statistics record in the summary");
            return;
        }
        st_.s_.summary = true;
        st_.s_.summaryMessageCount = messageCount;
        std::map<std::uint16_t, std::uint64_t> claimed;
        while (map.remaining() > 0 && !map.failed()) {
            const auto channel = map.u16();
            claimed[channel] = map.u64();
        }
        if (messageCount != st_.s_.messageCount || chunkCount != st_.s_.chunks.size() ||
            (!claimed.empty() && claimed != st_.s_.channelMessages)) {
            st_.problem(fmt::format("the summary's statistics ({} messages in {} chunks) disagree "
                                    "with the data section ({} messages in {} chunks)",
                                    messageCount, chunkCount, st_.s_.messageCount,
                                    st_.s_.chunks.size()));
        }
    }

private:
    ScanState& st_;
};

} // namespace

void checkSummary(ScanState& st, std::size_t afterDataEnd)
{
    SummaryChecker(st).summary(afterDataEnd);
}

} // namespace replica::recordings::mcap::detail
