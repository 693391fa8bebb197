// Reading only a file's end through the bounded reader (input_file.h; piece by piece:
// readInputFilePieces there), opened once, never held whole.
#pragma once

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>

#include <fmt/format.h>
#include <unistd.h>

#include <pipeline/base/expected.h>
#include <pipeline/base/input_file.h>

namespace replica {

// The last 'n' bytes of 'path' (all of it when shorter), checked as readInputFile does and opened
// once: for a reader that looks only at a file's end (is a recording closed?).
inline Expected<std::string> readInputFileTail(const std::filesystem::path& path,
                                               std::size_t n,
                                               std::uintmax_t maxBytes,
                                               std::string_view what)
{
    input_file_detail::Fd f;
    auto st = input_file_detail::openChecked(f, path, maxBytes, what);
    if (!st) {
        return tl::unexpected(st.error());
    }
    const auto size = static_cast<std::uintmax_t>(st->st_size);
    std::string tail(static_cast<std::size_t>(std::min<std::uintmax_t>(n, size)), '\0');
    std::size_t done = 0;
    while (done < tail.size()) {
        const ssize_t got = ::pread(f.fd, tail.data() + done, tail.size() - done,
                                    static_cast<off_t>(size - tail.size() + done));
        if (got < 0 && errno == EINTR) {
            continue;
        }
        if (got <= 0) {
            return makeError(ErrorCode::Io,
                             fmt::format("{}: cannot read {} ({})", path.string(), what,
                                         got < 0 ? std::strerror(errno) : "shorter than its size"));
        }
        done += static_cast<std::size_t>(got);
    }
    return tail;
}

} // namespace replica
