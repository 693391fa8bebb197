// The kiosk's folder of session recordings: a fresh name per session, a crashed session recovered
// in place at start, a new file when one grows past its size or age, and the oldest deleted
// beyond a total size. Works with any file names (std::filesystem, no shell).
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

// Rebuilds every unfinished *.mcap in dir in place ('replica recover' into a temporary file,
// then renamed over the original); returns the files recovered. Files nothing can be recovered
// from are renamed to NAME.unrecoverable so that they are not tried again at every start.
std::vector<std::filesystem::path> recoverUnfinished(const std::filesystem::path& dir);

// Deletes the oldest *.mcap (by modification time, then name) until their total is at most
// keepBytes; never 'keep'. Returns the files deleted.
std::vector<std::filesystem::path> enforceRetention(const std::filesystem::path& dir,
                                                    std::uint64_t keepBytes,
                                                    const std::filesystem::path& keep = {});

// dir/YYYYmmddTHHMMSSZ.mcap (UTC), with -N appended when that name is taken.
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
