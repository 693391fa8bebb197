// Linear MCAP scanning: records one after another, chunks decompressed and CRC-checked, the summary
// checked against what the data section really holds, and resynchronisation for recovery.
#include <algorithm>
#include <cstring>
#include <optional>

#include <fmt/format.h>

#include <recordings/mcap/chunk_unpack.h>
#include <recordings/mcap/crc.h>
#include <recordings/mcap/reader.h>
#include <recordings/mcap/scan_state.h>

namespace replica::recordings::mcap {
namespace {

using detail::checkSummary;
using detail::ScanState;

// How far resynchronisation looks for a chunk's opcode at once.
constexpr std::uint64_t kFindStep = 64 << 10;

class Scanner : ScanState
{
public:
    Scanner(Source& in, const ScanOptions& o, const MessageSink* sink)
        : ScanState(in, o), sink_(sink)
    {
        work_.budget =
                o.maxDecompressedBytes != 0 ? o.maxDecompressedBytes : decompressionBudget(size_);
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
        if (size_ < kMagic.size() || read(0, kMagic.size()) != kMagic) {
            if (s_.readError.empty()) {
                problem("not an MCAP file (bad magic bytes at byte 0)");
            }
            return std::move(s_);
        }
        std::size_t at = kMagic.size();
        while (at < size_) {
            const std::size_t left = size_ - at;
            if (left < kRecordPrefix) {
                problem(fmt::format("truncated: {} stray byte(s) at byte {} (the file was cut "
                                    "short)",
                                    left, at));
                s_.bytesSkipped += left;
                break;
            }
            const auto prefix = read(at, kRecordPrefix);
            if (!prefix) {
                return std::move(s_);
            }
            ByteReader r(*prefix);
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
            const std::size_t next = at + kRecordPrefix + static_cast<std::size_t>(len);
            const Step step = dataRecord(op, len, at, next);
            if (step == Step::Done || stopped_ || !s_.readError.empty()) {
                return std::move(s_);
            }
            const bool ok = step == Step::Next;
            if (work_.overBudget) {
                return overBudget();
            }
            if (!ok) {
                if (!resyncFrom(at)) {
                    if (!o_.resync && s_.readError.empty()) {
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
        if (!s_.readError.empty()) {
            return std::move(s_);
        }
        if (work_.overBudget) {
            return overBudget();
        }
        problem(fmt::format("no Data End record: the recording was cut short at byte {} (power "
                            "cut or crash?); 'replica recover' rebuilds its index",
                            size_));
        return std::move(s_);
    }

    // What a record of the data section leaves the scan to do.
    enum class Step { Next, Damaged, Done };

    Step dataRecord(std::uint8_t op, std::uint64_t len, std::size_t at, std::size_t next)
    {
        switch (static_cast<Op>(op)) {
        case Op::Header:
            if (at == kMagic.size() && len <= kMaxRecordBytes) {
                const auto c = content(at, len, "Header");
                ByteReader h(c.value_or(std::string_view()));
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
            if (const auto c = content(at, len, "a Schema, Channel or Message")) {
                return inner(static_cast<Op>(op), *c, at) ? Step::Next : Step::Damaged;
            }
            s_.messagesDropped += op == static_cast<std::uint8_t>(Op::Message) ? 1 : 0;
            return Step::Damaged;
        case Op::Chunk:
            if (const auto c = content(at, len, "Chunk")) {
                return chunk(*c, at, next - at) ? Step::Next : Step::Damaged;
            }
            ++s_.chunksDamaged;
            return Step::Damaged;
        case Op::Metadata:
            if (const auto c = content(at, len, "Metadata")) {
                if (auto m = decodeMetadata(*c)) {
                    s_.metadata.push_back(std::move(*m));
                    return Step::Next;
                }
                problem(fmt::format("malformed Metadata record at byte {}", at));
            }
            return Step::Damaged;
        case Op::DataEnd:
            s_.dataEnd = true;
            s_.dataSectionEnd = at;
            dataEnd(at, len);
            checkSummary(*this, next);
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
        s_.bytesSkipped += size_ - std::min<std::size_t>(s_.dataSectionEnd, size_);
        problem(fmt::format("the recording decompresses to more than {} MiB, the budget for a "
                            "{}-byte file ({}x its size, at least {} MiB; Replica's own "
                            "recordings take about 3x): not read further",
                            (o_.maxDecompressedBytes != 0 ? o_.maxDecompressedBytes
                                                          : decompressionBudget(size_)) >>
                                    20,
                            size_, kDecompressionRatio, kMinDecompressionBudget >> 20));
        return std::move(s_);
    }

    // Finds the next plausible, intact chunk after `at`; without resync, reports failure.
    bool resyncFrom(std::size_t at)
    {
        if (!o_.resync) {
            return false;
        }
        std::uint64_t p = at + 1;
        while (p + kRecordPrefix <= size_) {
            const auto piece = read(p, std::min<std::uint64_t>(kFindStep, size_ - p));
            if (!piece) {
                break;
            }
            const void* hit =
                    std::memchr(piece->data(), static_cast<int>(Op::Chunk), piece->size());
            if (hit == nullptr) {
                p += piece->size();
                continue;
            }
            p += static_cast<std::uint64_t>(static_cast<const char*>(hit) - piece->data());
            if (p + kRecordPrefix > size_) {
                break;
            }
            if (intactChunkAt(p)) {
                s_.bytesSkipped += p - at;
                resyncAt_ = p;
                return true;
            }
            if (work_.overBudget || !s_.readError.empty()) {
                break;
            }
            ++p;
        }
        s_.bytesSkipped += size_ - at;
        return false;
    }

    // Whether a plausible chunk (zstd or uncompressed, with a CRC) starts at `p` and unpacks
    // intact within the budget.
    bool intactChunkAt(std::uint64_t p)
    {
        const auto prefix = read(p, kRecordPrefix);
        if (!prefix) {
            return false;
        }
        ByteReader r(prefix->substr(1));
        const std::uint64_t len = r.u64();
        if (len > size_ - p - kRecordPrefix || len > kMaxRecordBytes) {
            return false;
        }
        const auto whole = read(p, kRecordPrefix + len);
        if (!whole) {
            return false;
        }
        const auto c = chunkFields(whole->substr(kRecordPrefix));
        if (!c || (c->compression != "zstd" && !c->compression.empty()) || c->crc == 0) {
            return false;
        }
        return unpack(*c, records_, work_).empty();
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
            if (inChunk_) {
                chunkMessages_.push_back(std::move(*m));
            } else {
                keep(std::move(*m));
            }
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
        if (auto why = unpack(*c, records_, work_); !why.empty()) {
            if (work_.overBudget) {
                return false; // reported once, by run()
            }
            problem(fmt::format("chunk at byte {} {}", at, why));
            ++s_.chunksDamaged;
            return false;
        }
        // A chunk's messages are kept only once all its records parsed: one whose CRC matched but
        // whose records do not parse was written wrong, and none of it is kept.
        chunkMessages_.clear();
        inChunk_ = true;
        const auto why = chunkRecords(at);
        inChunk_ = false;
        if (!why.empty()) {
            if (why != "-") {
                problem(fmt::format("chunk at byte {} {}", at, why));
            }
            ++s_.chunksDamaged;
            chunkMessages_.clear();
            return false;
        }
        s_.chunks.push_back({at, length, chunkMessages_.size()});
        for (auto& m : chunkMessages_) {
            keep(std::move(m));
        }
        chunkMessages_.clear();
        return true;
    }

    // The records of the chunk at `at` (in records_): "" when all parsed, else what was wrong
    // ("-": already reported).
    std::string chunkRecords(std::size_t at)
    {
        const std::string_view records = records_;
        std::size_t p = 0;
        while (p < records.size()) {
            if (records.size() - p < kRecordPrefix) {
                return "ends in a partial record";
            }
            ByteReader r(records.substr(p, kRecordPrefix));
            const auto op = r.u8();
            const std::uint64_t len = r.u64();
            if (len > records.size() - p - kRecordPrefix) {
                return "holds a record that overruns it";
            }
            const auto body = records.substr(p + kRecordPrefix, len);
            const auto kind = static_cast<Op>(op);
            if (kind == Op::Chunk) {
                nestedChunk(at, p, len);
            }
            if ((kind == Op::Schema || kind == Op::Channel || kind == Op::Message) &&
                !inner(kind, body, at)) {
                return "-";
            }
            p += kRecordPrefix + static_cast<std::size_t>(len);
        }
        return {};
    }

    // MCAP chunks do not nest and Replica's writer never nests them: a Chunk record inside the
    // chunk at `at` (at offset `p` of its records) is not unpacked, and what it holds is lost:
    // reported and counted as a dropped chunk, so that recover says so (exit 3).
    void nestedChunk(std::size_t at, std::size_t p, std::uint64_t len)
    {
        problem(fmt::format("chunk at byte {} holds a Chunk record ({} bytes at offset {} of its "
                            "records); chunks do not nest: its messages are not read",
                            at, len, p));
        ++s_.chunksDamaged;
    }

    // A message kept: to the sink, or into the Scan.
    void keep(Message&& m)
    {
        ++s_.messageCount;
        ++s_.channelMessages[m.channelId];
        if (sink_ == nullptr) {
            s_.messages.push_back(std::move(m));
        } else if (!stopped_ && !(*sink_)(std::move(m))) {
            stopped_ = true;
        }
    }

    void dataEnd(std::size_t at, std::uint64_t len)
    {
        const auto content = read(at + kRecordPrefix, std::min<std::uint64_t>(len, 4));
        if (!content) {
            return;
        }
        ByteReader r(*content);
        const std::uint32_t crc = r.u32();
        if (r.failed()) {
            problem(fmt::format("Data End record at byte {} is malformed", at));
            return;
        }
        if (crc != 0 && crcOf(0, at) != crc && s_.readError.empty()) {
            problem("data section CRC mismatch: some byte before the Data End record changed");
        }
    }

    const MessageSink* sink_ = nullptr;
    std::size_t resyncAt_ = 0;
    Work work_;
    std::string records_;  // the chunk being unpacked
    bool inChunk_ = false; // its messages go to chunkMessages_ until it proves whole
    std::vector<Message> chunkMessages_;
    bool stopped_ = false; // the sink asked to stop
};

} // namespace

Scan scan(std::string_view file, const ScanOptions& options)
{
    MemorySource in(file);
    return Scanner(in, options, nullptr).run();
}

Scan scan(Source& source, const ScanOptions& options, const MessageSink& sink)
{
    return Scanner(source, options, &sink).run();
}

} // namespace replica::recordings::mcap
