// Session files: recovery, retention, rotation.
#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <ctime>
#include <regex>
#include <set>
#include <sstream>

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/file.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <pipeline/base/input_file_parts.h>
#include <platform/logging.h>
#include <platform/session_files.h>
#include <recordings/recover.h>

namespace replica::platform {
namespace fs = std::filesystem;

namespace {

constexpr const char* kLockName = ".replica-kiosk.lock";
constexpr const char* kRegisterName = ".replica-sessions";
constexpr const char* kUnrecoverable = ".unrecoverable";

// The names newSessionPath gives (and their .unrecoverable).
bool sessionName(const std::string& name)
{
    static const std::regex pattern(R"(\d{8}T\d{6}Z(-\d+)?\.mcap(\.unrecoverable)?)");
    return std::regex_match(name, pattern);
}

// The file's bytes, never through a symbolic link; empty when it cannot be read.
std::string readNoFollow(const fs::path& file)
{
    const int fd = ::open(file.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
    if (fd < 0) {
        return {};
    }
    std::string text;
    std::array<char, 4096> buf{};
    for (ssize_t n = 0; (n = ::read(fd, buf.data(), buf.size())) > 0;) {
        text.append(buf.data(), static_cast<std::size_t>(n));
    }
    ::close(fd);
    return text;
}

std::set<std::string> registered(const fs::path& dir)
{
    std::set<std::string> names;
    std::istringstream in(readNoFollow(dir / kRegisterName));
    for (std::string line; std::getline(in, line);) {
        names.insert(line);
    }
    return names;
}

// Adds a session file's name to the folder's register, on disk before the file exists.
void registerName(const fs::path& dir, const std::string& name)
{
    const int fd = ::open((dir / kRegisterName).c_str(),
                          O_WRONLY | O_APPEND | O_CREAT | O_NOFOLLOW | O_CLOEXEC, 0640);
    if (fd < 0) {
        logger("rec")->warn("{}: cannot register the session file {}: {}; retention and "
                            "recovery will leave it alone",
                            (dir / kRegisterName).string(), name, std::strerror(errno));
        return;
    }
    const std::string line = name + "\n";
    const bool ok = ::write(fd, line.data(), line.size()) == static_cast<ssize_t>(line.size());
    (void)::fsync(fd);
    ::close(fd);
    if (!ok) {
        logger("rec")->warn("{}: could not register {}", (dir / kRegisterName).string(), name);
    }
}

} // namespace

std::vector<fs::path> kioskFiles(const fs::path& dir)
{
    const auto mine = registered(dir);
    std::vector<fs::path> out;
    std::error_code ec;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
        std::string name = it->path().filename().string();
        if (!sessionName(name) || it->symlink_status(ec).type() != fs::file_type::regular) {
            continue;
        }
        if (name.ends_with(kUnrecoverable)) {
            name.resize(name.size() - std::strlen(kUnrecoverable));
        }
        if (mine.contains(name)) {
            out.push_back(it->path());
        }
    }
    return out;
}

bool heldOpenElsewhere(const fs::path& file)
{
    const int fd = ::open(file.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK);
    if (fd < 0) {
        return false;
    }
    const bool held = ::flock(fd, LOCK_EX | LOCK_NB) != 0 && errno == EWOULDBLOCK;
    ::close(fd); // releases the probe's own lock
    return held;
}

std::uint64_t freeBytes(const fs::path& dir)
{
    struct statvfs st {
    };
    if (::statvfs(dir.c_str(), &st) != 0) {
        return 0;
    }
    return static_cast<std::uint64_t>(st.f_bavail) * static_cast<std::uint64_t>(st.f_frsize);
}

Expected<SessionFolderLock> SessionFolderLock::acquire(const fs::path& dir)
{
    std::error_code ec;
    fs::create_directories(dir, ec);
    const fs::path path = dir / kLockName;
    const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_NOFOLLOW | O_CLOEXEC, 0640);
    if (fd < 0) {
        return makeError(ErrorCode::Io, fmt::format("{}: cannot open the sessions folder's lock: "
                                                    "{}",
                                                    path.string(), std::strerror(errno)));
    }
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
        ::close(fd);
        std::string pid = readNoFollow(path);
        pid.erase(std::remove_if(pid.begin(), pid.end(), [](char c) { return c < '0' || c > '9'; }),
                  pid.end());
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: the sessions folder is in use by another kiosk (pid {}); "
                                     "stop it first ('systemctl stop replica'), or give this one "
                                     "another recording.directory",
                                     dir.string(), pid.empty() ? "unknown" : pid));
    }
    const std::string pid = fmt::format("{}\n", ::getpid());
    if (::ftruncate(fd, 0) != 0 || ::write(fd, pid.data(), pid.size()) < 0) {
        logger("rec")->warn("{}: could not write this kiosk's pid", path.string());
    }
    return SessionFolderLock(fd);
}

