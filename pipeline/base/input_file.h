// Reading a file that a person or another file named: regular files only (not a directory, FIFO,
// device or /proc entry), a size limit checked before reading, and errors that name the file
// instead of exceptions (a symlink loop, a directory, /dev/zero). Also the check for a name
// taken from an input file before it becomes part of a path.
#pragma once

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <pipeline/base/expected.h>

namespace replica {

// Limits for the text formats Replica reads (JSON, CSV, profiles). The largest shipped file is
// well under 1 MiB; these leave room for measured data without letting /dev/zero or a 2 GB
// mistake near memory.
constexpr std::uintmax_t kMaxJsonBytes = 64u << 20;
constexpr std::uintmax_t kMaxCsvBytes = 64u << 20;
// Rows and fields of one CSV or CGATS table: a 64 MiB file of one-character rows would otherwise
// hold tens of millions of rows, each its own allocation. The largest shipped table has 733 rows
// and 100 fields.
constexpr std::size_t kMaxTableRows = 1u << 20;
constexpr std::size_t kMaxTableFields = 4096;
// The site file: a few kilobytes of TOML.
constexpr std::uintmax_t kMaxTomlBytes = 1u << 20;
// Images (EXR, PNG): file size, and pixels per side checked from the header before allocating.
constexpr std::uintmax_t kMaxImageBytes = 1024u << 20;
constexpr int kMaxImageSide = 16384;
// Pixels of one EXR in all (a few hundred bytes of header can declare 16384 x 16384, a GiB per
// float channel): 4096 x 4096, the largest booth 'booth build' makes; the shipped ones hold at most
// 110,592.
constexpr std::int64_t kMaxExrPixels = std::int64_t{4096} * 4096;

namespace input_file_detail {

inline std::string kindOf(mode_t mode)
{
    if (S_ISDIR(mode)) {
        return "a directory";
    }
    if (S_ISFIFO(mode)) {
        return "a FIFO";
    }
    if (S_ISCHR(mode) || S_ISBLK(mode)) {
        return "a device";
    }
    if (S_ISSOCK(mode)) {
        return "a socket";
    }
    return "not a regular file";
}

inline std::string sizeText(std::uintmax_t bytes)
{
    return bytes >= (1u << 20) && bytes % (1u << 20) == 0 ? fmt::format("{} MiB", bytes >> 20)
                                                          : fmt::format("{} bytes", bytes);
}

struct Fd {
    int fd = -1;
    ~Fd()
    {
        if (fd >= 0) {
            ::close(fd);
        }
    }
};

inline Expected<struct stat> openChecked(Fd& f,
                                         const std::filesystem::path& path,
                                         std::uintmax_t maxBytes,
                                         std::string_view what)
{
    // O_NONBLOCK: opening a FIFO must not wait for a writer; it is refused just below.
    f.fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
    if (f.fd < 0) {
        const int err = errno;
        return makeError(
                err == ENOENT ? ErrorCode::NotFound : ErrorCode::Io,
                fmt::format("{}: cannot open {} ({}){}", path.string(), what, std::strerror(err),
                            err == ELOOP ? "; a symbolic link loop: point it at a file" : ""));
    }
    struct stat st {
    };
    if (::fstat(f.fd, &st) != 0) {
        return makeError(ErrorCode::Io, fmt::format("{}: cannot stat {} ({})", path.string(), what,
                                                    std::strerror(errno)));
    }
    if (!S_ISREG(st.st_mode)) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: is {}, not a {} file; name a regular file", path.string(),
                                     kindOf(st.st_mode), what));
    }
    if (static_cast<std::uintmax_t>(st.st_size) > maxBytes) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: {} bytes, more than the {} a {} file may hold",
                                     path.string(), st.st_size, sizeText(maxBytes), what));
    }
    return st;
}

} // namespace input_file_detail

// Checks that 'path' is a regular file of at most maxBytes, for readers that open it themselves
// (OpenEXR, libpng). 'what' names the kind of file in the message ("scene manifest", "CSV").
inline Expected<void>
checkInputFile(const std::filesystem::path& path, std::uintmax_t maxBytes, std::string_view what)
{
    input_file_detail::Fd f;
    auto st = input_file_detail::openChecked(f, path, maxBytes, what);
    if (!st) {
        return tl::unexpected(st.error());
    }
    return {};
}

