// Low-level MCAP file writer: chunked (zstd), CRC'd, indexed, with a summary and footer at
// finish().
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <pipeline/base/expected.h>
#include <recordings/mcap/records.h>

namespace replica::recordings::mcap {

// Appends records to one file. Schemas, channels and messages go into the open chunk; closeChunk()
// compresses it and appends it with its message indexes in one write (optionally fdatasync'ed), so
// a file cut short anywhere still holds every earlier chunk intact. The first I/O failure is kept:
// every later call returns it and writes nothing more, leaving the file as a valid prefix.
// Not thread-safe: one thread owns a writer.
class FileWriter
{
public:
    // Creates `path` and writes the magic and the Header record. Never follows a symbolic link;
    // a non-empty regular file there is truncated only when 'overwrite'.
    static Expected<std::unique_ptr<FileWriter>>
    create(const std::filesystem::path& path, const std::string& library, bool overwrite = true);
    ~FileWriter();
    FileWriter(const FileWriter&) = delete;
    FileWriter& operator=(const FileWriter&) = delete;

    void addSchema(const Schema& s);
    void addChannel(const Channel& c);
    void addMessage(const Message& m);
    // Written at once, outside any chunk (so it survives damage to the chunks), and indexed in the
    // summary.
    Expected<void> addMetadata(const Metadata& m);

    // Uncompressed bytes in the open chunk (0: nothing pending).
    std::size_t pendingBytes() const { return chunk_.size(); }
    Expected<void> closeChunk(bool sync);
    // Closes the open chunk, writes Data End, the summary, summary offsets and footer, syncs and
    // closes the file.
    Expected<void> finish();

    std::uint64_t bytesWritten() const { return offset_; }
    std::uint64_t chunkCount() const { return chunkIndexes_.size(); }
    const std::optional<Error>& failure() const { return failure_; }

private:
    FileWriter(int fd, std::filesystem::path path);
    Expected<void> put(std::string_view bytes);
    Expected<void> fail(std::string what, int err);
    Expected<void> checkNotDeleted();
    std::string summarySection(std::uint64_t summaryStart) const;
    std::string chunkIndexRecords() const;
    std::string statisticsRecord() const;

    struct ChunkIndex {
        std::uint64_t startTime = 0, endTime = 0, offset = 0, length = 0;
        std::map<std::uint16_t, std::uint64_t> indexOffsets;
        std::uint64_t indexLength = 0, compressedSize = 0, uncompressedSize = 0;
    };

    int fd_ = -1;
    std::filesystem::path path_;
    std::uint64_t offset_ = 0;
    std::uint32_t dataCrc_ = 0;
    std::string chunk_;
    std::uint64_t chunkStart_ = 0, chunkEnd_ = 0;
    bool chunkHasMessages_ = false;
    std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> chunkMessages_;
    std::vector<Schema> schemas_;
    std::vector<Channel> channels_;
    std::vector<ChunkIndex> chunkIndexes_;
    struct MetadataIndex {
        std::uint64_t offset = 0, length = 0;
        std::string name;
    };
    std::vector<MetadataIndex> metadataIndexes_;
    std::map<std::uint16_t, std::uint64_t> channelCounts_;
    std::uint64_t messageCount_ = 0, firstTime_ = UINT64_MAX, lastTime_ = 0;
    std::optional<Error> failure_;
    bool finished_ = false;
    void* zstd_ = nullptr; // ZSTD_CCtx*, kept for the writer's life to avoid reallocating
};

} // namespace replica::recordings::mcap