SessionFolderLock::SessionFolderLock(SessionFolderLock&& other) noexcept : fd_(other.fd_)
{
    other.fd_ = -1;
}

SessionFolderLock::~SessionFolderLock()
{
    if (fd_ >= 0) {
        ::close(fd_);
    }
}

bool recordingFinished(const fs::path& file)
{
    static constexpr std::string_view kMagic{"\x89MCAP0\r\n", 8};
    // Opened once, without waiting, a regular file only (a FIFO in a session's place is not
    // finished, and is never waited for); only its last bytes read.
    const auto tail = readInputFileTail(file, 16, UINTMAX_MAX, "recording");
    return tail && tail->size() == 16 && std::string_view(*tail).substr(8) == kMagic;
}

// What a recovery cut short leaves beside a kiosk file NAME (a stop signal or a kill during
// start-up ends the process without unwinding): NAME.recovering, the finished copy not yet renamed
// back, and .NAME.recovering.recover-PID-HEX, recover's temporary file. Either may be as large as
// the session, and no other code looks at them, so they are deleted before recovery starts again
// (the original NAME is still there, and is recovered anew). Only for the kiosk's registered
// names, only regular files, and only under the folder's lock (this kiosk is the one recovering).
void removeInterruptedRecoveries(const fs::path& dir)
{
    static const std::regex temp(R"(\.(.+)\.recovering\.recover-\d+-[0-9a-f]{8})");
    const auto mine = registered(dir);
    std::error_code ec;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
        const std::string name = it->path().filename().string();
        std::smatch m;
        std::string owner;
        if (std::regex_match(name, m, temp)) {
            owner = m[1].str();
        } else if (name.ends_with(".recovering")) {
            owner = name.substr(0, name.size() - std::strlen(".recovering"));
        }
        std::error_code typeEc;
        if (owner.empty() || !mine.contains(owner) ||
            it->symlink_status(typeEc).type() != fs::file_type::regular ||
            heldOpenElsewhere(it->path())) {
            continue;
        }
        std::error_code rmEc;
        if (fs::remove(it->path(), rmEc)) {
            logger("rec")->warn("{}: left by a recovery that was cut short; deleted (the session "
                                "itself is recovered again)",
                                it->path().string());
        }
    }
}

std::vector<fs::path> recoverUnfinished(const fs::path& dir, const FreeSpace& free)
{
    auto log = logger("rec");
    std::vector<fs::path> recovered;
    removeInterruptedRecoveries(dir);
    for (const auto& f : kioskFiles(dir)) {
        if (f.extension() != ".mcap" || recordingFinished(f)) {
            continue;
        }
        if (heldOpenElsewhere(f)) {
            log->warn("{}: unfinished but being written by another process; left alone",
                      f.string());
            continue;
        }
        std::error_code ec;
        const auto bytes = fs::file_size(f, ec);
        if (const auto room = free(dir); !ec && room < bytes) {
            log->warn("{}: unfinished ({} bytes) and only {} bytes free to recover it into: left "
                      "as it is; recovered at a start when there is room",
                      f.string(), bytes, room);
            continue;
        }
        fs::path tmp = f;
        tmp += ".recovering";
        auto r = recordings::recoverRecording(f, tmp, recordings::ExistingOutput::Replace);
        if (!r) {
            fs::remove(tmp, ec);
            if (r.error().code == ErrorCode::Io) { // no room after all, or a write failed
                log->warn("{}: unfinished; recovering it failed ({}): left as it is, tried again "
                          "at the next start",
                          f.string(), r.error().message);
                continue;
            }
            fs::path bad = f;
            bad += kUnrecoverable;
            fs::rename(f, bad, ec);
            log->warn("{}: unfinished and not recoverable ({}); renamed to {}", f.string(),
                      r.error().message, bad.string());
            continue;
        }
        fs::rename(tmp, f, ec);
        if (ec) {
            log->warn("{}: recovered into {} but could not rename it back: {}", f.string(),
                      tmp.string(), ec.message());
            continue;
        }
        log->warn("{}: the previous session ended without closing it (power cut or crash); "
                  "recovered in place: {} messages kept, {} dropped",
                  f.string(), r->messagesKept, r->messagesDropped);
        recovered.push_back(f);
    }
    return recovered;
}

