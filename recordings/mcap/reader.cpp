// Linear MCAP scanning: records one after another, chunks decompressed and CRC-checked, the summary
// checked against what the data section really holds, and resynchronisation for recovery.
#include <algorithm>
#include <optional>

#include <fmt/format.h>

#include <recordings/mcap/chunk_unpack.h>
#include <recordings/mcap/crc.h>
#include <recordings/mcap/reader.h>

namespace replica::recordings::mcap {
namespace {

class Scanner
{
public:
    Scanner(std::string_view file, const ScanOptions& o) : f_(file), o_(o)
    {
        work_.budget = o.maxDecompressedBytes != 0 ? o.maxDecompressedBytes
                                                   : decompressionBudget(file.size());
    }

    Scan run()
    {
        Scan s = records();
        s.bytesExamined = work_.examined;
        return s;
    }

private:
    Scan records()
    {
        if (f_.size() < kMagic.size() || f_.substr(0, kMagic.size()) != kMagic) {
            problem("not an MCAP file (bad magic bytes at byte 0)");
            return std::move(s_);
        }
        std::size_t at = kMagic.size();
        while (at < f_.size()) {
            const std::size_t left = f_.size() - at;
            if (left < kRecordPrefix) {
                problem(fmt::format("truncated: {} stray byte(s) at byte {} (the file was cut "
                                    "short)",
                                    left, at));
                s_.bytesSkipped += left;
                break;
            }
            ByteReader r(f_.substr(at, kRecordPrefix));
            const auto op = r.u8();
            const std::uint64_t len = r.u64();
            if (op == 0 || len > left - kRecordPrefix) {
                problem(op == 0 ? fmt::format("invalid record (opcode 0) at byte {}", at)
                                : fmt::format("record at byte {} (opcode 0x{:02x}) claims {} bytes "
                                              "but only {} remain: truncated or corrupted",
                                              at, op, len, left - kRecordPrefix));
                if (!resyncFrom(at)) {
                    break;
                }
                at = resyncAt_;
                continue;
            }
            const std::string_view content = f_.substr(at + kRecordPrefix, len);
            const std::size_t next = at + kRecordPrefix + static_cast<std::size_t>(len);
            const Step step = dataRecord(op, content, at, next);
            if (step == Step::Done) {
                return std::move(s_);
            }
            const bool ok = step == Step::Next;
            if (work_.overBudget) {
                return overBudget();
            }
            if (!ok) {
                if (!resyncFrom(at)) {
                    if (!o_.resync) {
                        at = next; // keep reporting: the length field looked sane
                        continue;
                    }
                    break;
                }
                at = resyncAt_;
                continue;
            }
            s_.dataSectionEnd = next;
            at = next;
        }
        if (work_.overBudget) {
            return overBudget();
        }
        problem(fmt::format("no Data End record: the recording was cut short at byte {} (power "
                            "cut or crash?); 'replica recover' rebuilds its index",
                            f_.size()));
        return std::move(s_);
    }

    // What a record of the data section leaves the scan to do.
    enum class Step { Next, Damaged, Done };

    Step dataRecord(std::uint8_t op, std::string_view content, std::size_t at, std::size_t next)
    {
        switch (static_cast<Op>(op)) {
        case Op::Header:
            if (at == kMagic.size()) {
                ByteReader h(content);
                h.str();
                s_.library = h.str();
            }
            return Step::Next;
        case Op::Schema:
        case Op::Channel:
        case Op::Message:
            if (o_.chunkedOnly) {
                // Damage, not a sample (so not counted as a dropped message); its bounds looked
                // sane: skip it whole and go on.
                problem(fmt::format("{} record at byte {} outside every chunk, where no CRC "
                                    "covers it: skipped",
                                    op == static_cast<std::uint8_t>(Op::Message)  ? "Message"
                                    : op == static_cast<std::uint8_t>(Op::Schema) ? "Schema"
                                                                                  : "Channel",
                                    at));
                s_.bytesSkipped += next - at;
                return Step::Next;
            }
            return inner(static_cast<Op>(op), content, at) ? Step::Next : Step::Damaged;
        case Op::Chunk:
            return chunk(content, at, next - at) ? Step::Next : Step::Damaged;
        case Op::Metadata:
            if (auto m = decodeMetadata(content)) {
                s_.metadata.push_back(std::move(*m));
                return Step::Next;
            }
            problem(fmt::format("malformed Metadata record at byte {}", at));
            return Step::Damaged;
        case Op::DataEnd:
            s_.dataEnd = true;
            s_.dataSectionEnd = at;
            dataEnd(content, at);
            summary(next);
            return Step::Done;
        case Op::Footer:
            problem(fmt::format("footer at byte {} without a Data End record before it", at));
            return Step::Done;
        default:
            return Step::Next; // indexes, attachments and private records carry no samples
        }
    }

