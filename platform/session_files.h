// The kiosk's folder of session recordings: a fresh name per session, a crashed session recovered
// in place at start, a new file when one grows past its size or age, and the oldest deleted
// beyond a total size. The folder is the kiosk's: one kiosk at a time (a lock file), and recovery
// and retention touch only the files the kiosk wrote (its name pattern, listed in the folder's
// register before each is created), never through a symbolic link, never one another process
// holds open (every recording being written holds a lock on its file). Works with any file names
// (std::filesystem, no shell).
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <pipeline/base/expected.h>
#include <recordings/recording.h>

namespace replica::platform {

// Whether the file ends with the MCAP magic, i.e. its writer closed it.
bool recordingFinished(const std::filesystem::path& file);

// The folder's lock (dir/.replica-kiosk.lock, flock), held for the process's life: a second
// kiosk on the folder is refused with one line naming the holder's pid.
class SessionFolderLock
{
public:
    static Expected<SessionFolderLock> acquire(const std::filesystem::path& dir);
    SessionFolderLock(SessionFolderLock&& other) noexcept;
    SessionFolderLock& operator=(SessionFolderLock&&) = delete;
    SessionFolderLock(const SessionFolderLock&) = delete;
    ~SessionFolderLock();

private:
    explicit SessionFolderLock(int fd) : fd_(fd) {}
    int fd_ = -1;
};

// The kiosk's own files in dir: named as newSessionPath names them (YYYYmmddTHHMMSSZ[-N].mcap,
// or that with .unrecoverable) and listed in the folder's register (dir/.replica-sessions), each
// a regular file (not a symbolic link).
std::vector<std::filesystem::path> kioskFiles(const std::filesystem::path& dir);

// Whether another open file description holds a lock on the file (a recording being written:
// the writer locks its file).
bool heldOpenElsewhere(const std::filesystem::path& file);

// Free bytes where 'dir' is (statvfs); a test may pass its own.
using FreeSpace = std::function<std::uint64_t(const std::filesystem::path&)>;
std::uint64_t freeBytes(const std::filesystem::path& dir);

// Rebuilds every unfinished kiosk file in dir in place ('replica recover' into a temporary file,
// then renamed over the original); returns the files recovered. One without room for its copy
// (less free space than its size) is left as it is and tried again at the next start; one
// nothing can be recovered from is renamed to NAME.unrecoverable so that it is not tried again.
// A file another process holds open is not touched. What an earlier recovery cut short by a stop
// or a kill left beside a kiosk file (NAME.recovering and recover's temporary file) is deleted
// first.
std::vector<std::filesystem::path> recoverUnfinished(const std::filesystem::path& dir,
                                                     const FreeSpace& free = freeBytes);

// Deletes the oldest kiosk files (by modification time, then name) until the total of all of
// them (unfinished and .unrecoverable ones included) is at most keepBytes; never 'keep', never
// an unfinished one (it waits for its recovery), never one another process holds open. Returns
// the files deleted.
std::vector<std::filesystem::path> enforceRetention(const std::filesystem::path& dir,
                                                    std::uint64_t keepBytes,
                                                    const std::filesystem::path& keep = {});

// dir/YYYYmmddTHHMMSSZ.mcap (UTC), with -N appended when that name is taken, listed in the
// folder's register before it is returned (so that a crash between the two leaves nothing
// unlisted).
std::filesystem::path newSessionPath(const std::filesystem::path& dir);

struct RotationPolicy {
    std::uint64_t rotateBytes = 1ull << 30;
    std::chrono::seconds rotateAge{3600};
    std::uint64_t keepBytes = 20ull << 30;
};

// Owns the session's current writer and opens the next one when the policy says.
class SessionRecorder
{
public:
    using Factory = std::function<Expected<std::unique_ptr<recordings::RecordingWriter>>(
            const std::filesystem::path&)>;
    SessionRecorder(std::filesystem::path dir, RotationPolicy policy, Factory factory)
        : dir_(std::move(dir)), policy_(policy), factory_(std::move(factory))
    {}

    // Opens the first file (after retention).
    Expected<void> open();
    recordings::RecordingWriter* current() const { return writer_.get(); }
    const std::filesystem::path& currentPath() const { return path_; }
    // Called after each frame: checks size and age (at most once a second), and when either is
    // reached closes the file, opens a new one and applies retention. Returns the writer to use.
    recordings::RecordingWriter* afterFrame();
    Expected<void> close();
    std::uint64_t rotations() const { return rotations_; }

private:
    Expected<void> openNext();

    std::filesystem::path dir_;
    RotationPolicy policy_;
    Factory factory_;
    std::unique_ptr<recordings::RecordingWriter> writer_;
    std::unique_ptr<recordings::RecordingWriter> previous_; // closed after the loop switched
    std::filesystem::path path_;
    std::chrono::steady_clock::time_point opened_{};
    std::chrono::steady_clock::time_point lastCheck_{};
    std::uint64_t rotations_ = 0;
};

} // namespace replica::platform
