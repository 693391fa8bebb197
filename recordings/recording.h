// What a Replica recording holds and the API to write and read one (MCAP on disk; see README.md).
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <hal/device.h>
#include <hal/samples.h>
#include <pipeline/base/expected.h>

namespace replica::recordings {

// Bumped whenever what is written changes; readers open every earlier version they know.
constexpr int kFormatVersion = 1;

// For each rendered frame: its tick time and exactly which sample of each device it consumed (by
// the device's sequence number), so replay never has to guess timing. nullopt: no sample yet.
struct FrameRecord {
    std::uint64_t frameIndex = 0;
    std::int64_t tickNs = 0;
    std::optional<std::uint32_t> spectrumSequence;
    std::optional<std::uint32_t> poseSequence;
    std::optional<std::uint32_t> accelSequence;
};

// Describes the session: enough to re-create the renderer's inputs other than the samples.
struct SessionInfo {
    std::string softwareVersion; // "replica 0.1.0"
    std::string configJson;      // the resolved run configuration (size, rate, scene, ...), JSON
    std::string boothModel;      // booth model identifier
    std::string scene;           // scene identifier
    std::string displayProfile;  // display profile identifier
    std::int64_t wallClockStartNs = 0; // Unix time (ns) at session time 0, for viewers' dates
    hal::DeviceInfo spectrometer, tracker, accel;
};

struct Recording {
    int formatVersion = 0;
    SessionInfo session;
    std::vector<hal::SpectrumSample> spectra;
    std::vector<hal::PoseSample> poses;
    std::vector<hal::AccelSample> accel;
    std::vector<FrameRecord> frames;
    std::uint64_t droppedMessages = 0; // what the writer recorded as dropped (queue full)
};

// Appends samples and frame records to a recording. write() never blocks the caller for I/O.
class RecordingWriter
{
public:
    // Creates (truncates) the file and writes the header and session description.
    static Expected<std::unique_ptr<RecordingWriter>> create(const std::filesystem::path& path,
                                                             const SessionInfo& session);
    virtual ~RecordingWriter() = default;

    virtual void write(const hal::SpectrumSample& s) = 0;
    virtual void write(const hal::PoseSample& s) = 0;
    virtual void write(const hal::AccelSample& s) = 0;
    virtual void write(const FrameRecord& f) = 0;
    // Flushes everything and writes the summary and footer. Safe to call once; the destructor calls
    // it.
    virtual Expected<void> close() = 0;
};

// Reads a whole recording. Fails with a one-line reason (missing, empty, not a recording, damaged).
Expected<Recording> readRecording(const std::filesystem::path& path);

} // namespace replica::recordings
