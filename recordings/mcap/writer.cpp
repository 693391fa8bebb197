// The MCAP file writer: chunk assembly, zstd compression, CRCs, indexes, summary and footer.
#include <algorithm>
#include <cerrno>
#include <cstring>

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zstd.h>

#include <recordings/mcap/crc.h>
#include <recordings/mcap/writer.h>

namespace replica::recordings::mcap {
namespace {

ZSTD_CCtx* cctx(void* p)
{
    return static_cast<ZSTD_CCtx*>(p);
}

} // namespace

FileWriter::FileWriter(int fd, std::filesystem::path path) : fd_(fd), path_(std::move(path))
{
    zstd_ = ZSTD_createCCtx();
    ZSTD_CCtx_setParameter(cctx(zstd_), ZSTD_c_compressionLevel, 3);
    ZSTD_CCtx_setParameter(cctx(zstd_), ZSTD_c_checksumFlag, 1);
}

FileWriter::~FileWriter()
{
    ZSTD_freeCCtx(cctx(zstd_));
    if (fd_ >= 0) {
        ::close(fd_);
    }
}

Expected<std::unique_ptr<FileWriter>>
FileWriter::create(const std::filesystem::path& path, const std::string& library, bool overwrite)
{
    // Never through a symbolic link (O_NOFOLLOW), and truncated only once it is known to be a
    // regular file we may overwrite.
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_NOFOLLOW | O_CLOEXEC, 0644);
    if (fd < 0) {
        const int err = errno;
        if (err == ELOOP) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("{}: is a symbolic link; a recording is never written "
                                         "through one: name the file itself",
                                         path.string()));
        }
        return makeError(
                ErrorCode::Io,
                fmt::format("{}: cannot create recording: {}{}", path.string(), std::strerror(err),
                            err == EACCES || err == EROFS ? " (choose a writable directory)" : ""));
    }
    // Locked while it is written: the kiosk's recovery and retention leave a locked file alone
    // (platform/session_files.h), and two writers never share one file.
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
        ::close(fd);
        return makeError(
                ErrorCode::InvalidArgument,
                fmt::format("{}: another process is writing it; name another file", path.string()));
    }
    struct stat st {
    };
    if (::fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && st.st_size > 0) {
        if (!overwrite) {
            ::close(fd);
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("{}: already exists; pass --force to overwrite it, or "
                                         "name a new file",
                                         path.string()));
        }
        if (::ftruncate(fd, 0) != 0) {
            const int err = errno;
            ::close(fd);
            return makeError(ErrorCode::Io, fmt::format("{}: cannot truncate: {}", path.string(),
                                                        std::strerror(err)));
        }
    }
    std::unique_ptr<FileWriter> w(new FileWriter(fd, path));
    ByteWriter header;
    header.str("");
    header.str(library);
    std::string start(kMagic);
    start += record(Op::Header, header.bytes());
    if (auto ok = w->put(start); !ok) {
        return tl::unexpected(ok.error());
    }
    return w;
}

Expected<void> FileWriter::fail(std::string what, int err)
{
    if (!failure_) {
        std::string hint;
        if (err == ENOSPC) {
            hint = " (disk full: free space; what was written so far is kept)";
        } else if (err == EFBIG) {
            hint = " (file size limit reached; what was written so far is kept)";
        }
        failure_ = Error{ErrorCode::Io, err ? fmt::format("{}: {}: {}{}", path_.string(), what,
                                                          std::strerror(err), hint)
                                            : fmt::format("{}: {}{}", path_.string(), what, hint)};
    }
    return tl::unexpected(*failure_);
}

Expected<void> FileWriter::put(std::string_view bytes)
{
    if (failure_) {
        return tl::unexpected(*failure_);
    }
    if (!finished_) {
        dataCrc_ = crc32(dataCrc_, bytes);
    }
    while (!bytes.empty()) {
        const ssize_t n = ::write(fd_, bytes.data(), bytes.size());
        if (n < 0 && errno == EINTR) {
            continue;
        }
        if (n <= 0) {
            return fail("writing the recording failed", n < 0 ? errno : ENOSPC);
        }
        bytes.remove_prefix(static_cast<std::size_t>(n));
        offset_ += static_cast<std::uint64_t>(n);
    }
    return {};
}

