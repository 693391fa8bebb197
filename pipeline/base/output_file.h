// Writing a file that a person named (an output option): the one way every command writes one.
// Never through a symbolic link, never into a FIFO, device or directory; whole or not at all (an
// exclusive temporary file beside it, written, fsynced, then renamed over the name); a write that
// fails (a full disk) an error naming the file, never a short file and exit 0. The counterpart of
// input_file.h.
#pragma once

#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <pipeline/base/expected.h>
#include <pipeline/base/input_file.h>

namespace replica {

inline Expected<void>
writeOutputFile(const std::filesystem::path& path, std::string_view bytes, std::string_view what)
{
    const std::string name = path.string();
    struct stat st {
    };
    if (::lstat(path.c_str(), &st) == 0) {
        if (S_ISLNK(st.st_mode)) {
            return makeError(
                    ErrorCode::InvalidArgument,
                    fmt::format("{}: is a symbolic link; the {} is written to a file of that "
                                "name, never through a link: name the file itself",
                                name, what));
        }
        if (!S_ISREG(st.st_mode)) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("{}: is {}, not a {} file; name a regular file or a new "
                                         "one",
                                         name, input_file_detail::kindOf(st.st_mode), what));
        }
    }
    static std::atomic<unsigned> counter{0};
    const std::filesystem::path dir = path.has_parent_path() ? path.parent_path() : ".";
    const std::filesystem::path tmp =
            dir / fmt::format(".{}.{}-{}.tmp", path.filename().string(), ::getpid(), counter++);
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (fd < 0) {
        return makeError(ErrorCode::Io, fmt::format("{}: cannot write the {}: {}", name, what,
                                                    std::strerror(errno)));
    }
    auto failed = [&](const char* doing) -> Expected<void> {
        const int err = errno;
        ::close(fd);
        ::unlink(tmp.c_str());
        return makeError(ErrorCode::Io, fmt::format("{}: {} the {} failed: {}; nothing written",
                                                    name, doing, what, std::strerror(err)));
    };
    std::size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0 && errno == EINTR) {
            continue;
        }
        if (n <= 0) {
            if (n == 0) {
                errno = EIO;
            }
            return failed("writing");
        }
        done += static_cast<std::size_t>(n);
    }
    if (::fsync(fd) != 0) {
        return failed("syncing");
    }
    if (::close(fd) != 0) {
        const int err = errno;
        ::unlink(tmp.c_str());
        return makeError(ErrorCode::Io,
                         fmt::format("{}: closing the {} failed: {}; nothing written", name, what,
                                     std::strerror(err)));
    }
    if (::rename(tmp.c_str(), path.c_str()) != 0) {
        const int err = errno;
        ::unlink(tmp.c_str());
        return makeError(ErrorCode::Io, fmt::format("{}: cannot write the {}: {}", name, what,
                                                    std::strerror(err)));
    }
    return {};
}

} // namespace replica
