// Linear MCAP reader that checks everything it can (CRCs, sizes, summary) and never trusts a
// length.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <recordings/mcap/records.h>
#include <recordings/mcap/source.h>

namespace replica::recordings::mcap {

// Limits on what a recording can make Replica hold (docs/recordings.md, 'Limits'). A chunk
// decompresses to at most kMaxChunkUncompressedBytes (Replica's writer closes one at 256 KiB), and
// all chunks of a file together to at most decompressionBudget(file size): kDecompressionRatio
// times the file (Replica's recordings decompress to about 3x), and never less than
// kMinDecompressionBudget.
constexpr std::uint64_t kMaxChunkUncompressedBytes = 16ULL << 20;
constexpr std::uint64_t kDecompressionRatio = 10;
constexpr std::uint64_t kMinDecompressionBudget = 64ULL << 20;
constexpr std::uint64_t decompressionBudget(std::uint64_t fileBytes)
{
    return fileBytes * kDecompressionRatio > kMinDecompressionBudget
                   ? fileBytes * kDecompressionRatio
                   : kMinDecompressionBudget;
}

struct ScanOptions {
    // Total uncompressed bytes the scan may decompress; 0: decompressionBudget(file size).
    std::uint64_t maxDecompressedBytes = 0;
    // After damage, search forward for the next chunk that decompresses and matches its CRC and go
    // on from there (recover); otherwise stop at the first record that cannot be trusted.
    bool resync = false;
    std::size_t maxDamageReports = 20;
    // Channels (and their schemas) to assume for messages on a channel the file never defines, for
    // when the chunk that defined them was lost (recover knows each format's fixed channels).
    std::map<std::uint16_t, Channel> fallbackChannels;
    std::map<std::uint16_t, Schema> fallbackSchemas;
    // Trust Schema, Channel and Message records only inside a chunk, where a CRC covers them
    // (recover: Replica's writer puts every one in a chunk). A record of those kinds in the data
    // section itself is reported and skipped: one flipped bit turns a Message Index (opcode 0x07)
    // into a Message (0x05) whose payload is the index's bytes, and nothing checks it before the
    // Data End record's CRC, which covers the whole section and so cannot say which record broke.
    bool chunkedOnly = false;
};

struct ChunkSpan {
    std::uint64_t offset = 0, length = 0, messages = 0;
};

struct Scan {
    std::string library; // the Header's library string ("" if none)
    std::map<std::uint16_t, Schema> schemas;
    std::map<std::uint16_t, Channel> channels;
    std::vector<Message> messages;  // in file order, every one on a known channel (none kept
                                    // when a sink takes them)
    std::uint64_t messageCount = 0; // messages kept (or given to the sink)
    std::map<std::uint16_t, std::uint64_t> channelMessages; // of those, per channel
    std::vector<Metadata> metadata;    // intact Metadata records of the data section
    std::vector<ChunkSpan> chunks;     // intact chunks
    std::vector<std::string> damage;   // one sentence each, with byte offsets; empty: file is sound
    std::uint64_t damageCount = 0;     // damage found (damage may hold fewer lines)
    std::uint64_t bytesSkipped = 0;    // bytes of the data section not part of any intact record
    std::uint64_t messagesDropped = 0; // messages seen but unusable (unknown channel, malformed)
    std::uint64_t chunksDamaged = 0;   // chunk records that failed a check
    std::optional<std::uint64_t> summaryMessageCount; // what the summary's statistics claim
    std::vector<std::uint16_t> channelsAssumed;       // taken from fallbackChannels
    bool dataEnd = false;                             // the Data End record was reached
    bool footer = false;              // footer and trailing magic present and consistent
    bool summary = false;             // a summary with statistics was present and checked
    std::uint64_t dataSectionEnd = 0; // offset just past the last intact data-section record
    // Chunk bytes copied, decompressed and checksummed, every attempt counted (recover's resync
    // tries each plausible chunk header after damage), zstd input included: at most the
    // decompression budget, so the work is linear in the file's size.
    std::uint64_t bytesExamined = 0;
    std::string readError; // the file could not be read (an I/O error, or it shrank): scan ended
};

// Takes each kept message; false stops the scan (after the current record).
using MessageSink = std::function<bool(Message&&)>;

// Scans a whole file held in memory. Never throws on malformed input; reports it in damage.
Scan scan(std::string_view file, const ScanOptions& options = {});

// Scans `source` (recover: a file through a bounded window) and gives each kept message to `sink`
// instead of keeping it, in file order; a chunk's messages once the whole chunk proved intact. What
// the scan holds is one chunk and the window, whatever the file's size; the same file gives the
// same Scan (less `messages`) as the scan above.
Scan scan(Source& source, const ScanOptions& options, const MessageSink& sink);

} // namespace replica::recordings::mcap