void FileWriter::addSchema(const Schema& s)
{
    if (std::find(schemas_.begin(), schemas_.end(), s) == schemas_.end()) {
        schemas_.push_back(s);
    }
    chunk_ += encodeSchema(s);
}

void FileWriter::addChannel(const Channel& c)
{
    if (std::find(channels_.begin(), channels_.end(), c) == channels_.end()) {
        channels_.push_back(c);
    }
    chunk_ += encodeChannel(c);
}

void FileWriter::addMessage(const Message& m)
{
    if (!chunkHasMessages_) {
        chunkStart_ = chunkEnd_ = m.logTime;
        chunkHasMessages_ = true;
    }
    chunkStart_ = std::min(chunkStart_, m.logTime);
    chunkEnd_ = std::max(chunkEnd_, m.logTime);
    chunkMessages_[m.channelId].emplace_back(m.logTime, chunk_.size());
    chunk_ += encodeMessage(m);
    ++channelCounts_[m.channelId];
    ++messageCount_;
    firstTime_ = std::min(firstTime_, m.logTime);
    lastTime_ = std::max(lastTime_, m.logTime);
}

Expected<void> FileWriter::addMetadata(const Metadata& m)
{
    const std::string rec = encodeMetadata(m);
    const std::uint64_t at = offset_;
    if (auto ok = put(rec); !ok) {
        return ok;
    }
    metadataIndexes_.push_back({at, rec.size(), m.name});
    return {};
}

Expected<void> FileWriter::closeChunk(bool sync)
{
    if (failure_) {
        return tl::unexpected(*failure_);
    }
    if (chunk_.empty()) {
        return {};
    }
    std::string compressed(ZSTD_compressBound(chunk_.size()), '\0');
    const std::size_t csize = ZSTD_compress2(cctx(zstd_), compressed.data(), compressed.size(),
                                             chunk_.data(), chunk_.size());
    if (ZSTD_isError(csize)) {
        return fail(fmt::format("compressing a chunk failed ({})", ZSTD_getErrorName(csize)), 0);
    }
    compressed.resize(csize);
    ByteWriter c;
    c.u64(chunkHasMessages_ ? chunkStart_ : 0);
    c.u64(chunkHasMessages_ ? chunkEnd_ : 0);
    c.u64(chunk_.size());
    c.u32(crc32(0, chunk_));
    c.str("zstd");
    c.u64(compressed.size());
    c.raw(compressed);
    ChunkIndex index;
    index.startTime = chunkHasMessages_ ? chunkStart_ : 0;
    index.endTime = chunkHasMessages_ ? chunkEnd_ : 0;
    index.offset = offset_;
    std::string out = record(Op::Chunk, c.bytes());
    index.length = out.size();
    index.compressedSize = compressed.size();
    index.uncompressedSize = chunk_.size();
    for (const auto& [channel, entries] : chunkMessages_) {
        ByteWriter array;
        for (const auto& [time, at] : entries) {
            array.u64(time);
            array.u64(at);
        }
        ByteWriter mi;
        mi.u16(channel);
        mi.str(array.bytes());
        index.indexOffsets[channel] = offset_ + out.size();
        const std::string rec = record(Op::MessageIndex, mi.bytes());
        index.indexLength += rec.size();
        out += rec;
    }
    chunk_.clear();
    chunkMessages_.clear();
    chunkHasMessages_ = false;
    if (auto ok = put(out); !ok) {
        return ok;
    }
    chunkIndexes_.push_back(std::move(index));
    if (sync) {
        if (::fdatasync(fd_) != 0) {
            return fail("syncing the recording to disk failed", errno);
        }
        return checkNotDeleted();
    }
    return {};
}

Expected<void> FileWriter::checkNotDeleted()
{
    // Writes to an unlinked file succeed and vanish with it: say so instead of recording into
    // nothing.
    struct stat st {
    };
    if (::fstat(fd_, &st) == 0 && st.st_nlink == 0) {
        return fail("the recording file was deleted while recording; nothing more is written", 0);
    }
    return {};
}

// The chunk index records, one per chunk written.
std::string FileWriter::chunkIndexRecords() const
{
    std::string g;
    for (const auto& ci : chunkIndexes_) {
        ByteWriter map;
        for (const auto& [channel, at] : ci.indexOffsets) {
            map.u16(channel);
            map.u64(at);
        }
        ByteWriter w;
        w.u64(ci.startTime);
        w.u64(ci.endTime);
        w.u64(ci.offset);
        w.u64(ci.length);
        w.str(map.bytes());
        w.u64(ci.indexLength);
        w.str("zstd");
        w.u64(ci.compressedSize);
        w.u64(ci.uncompressedSize);
        g += record(Op::ChunkIndex, w.bytes());
    }
    return g;
}