    Scan overBudget()
    {
        // What is not read is lost: counted, so that recover says so (exit 3).
        ++s_.chunksDamaged;
        s_.bytesSkipped += f_.size() - std::min<std::size_t>(s_.dataSectionEnd, f_.size());
        problem(fmt::format("the recording decompresses to more than {} MiB, the budget for a "
                            "{}-byte file ({}x its size, at least {} MiB; Replica's own "
                            "recordings take about 3x): not read further",
                            (o_.maxDecompressedBytes != 0 ? o_.maxDecompressedBytes
                                                          : decompressionBudget(f_.size())) >>
                                    20,
                            f_.size(), kDecompressionRatio, kMinDecompressionBudget >> 20));
        return std::move(s_);
    }

    void problem(std::string what)
    {
        ++s_.damageCount;
        if (s_.damage.size() < o_.maxDamageReports) {
            s_.damage.push_back(std::move(what));
        }
    }

    // Finds the next plausible, intact chunk after `at`; without resync, reports failure.
    bool resyncFrom(std::size_t at)
    {
        if (!o_.resync) {
            return false;
        }
        for (std::size_t p = at + 1; p + kRecordPrefix <= f_.size(); ++p) {
            if (static_cast<std::uint8_t>(f_[p]) != static_cast<std::uint8_t>(Op::Chunk)) {
                continue;
            }
            ByteReader r(f_.substr(p + 1, 8));
            const std::uint64_t len = r.u64();
            if (len > f_.size() - p - kRecordPrefix) {
                continue;
            }
            const auto c = chunkFields(f_.substr(p + kRecordPrefix, len));
            if (!c || (c->compression != "zstd" && !c->compression.empty()) || c->crc == 0) {
                continue;
            }
            std::string records;
            if (!unpack(*c, records, work_).empty()) {
                if (work_.overBudget) {
                    break;
                }
                continue;
            }
            s_.bytesSkipped += p - at;
            resyncAt_ = p;
            return true;
        }
        s_.bytesSkipped += f_.size() - at;
        return false;
    }

    // A Schema, Channel or Message record, in the data section or inside a chunk.
    bool inner(Op op, std::string_view content, std::size_t at)
    {
        if (op == Op::Schema) {
            auto sc = decodeSchema(content);
            if (!sc) {
                problem(fmt::format("malformed Schema record at byte {}", at));
                return false;
            }
            if (sc->id == 0) {
                return true; // id 0 is invalid; readers ignore it
            }
            auto [it, fresh] = s_.schemas.emplace(sc->id, *sc);
            if (!fresh && !(it->second == *sc)) {
                problem(fmt::format("Schema {} at byte {} differs from an earlier one", sc->id,
                                    at));
            }
        } else if (op == Op::Channel) {
            auto ch = decodeChannel(content);
            if (!ch) {
                problem(fmt::format("malformed Channel record at byte {}", at));
                return false;
            }
            auto [it, fresh] = s_.channels.emplace(ch->id, *ch);
            if (!fresh && !(it->second == *ch)) {
                problem(fmt::format("Channel {} at byte {} differs from an earlier one", ch->id,
                                    at));
            }
        } else {
            auto m = decodeMessage(content);
            if (!m) {
                problem(fmt::format("malformed Message record at byte {}", at));
                ++s_.messagesDropped;
                return false;
            }
            if (!s_.channels.contains(m->channelId) && o_.fallbackChannels.contains(m->channelId)) {
                const auto& ch = o_.fallbackChannels.at(m->channelId);
                s_.channels.emplace(ch.id, ch);
                if (auto it = o_.fallbackSchemas.find(ch.schemaId);
                    it != o_.fallbackSchemas.end()) {
                    s_.schemas.emplace(it->first, it->second);
                }
                s_.channelsAssumed.push_back(ch.id);
            }
            if (!s_.channels.contains(m->channelId)) {
                problem(fmt::format("message at byte {} on channel {} that was never defined", at,
                                    m->channelId));
                ++s_.messagesDropped;
                return true;
            }
            s_.messages.push_back(std::move(*m));
        }
        return true;
    }

