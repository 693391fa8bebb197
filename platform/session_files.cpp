// Session files: recovery, retention, rotation.
#include <algorithm>
#include <array>
#include <ctime>
#include <fstream>

#include <fmt/format.h>

#include <platform/logging.h>
#include <platform/session_files.h>
#include <recordings/recover.h>

namespace replica::platform {
namespace fs = std::filesystem;

namespace {

std::vector<fs::path> recordingsIn(const fs::path& dir)
{
    std::vector<fs::path> out;
    std::error_code ec;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
        if (it->is_regular_file(ec) && it->path().extension() == ".mcap") {
            out.push_back(it->path());
        }
    }
    return out;
}

} // namespace

bool recordingFinished(const fs::path& file)
{
    static constexpr std::array<char, 8> kMagic{'\x89', 'M', 'C', 'A', 'P', '0', '\r', '\n'};
    std::ifstream in(file, std::ios::binary | std::ios::ate);
    if (!in) {
        return false;
    }
    const auto size = static_cast<std::streamoff>(in.tellg());
    if (size < 16) {
        return false;
    }
    std::array<char, 8> tail{};
    in.seekg(size - 8);
    in.read(tail.data(), tail.size());
    return in.gcount() == 8 && tail == kMagic;
}

std::vector<fs::path> recoverUnfinished(const fs::path& dir)
{
    auto log = logger("rec");
    std::vector<fs::path> recovered;
    for (const auto& f : recordingsIn(dir)) {
        if (recordingFinished(f)) {
            continue;
        }
        fs::path tmp = f;
        tmp += ".recovering";
        auto r = recordings::recoverRecording(f, tmp, recordings::ExistingOutput::Replace);
        std::error_code ec;
        if (!r) {
            fs::remove(tmp, ec);
            fs::path bad = f;
            bad += ".unrecoverable";
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
    for (const auto& f : recordingsIn(dir)) {
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
        if (!keep.empty() && e.path == keep) {
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
    for (int n = 1; fs::exists(p, ec); ++n) {
        p = dir / fmt::format("{}-{}.mcap", stamp.data(), n);
    }
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
