// Bounded, non-blocking reads of sysfs attributes.
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>

#include <fcntl.h>
#include <fmt/format.h>
#include <poll.h>
#include <unistd.h>

#include <hal/sysfs_file.h>

namespace replica::hal {

Expected<std::string>
readSysfsFile(const std::filesystem::path& file, std::size_t maxBytes, SysfsRead what)
{
    // O_NONBLOCK: opening a FIFO does not wait for a writer, reading one does not wait for data;
    // poll() bounds the wait for anything else that does not answer at once, all reads together.
    const int fd = ::open(file.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
    if (fd < 0) {
        return makeError(ErrorCode::NotFound, fmt::format("{}: cannot be read ({})", file.string(),
                                                          std::strerror(errno)));
    }
    const auto deadline =
            std::chrono::steady_clock::now() + std::chrono::milliseconds(kSysfsWaitMs);
    std::string text;
    int err = 0;
    for (;;) {
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
                deadline - std::chrono::steady_clock::now());
        pollfd p{fd, POLLIN, 0};
        const int ready = ::poll(&p, 1, static_cast<int>(std::max<long>(0, left.count())));
        if (ready < 0 && errno == EINTR) {
            continue;
        }
        if (ready <= 0) {
            err = ready == 0 ? EAGAIN : errno;
            break;
        }
        const std::size_t have = text.size();
        text.resize(maxBytes + 1); // one more than allowed: to know there is more
        const ssize_t got = ::read(fd, text.data() + have, text.size() - have);
        err = got < 0 ? errno : 0;
        text.resize(have + static_cast<std::size_t>(std::max<ssize_t>(got, 0)));
        if (got < 0 && err == EINTR) {
            continue;
        }
        if (got <= 0 || text.size() > maxBytes ||
            (what == SysfsRead::FirstLine && text.find('\n', have) != std::string::npos)) {
            break;
        }
    }
    ::close(fd);
    if (err == EAGAIN) {
        return makeError(ErrorCode::DeviceFailure,
                         fmt::format("{}: no answer within {} ms (a sysfs attribute answers at "
                                     "once: is it a FIFO or a device?)",
                                     file.string(), kSysfsWaitMs));
    }
    if (err != 0) {
        return makeError(ErrorCode::DeviceFailure,
                         fmt::format("{}: cannot be read ({})", file.string(), std::strerror(err)));
    }
    if (what == SysfsRead::FirstLine) {
        if (const auto nl = text.find('\n'); nl != std::string::npos) {
            text.resize(nl);
        }
    }
    if (text.size() > maxBytes) {
        return makeError(ErrorCode::DeviceFailure,
                         fmt::format("{}: more than {} bytes (a sysfs attribute is a few: is it "
                                     "a device or a regular file?)",
                                     file.string(), maxBytes));
    }
    return text;
}

} // namespace replica::hal