    bool chunk(std::string_view content, std::size_t at, std::size_t length)
    {
        const auto c = chunkFields(content);
        if (!c) {
            problem(fmt::format("chunk at byte {} has inconsistent size fields", at));
            ++s_.chunksDamaged;
            return false;
        }
        std::string records;
        if (auto why = unpack(*c, records, work_); !why.empty()) {
            if (work_.overBudget) {
                return false; // reported once, by run()
            }
            problem(fmt::format("chunk at byte {} {}", at, why));
            ++s_.chunksDamaged;
            return false;
        }
        const std::size_t before = s_.messages.size();
        // A chunk whose CRC matched but whose records do not parse was written wrong: keep none of
        // it.
        auto reject = [&](std::string why) {
            problem(fmt::format("chunk at byte {} {}", at, why));
            ++s_.chunksDamaged;
            s_.messages.resize(before);
            return false;
        };
        std::size_t p = 0;
        while (p < records.size()) {
            if (records.size() - p < kRecordPrefix) {
                return reject("ends in a partial record");
            }
            ByteReader r(std::string_view(records).substr(p, kRecordPrefix));
            const auto op = r.u8();
            const std::uint64_t len = r.u64();
            if (len > records.size() - p - kRecordPrefix) {
                return reject("holds a record that overruns it");
            }
            const auto body = std::string_view(records).substr(p + kRecordPrefix, len);
            const auto kind = static_cast<Op>(op);
            if (kind == Op::Schema || kind == Op::Channel || kind == Op::Message) {
                if (!inner(kind, body, at)) {
                    ++s_.chunksDamaged;
                    s_.messages.resize(before);
                    return false;
                }
            }
            p += kRecordPrefix + static_cast<std::size_t>(len);
        }
        s_.chunks.push_back({at, length, s_.messages.size() - before});
        return true;
    }

    void dataEnd(std::string_view content, std::size_t at)
    {
        ByteReader r(content);
        const std::uint32_t crc = r.u32();
        if (r.failed()) {
            problem(fmt::format("Data End record at byte {} is malformed", at));
            return;
        }
        if (crc != 0 && crc32(0, f_.substr(0, at)) != crc) {
            problem("data section CRC mismatch: some byte before the Data End record changed");
        }
    }