// 'path', checked as readInputFile does and opened once, read in pieces of at most 64 KiB given in
// order to 'piece' (a digest): nothing is held, and no other open can find something else at the
// name.
template <typename Piece>
Expected<void> readInputFilePieces(const std::filesystem::path& path,
                                   std::uintmax_t maxBytes,
                                   std::string_view what,
                                   Piece&& piece)
{
    input_file_detail::Fd f;
    auto st = input_file_detail::openChecked(f, path, maxBytes, what);
    if (!st) {
        return tl::unexpected(st.error());
    }
    char buf[65536];
    std::uintmax_t total = 0;
    for (;;) {
        const ssize_t got = ::read(f.fd, buf, sizeof buf);
        if (got < 0) {
            if (errno == EINTR) {
                continue;
            }
            return makeError(ErrorCode::Io, fmt::format("{}: cannot read {} ({})", path.string(),
                                                        what, std::strerror(errno)));
        }
        if (got == 0) {
            return {};
        }
        total += static_cast<std::uintmax_t>(got);
        if (total > maxBytes) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("{}: more than the {} a {} file may hold", path.string(),
                                         input_file_detail::sizeText(maxBytes), what));
        }
        piece(std::string_view(buf, static_cast<std::size_t>(got)));
    }
}

// The whole of 'path' as bytes, checked as above. Reads at most maxBytes + 1 whatever the size
// says (a /proc file claims 0 bytes).
inline Expected<std::string>
readInputFile(const std::filesystem::path& path, std::uintmax_t maxBytes, std::string_view what)
{
    std::string text;
    auto ok = readInputFilePieces(path, maxBytes, what,
                                  [&](std::string_view piece) { text.append(piece); });
    if (!ok) {
        return tl::unexpected(ok.error());
    }
    return text;
}

// Refuses a table (CSV: 'separator' ','; CGATS: ' ', fields separated by spaces or tabs) with more
// than kMaxTableRows lines or a line of more than kMaxTableFields fields, before it is split: one
// line naming 'source' (and the line), the limit and the value.
inline Expected<void>
checkTableLimits(std::string_view text, std::string_view source, char separator)
{
    std::size_t rows = 0;
    std::size_t fields = 0;
    std::size_t widest = 0;
    std::size_t widestRow = 0;
    bool inField = false;
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (c == '\n') {
            ++rows;
            fields = 0;
            inField = false;
        } else if (separator == ' ') {
            const bool blank = c == ' ' || c == '\t' || c == '\r';
            fields += !blank && !inField ? 1 : 0; // a field starts
            inField = !blank;
        } else {
            fields = std::max<std::size_t>(fields, 1) + (c == separator ? 1 : 0);
        }
        if (fields > widest) {
            widest = fields;
            widestRow = rows + 1;
        }
    }
    rows += !text.empty() && text.back() != '\n' ? 1 : 0;
    if (rows > kMaxTableRows) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: {} lines, more than the limit of {} for a table", source,
                                     rows, kMaxTableRows));
    }
    if (widest > kMaxTableFields) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}:{}: {} fields on one line, more than the limit of {} for "
                                     "a table",
                                     source, widestRow, widest, kMaxTableFields));
    }
    return {};
}

// A name read from an input file (a booth light's name, a luminance map's file name) that will
// become part of a path: letters, digits, '.', '_', '-' and ' ', not starting with '.', at most
// 128 characters; so never a separator, '..', or an absolute path.
inline Expected<void> checkPlainName(const std::string& name, const std::string& where)
{
    bool ok = !name.empty() && name.size() <= 128 && name.front() != '.';
    for (const char c : name) {
        ok = ok && ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '.' || c == '_' || c == '-' || c == ' ');
    }
    if (!ok) {
        std::string shown;
        for (const char c : name.substr(0, 64)) {
            shown += (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) ? '?' : c;
        }
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: '{}' cannot name a file: use letters, digits, '.', '_', "
                                     "'-' (not starting with '.', at most 128 characters)",
                                     where, shown));
    }
    return {};
}

} // namespace replica
