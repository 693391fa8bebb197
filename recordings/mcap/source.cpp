// A recording's bytes from memory, or from a file through a bounded, forward-moving window.
#include <algorithm>
#include <cerrno>
#include <cstring>

#include <fmt/format.h>
#include <unistd.h>

#include <pipeline/base/input_file.h>
#include <recordings/mcap/crc.h>
#include <recordings/mcap/source.h>

namespace replica::recordings::mcap {
namespace {

// What a refill reads beyond the request: large enough that a scan's reads (and the moves of the
// window's kept tail) cost about one pass over the file.
constexpr std::uint64_t kReadAhead = 4ULL << 20;
// The CRC of a range is computed piece by piece through a buffer of this size.
constexpr std::size_t kCrcPiece = 1U << 20;

} // namespace

std::optional<std::uint32_t> MemorySource::crc(std::uint64_t from, std::uint64_t to)
{
    return crc32(0, f_.substr(static_cast<std::size_t>(from), static_cast<std::size_t>(to - from)));
}

Expected<std::unique_ptr<FileSource>>
FileSource::open(const std::filesystem::path& path, std::uint64_t maxBytes, std::string_view what)
{
    input_file_detail::Fd f;
    auto st = input_file_detail::openChecked(f, path, maxBytes, what);
    if (!st) {
        return tl::unexpected(st.error());
    }
    const int fd = f.fd;
    f.fd = -1; // now the source's
    return std::unique_ptr<FileSource>(
            new FileSource(fd, static_cast<std::uint64_t>(st->st_size), path.string()));
}

FileSource::FileSource(int fd, std::uint64_t size, std::string name)
    : fd_(fd), size_(size), name_(std::move(name))
{}

FileSource::~FileSource()
{
    if (fd_ >= 0) {
        ::close(fd_);
    }
}

bool FileSource::readAt(std::uint64_t at, char* into, std::size_t n)
{
    std::size_t done = 0;
    while (done < n) {
        const ssize_t got = ::pread(fd_, into + done, n - done, static_cast<off_t>(at + done));
        if (got < 0 && errno == EINTR) {
            continue;
        }
        if (got <= 0) {
            error_ = got < 0 ? fmt::format("{}: cannot read bytes {}..{}: {}", name_, at + done,
                                           at + n, std::strerror(errno))
                             : fmt::format("{}: ends at byte {}, not at the {} bytes it had when "
                                           "opened (changed while being read)",
                                           name_, at + done, size_);
            return false;
        }
        done += static_cast<std::size_t>(got);
    }
    return true;
}

std::optional<std::string_view> FileSource::bytes(std::uint64_t at, std::uint64_t n)
{
    if (!error_.empty() || at > size_ || n > size_ - at || n > kMaxRecordBytes) {
        if (error_.empty()) {
            error_ = fmt::format("{}: bytes {}..+{} asked for, beyond the file or the window (a "
                                 "bug)",
                                 name_, at, n);
        }
        return std::nullopt;
    }
    const std::uint64_t end = start_ + buf_.size();
    if (at >= start_ && at + n <= end) {
        return std::string_view(buf_).substr(static_cast<std::size_t>(at - start_),
                                             static_cast<std::size_t>(n));
    }
    if (at >= start_ && at <= end) {
        buf_.erase(0, static_cast<std::size_t>(at - start_)); // keep what is still ahead
    } else {
        buf_.clear();
    }
    start_ = at;
    const std::size_t have = buf_.size();
    // At least kReadAhead new bytes (or the rest of the file) each time: a scan asking for a little
    // more than the window holds, again and again, must not move the window for a few bytes.
    const auto want = static_cast<std::size_t>(std::min(size_ - at, n + kReadAhead));
    buf_.resize(want);
    if (!readAt(at + have, buf_.data() + have, want - have)) {
        buf_.clear();
        return std::nullopt;
    }
    peak_ = std::max(peak_, buf_.size());
    return std::string_view(buf_).substr(0, static_cast<std::size_t>(n));
}

std::optional<std::uint32_t> FileSource::crc(std::uint64_t from, std::uint64_t to)
{
    if (from > to || to > size_) {
        error_ = fmt::format("{}: the CRC of bytes {}..{} asked for, beyond the file (a bug)",
                             name_, from, to);
        return std::nullopt;
    }
    std::string piece(std::min<std::uint64_t>(kCrcPiece, to - from), '\0');
    std::uint32_t c = 0;
    for (std::uint64_t at = from; at < to;) {
        const auto n = static_cast<std::size_t>(std::min<std::uint64_t>(piece.size(), to - at));
        if (!readAt(at, piece.data(), n)) {
            return std::nullopt;
        }
        c = crc32(c, std::string_view(piece).substr(0, n));
        at += n;
    }
    return c;
}

} // namespace replica::recordings::mcap