std::vector<fs::path>
enforceRetention(const fs::path& dir, std::uint64_t keepBytes, const fs::path& keep)
{
    struct Entry {
        fs::path path;
        fs::file_time_type time;
        std::uint64_t bytes;
    };
    std::vector<Entry> files;
    std::uint64_t total = 0;
    for (const auto& f : kioskFiles(dir)) {
        std::error_code ec;
        const auto bytes = fs::file_size(f, ec);
        const auto time = fs::last_write_time(f, ec);
        if (!ec) {
            files.push_back({f, time, bytes});
            total += bytes;
        }
    }
    std::sort(files.begin(), files.end(), [](const Entry& a, const Entry& b) {
        return a.time != b.time ? a.time < b.time : a.path < b.path;
    });
    std::vector<fs::path> deleted;
    for (const auto& e : files) {
        if (total <= keepBytes) {
            break;
        }
        // Not the file being written, not a session waiting for its recovery, not one another
        // process has open.
        const bool waiting = e.path.extension() == ".mcap" && !recordingFinished(e.path);
        if ((!keep.empty() && e.path == keep) || waiting || heldOpenElsewhere(e.path)) {
            continue;
        }
        std::error_code ec;
        if (fs::remove(e.path, ec)) {
            total -= e.bytes;
            deleted.push_back(e.path);
        }
    }
    if (!deleted.empty()) {
        logger("rec")->info("retention: deleted {} oldest sessions in {}; {} bytes remain "
                            "(limit {})",
                            deleted.size(), dir.string(), total, keepBytes);
    }
    return deleted;
}

fs::path newSessionPath(const fs::path& dir)
{
    const std::time_t now = std::time(nullptr);
    std::tm utc{};
    gmtime_r(&now, &utc);
    std::array<char, 32> stamp{};
    std::strftime(stamp.data(), stamp.size(), "%Y%m%dT%H%M%SZ", &utc);
    fs::path p = dir / (std::string(stamp.data()) + ".mcap");
    std::error_code ec;
    for (int n = 1; fs::exists(fs::symlink_status(p, ec)); ++n) {
        p = dir / fmt::format("{}-{}.mcap", stamp.data(), n);
    }
    registerName(dir, p.filename().string());
    return p;
}

Expected<void> SessionRecorder::open()
{
    std::error_code ec;
    fs::create_directories(dir_, ec);
    if (ec) {
        return makeError(ErrorCode::Io, fmt::format("{}: cannot create the recording folder: {}",
                                                    dir_.string(), ec.message()));
    }
    enforceRetention(dir_, policy_.keepBytes);
    return openNext();
}

Expected<void> SessionRecorder::openNext()
{
    path_ = newSessionPath(dir_);
    auto w = factory_(path_);
    if (!w) {
        return tl::unexpected(w.error());
    }
    previous_ = std::move(writer_);
    writer_ = std::move(*w);
    opened_ = std::chrono::steady_clock::now();
    lastCheck_ = opened_;
    logger("rec")->info("recording session to {}", path_.string());
    return {};
}

recordings::RecordingWriter* SessionRecorder::afterFrame()
{
    if (previous_) {
        // The loop has switched to the new writer: the old one can finish its file.
        if (auto ok = previous_->close(); !ok) {
            logger("rec")->warn("closing the previous session: {}", ok.error().message);
        }
        previous_.reset();
        enforceRetention(dir_, policy_.keepBytes, path_);
    }
    if (!writer_) {
        return nullptr;
    }
    const auto now = std::chrono::steady_clock::now();
    if (now - lastCheck_ < std::chrono::seconds(1)) {
        return writer_.get();
    }
    lastCheck_ = now;
    std::error_code ec;
    const auto bytes = fs::file_size(path_, ec);
    if ((!ec && bytes >= policy_.rotateBytes) || now - opened_ >= policy_.rotateAge) {
        const fs::path old = path_;
        if (auto ok = openNext(); !ok) {
            // A file the full disk left without even its header is no session: remove it.
            std::error_code rm;
            if (path_ != old && fs::file_size(path_, rm) < 16 && !rm) {
                fs::remove(path_, rm);
            }
            logger("rec")->error("{}; continuing in {}", ok.error().message, old.string());
            path_ = old;
            opened_ = now; // try again after another full age
            return writer_.get();
        }
        ++rotations_;
        logger("rec")->info("rotated {} ({} bytes) to {}", old.string(), ec ? 0 : bytes,
                            path_.string());
    }
    return writer_.get();
}

Expected<void> SessionRecorder::close()
{
    if (previous_) {
        (void)previous_->close();
        previous_.reset();
    }
    if (!writer_) {
        return {};
    }
    auto ok = writer_->close();
    return ok;
}

} // namespace replica::platform