    // Checks footer, trailing magic, summary CRC and the statistics against the data section.
    void summary(std::size_t afterDataEnd)
    {
        const std::size_t size = f_.size();
        if (size < afterDataEnd + kFooterRecordSize + kMagic.size()) {
            problem("the summary or footer is missing or cut short (the recording was not closed)");
            return;
        }
        if (f_.substr(size - kMagic.size()) != kMagic) {
            problem("the file does not end with the MCAP magic bytes");
            return;
        }
        const std::size_t footerAt = size - kMagic.size() - kFooterRecordSize;
        ByteReader fr(f_.substr(footerAt, kFooterRecordSize));
        const auto op = fr.u8();
        const auto len = fr.u64();
        const auto summaryStart = fr.u64();
        const auto offsetsStart = fr.u64();
        const auto summaryCrc = fr.u32();
        if (op != static_cast<std::uint8_t>(Op::Footer) || len != 20) {
            problem(fmt::format("no valid footer at byte {}", footerAt));
            return;
        }
        if (summaryCrc != 0 &&
            crc32(0, f_.substr(afterDataEnd, footerAt + kRecordPrefix + 16 - afterDataEnd)) !=
                    summaryCrc) {
            problem("summary CRC mismatch: the summary or footer was corrupted");
            return;
        }
        if (summaryStart == 0) {
            s_.footer = true; // an unindexed file: nothing more to check
            return;
        }
        const std::size_t summaryEnd = offsetsStart != 0 ? offsetsStart : footerAt;
        if (summaryStart != afterDataEnd || summaryEnd < summaryStart || summaryEnd > footerAt) {
            problem("the footer's summary offsets are inconsistent");
            return;
        }
        s_.footer = true;
        std::size_t p = summaryStart;
        std::uint64_t chunkIndexes = 0;
        while (p < summaryEnd) {
            if (summaryEnd - p < kRecordPrefix) {
                problem("the summary ends in a partial record");
                return;
            }
            ByteReader r(f_.substr(p, kRecordPrefix));
            const auto rop = static_cast<Op>(r.u8());
            const auto rlen = r.u64();
            if (rlen > summaryEnd - p - kRecordPrefix) {
                problem(fmt::format("summary record at byte {} overruns the summary", p));
                return;
            }
            const auto body = f_.substr(p + kRecordPrefix, rlen);
            if (rop == Op::ChunkIndex) {
                ++chunkIndexes;
                chunkIndex(body, p);
            } else if (rop == Op::MetadataIndex) {
                metadataIndex(body, p);
            } else if (rop == Op::Statistics) {
                statistics(body);
            } else if (rop == Op::Channel) {
                auto ch = decodeChannel(body);
                if (!ch || s_.channels.count(ch->id) == 0 || !(s_.channels.at(ch->id) == *ch)) {
                    problem(fmt::format("summary Channel record at byte {} does not match the "
                                        "data section",
                                        p));
                }
            }
            p += kRecordPrefix + static_cast<std::size_t>(rlen);
        }
        if (chunkIndexes != s_.chunks.size()) {
            problem(fmt::format("the summary indexes {} chunks but the data section holds {}",
                                chunkIndexes, s_.chunks.size()));
        }
        if (offsetsStart != 0) {
            summaryOffsets(offsetsStart, footerAt, summaryStart, summaryEnd);
        }
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
            problem(fmt::format("malformed Chunk Index record at byte {} in the summary", at));
            return;
        }
        const auto it =
                std::lower_bound(s_.chunks.begin(), s_.chunks.end(), offset,
                                 [](const ChunkSpan& c, std::uint64_t o) { return c.offset < o; });
        if (it == s_.chunks.end() || it->offset != offset || it->length != length) {
            problem(fmt::format("the Chunk Index at byte {} points at bytes {}..+{}, where the "
                                "data section holds no intact chunk of that length",
                                at, offset, length));
            return;
        }
        while (map.remaining() > 0 && !map.failed()) {
            map.u16();
            const auto indexAt = map.u64();
            if (!map.failed() && (indexAt < offset + length || indexAt >= s_.dataSectionEnd)) {
                problem(fmt::format("the Chunk Index at byte {} puts a message index at byte {}, "
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
        if (r.failed() || offset < kMagic.size() || offset > s_.dataSectionEnd ||
            length > s_.dataSectionEnd - offset) {
            problem(fmt::format("the Metadata Index at byte {} points outside the data section "
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
            ByteReader r(f_.substr(p, kRecordPrefix));
            const auto op = static_cast<Op>(r.u8());
            const auto len = r.u64();
            if (len > to - p - kRecordPrefix) {
                problem(fmt::format("summary offset record at byte {} overruns the footer", p));
                return;
            }
            ByteReader g(f_.substr(p + kRecordPrefix, len));
            g.u8();
            const auto start = g.u64();
            const auto length = g.u64();
            if (op == Op::SummaryOffset && (g.failed() || start < summaryStart ||
                                            start > summaryEnd || length > summaryEnd - start)) {
                problem(fmt::format("the Summary Offset at byte {} points outside the summary "
                                    "(byte {}, {} bytes)",
                                    p, start, length));
                return;
            }
            p += kRecordPrefix + static_cast<std::size_t>(len);
        }
        if (p != to) {
            problem(fmt::format("the summary offsets end in a partial record at byte {}", p));
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
            problem("malformed Statistics record in the summary");
            return;
        }
        s_.summary = true;
        s_.summaryMessageCount = messageCount;
        std::map<std::uint16_t, std::uint64_t> claimed;
        while (map.remaining() > 0 && !map.failed()) {
            const auto channel = map.u16();
            claimed[channel] = map.u64();
        }
        std::map<std::uint16_t, std::uint64_t> found;
        for (const auto& m : s_.messages) {
            ++found[m.channelId];
        }
        if (messageCount != s_.messages.size() || chunkCount != s_.chunks.size() ||
            (!claimed.empty() && claimed != found)) {
            problem(fmt::format("the summary's statistics ({} messages in {} chunks) disagree "
                                "with the data section ({} messages in {} chunks)",
                                messageCount, chunkCount, s_.messages.size(), s_.chunks.size()));
        }
    }

    std::string_view f_;
    ScanOptions o_;
    Scan s_;
    std::size_t resyncAt_ = 0;
    Work work_;
};

} // namespace

Scan scan(std::string_view file, const ScanOptions& options)
{
    return Scanner(file, options).run();
}

} // namespace replica::recordings::mcap
