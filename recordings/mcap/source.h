// Where a scan reads a recording's bytes: a file held in memory, or a bounded window over an open
// file (recover), so that what the scan holds does not grow with the file.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include <pipeline/base/expected.h>

namespace replica::recordings::mcap {

// The most a scan asks for at once: one whole record it parses (a chunk, at most 16 MiB of
// records uncompressed and so a little more compressed, or a Metadata record). A record longer
// than this is damage; records the scan skips (attachments, indexes) are never read.
constexpr std::uint64_t kMaxRecordBytes = 17ULL << 20;

class Source
{
public:
    virtual ~Source() = default;
    virtual std::uint64_t size() const = 0;
    // Bytes [at, at + n), valid until the next call; nullopt when they cannot be read (error()
    // says why). at + n must be within size().
    virtual std::optional<std::string_view> bytes(std::uint64_t at, std::uint64_t n) = 0;
    // The CRC-32 of bytes [from, to), read on their own (a file: piece by piece, not held).
    virtual std::optional<std::uint32_t> crc(std::uint64_t from, std::uint64_t to) = 0;
    virtual std::string error() const { return {}; }
};

// A file already in memory (inspect, replay, tests).
class MemorySource final : public Source
{
public:
    explicit MemorySource(std::string_view file) : f_(file) {}
    std::uint64_t size() const override { return f_.size(); }
    std::optional<std::string_view> bytes(std::uint64_t at, std::uint64_t n) override
    {
        return f_.substr(static_cast<std::size_t>(at), static_cast<std::size_t>(n));
    }
    std::optional<std::uint32_t> crc(std::uint64_t from, std::uint64_t to) override;

private:
    std::string_view f_;
};

// A regular file read through a window of at most kMaxRecordBytes plus a read-ahead of 4 MiB: a
// scan moving forward reads each byte once; a request outside the window refills it.
class FileSource final : public Source
{
public:
    // Opens `path` as the bounded reader does (a regular file of at most maxBytes, opened
    // without waiting); the size is taken once, a file that shrinks later is a read error.
    static Expected<std::unique_ptr<FileSource>>
    open(const std::filesystem::path& path, std::uint64_t maxBytes, std::string_view what);
    ~FileSource() override;
    FileSource(const FileSource&) = delete;
    FileSource& operator=(const FileSource&) = delete;

    std::uint64_t size() const override { return size_; }
    std::optional<std::string_view> bytes(std::uint64_t at, std::uint64_t n) override;
    std::optional<std::uint32_t> crc(std::uint64_t from, std::uint64_t to) override;
    std::string error() const override { return error_; }
    // The most the window held at once (tests).
    std::size_t peakWindow() const { return peak_; }

private:
    FileSource(int fd, std::uint64_t size, std::string name);
    bool readAt(std::uint64_t at, char* into, std::size_t n);

    int fd_ = -1;
    std::uint64_t size_ = 0;
    std::string name_;
    std::string buf_; // bytes [start_, start_ + buf_.size()) of the file
    std::uint64_t start_ = 0;
    std::size_t peak_ = 0;
    std::string error_;
};

} // namespace replica::recordings::mcap
