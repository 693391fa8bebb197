// Chunk records: their fields, and their records decompressed and CRC-checked within a budget.
#include <fmt/format.h>
#include <zstd.h>

#include <recordings/mcap/chunk_unpack.h>
#include <recordings/mcap/crc.h>
#include <recordings/mcap/reader.h>
#include <recordings/mcap/records.h>

namespace replica::recordings::mcap {
namespace {

// Refuse chunks claiming more than this uncompressed: Replica's writer closes a chunk at 256 KiB,
// and a corrupt or hostile size field must not make the reader allocate gigabytes.
constexpr std::uint64_t kMaxChunkBytes = kMaxChunkUncompressedBytes;

} // namespace

std::optional<ChunkFields> chunkFields(std::string_view content)
{
    ByteReader r(content);
    ChunkFields c;
    c.startTime = r.u64();
    c.endTime = r.u64();
    c.uncompressedSize = r.u64();
    c.crc = r.u32();
    c.compression = r.str();
    c.records = r.bytes(r.u64());
    if (r.failed() || r.remaining() != 0) {
        return std::nullopt;
    }
    return c;
}

std::string unpack(const ChunkFields& c, std::string& out, Work& work)
{
    if (c.compression.empty() && c.records.size() != c.uncompressedSize) {
        // Checked before the copy: a chunk claiming 0 bytes must not make each attempt copy
        // megabytes for free (nested chunks made recover quadratic in the file's size).
        return fmt::format("holds {} bytes uncompressed, not the {} it claims", c.records.size(),
                           c.uncompressedSize);
    }
    if (c.uncompressedSize > kMaxChunkBytes) {
        return fmt::format("claims {} uncompressed bytes (at most {} MiB)", c.uncompressedSize,
                           kMaxChunkBytes >> 20);
    }
    if (c.compression == "zstd") {
        // The frame says its own content size: a chunk claiming more than its frame holds is
        // refused before the claim is allocated.
        const unsigned long long framed =
                ZSTD_getFrameContentSize(c.records.data(), c.records.size());
        if (framed == ZSTD_CONTENTSIZE_ERROR) {
            return "does not decompress (not a zstd frame)";
        }
        if (framed != ZSTD_CONTENTSIZE_UNKNOWN && framed != c.uncompressedSize) {
            return fmt::format("claims {} uncompressed bytes but its zstd frame holds {}",
                               c.uncompressedSize, framed);
        }
    } else if (!c.compression.empty()) {
        return fmt::format("uses unsupported compression '{}'", c.compression);
    }
    // What this attempt reads and writes: the uncompressed records, and a zstd frame's input too
    // (a frame of many empty blocks produces nothing but takes time to read).
    const std::uint64_t cost = c.uncompressedSize + (c.compression.empty() ? 0 : c.records.size());
    if (cost > work.budget) {
        work.overBudget = true;
        return fmt::format("would take the recording past its decompression budget ({})",
                           "see docs/recordings.md, 'Limits'");
    }
    work.budget -= cost;
    work.examined += cost;
    if (c.compression.empty()) {
        out.assign(c.records);
    } else if (c.compression == "zstd") {
        out.resize(static_cast<std::size_t>(c.uncompressedSize));
        const std::size_t n =
                ZSTD_decompress(out.data(), out.size(), c.records.data(), c.records.size());
        if (ZSTD_isError(n)) {
            return fmt::format("does not decompress ({})", ZSTD_getErrorName(n));
        }
        out.resize(n);
    } else {
        return fmt::format("uses unsupported compression '{}'", c.compression);
    }
    if (out.size() != c.uncompressedSize) {
        return fmt::format("decompresses to {} bytes, not the {} it claims", out.size(),
                           c.uncompressedSize);
    }
    if (c.crc != 0 && crc32(0, out) != c.crc) {
        return "fails its CRC check (corrupted)";
    }
    return {};
}

} // namespace replica::recordings::mcap