// The statistics record: message, schema, channel, metadata and chunk counts, the time span, and
// the messages per channel.
std::string FileWriter::statisticsRecord() const
{
    ByteWriter counts;
    for (const auto& [channel, n] : channelCounts_) {
        counts.u16(channel);
        counts.u64(n);
    }
    ByteWriter w;
    w.u64(messageCount_);
    w.u16(static_cast<std::uint16_t>(schemas_.size()));
    w.u32(static_cast<std::uint32_t>(channels_.size()));
    w.u32(0);
    w.u32(static_cast<std::uint32_t>(metadataIndexes_.size()));
    w.u32(static_cast<std::uint32_t>(chunkIndexes_.size()));
    w.u64(messageCount_ ? firstTime_ : 0);
    w.u64(messageCount_ ? lastTime_ : 0);
    w.str(counts.bytes());
    return record(Op::Statistics, w.bytes());
}

// The summary section from 'summaryStart' to the end of the file: schemas, channels, chunk and
// metadata indexes and statistics, each group's offset, the footer, the summary's CRC and the
// closing magic.
std::string FileWriter::summarySection(std::uint64_t summaryStart) const
{
    std::string summary;
    struct Group {
        Op op;
        std::uint64_t start, length;
    };
    std::vector<Group> groups;
    auto group = [&](Op op, const std::string& bytes) {
        if (!bytes.empty()) {
            groups.push_back({op, summaryStart + summary.size(), bytes.size()});
            summary += bytes;
        }
    };
    std::string g;
    for (const auto& s : schemas_) {
        g += encodeSchema(s);
    }
    group(Op::Schema, g);
    g.clear();
    for (const auto& c : channels_) {
        g += encodeChannel(c);
    }
    group(Op::Channel, g);
    group(Op::ChunkIndex, chunkIndexRecords());
    g.clear();
    for (const auto& mi : metadataIndexes_) {
        ByteWriter w;
        w.u64(mi.offset);
        w.u64(mi.length);
        w.str(mi.name);
        g += record(Op::MetadataIndex, w.bytes());
    }
    group(Op::MetadataIndex, g);
    group(Op::Statistics, statisticsRecord());
    const std::uint64_t offsetsStart = summaryStart + summary.size();
    for (const auto& gr : groups) {
        ByteWriter w;
        w.u8(static_cast<std::uint8_t>(gr.op));
        w.u64(gr.start);
        w.u64(gr.length);
        summary += record(Op::SummaryOffset, w.bytes());
    }
    ByteWriter footer;
    footer.u8(static_cast<std::uint8_t>(Op::Footer));
    footer.u64(20);
    footer.u64(summaryStart);
    footer.u64(offsetsStart);
    summary += footer.bytes();
    const std::uint32_t summaryCrc = crc32(0, summary);
    ByteWriter tail;
    tail.u32(summaryCrc);
    tail.raw(kMagic);
    summary += tail.bytes();
    return summary;
}

Expected<void> FileWriter::finish()
{
    if (finished_) {
        return failure_ ? Expected<void>(tl::unexpected(*failure_)) : Expected<void>{};
    }
    if (auto ok = closeChunk(false); !ok) {
        finished_ = true;
        return ok;
    }
    if (auto ok = checkNotDeleted(); !ok) {
        finished_ = true;
        return ok;
    }
    ByteWriter dataEnd;
    dataEnd.u32(dataCrc_);
    if (auto ok = put(record(Op::DataEnd, dataEnd.bytes())); !ok) {
        finished_ = true;
        return ok;
    }
    finished_ = true;
    const std::string summary = summarySection(offset_);
    if (auto ok = put(summary); !ok) {
        return ok;
    }
    if (::fsync(fd_) != 0) {
        return fail("syncing the recording to disk failed", errno);
    }
    if (::close(fd_) != 0) {
        fd_ = -1;
        return fail("closing the recording failed", errno);
    }
    fd_ = -1;
    return {};
}

} // namespace replica::recordings::mcap
