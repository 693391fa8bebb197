// What a Replica recording holds and the API to write and read one (MCAP on disk; see README.md).
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include <hal/device.h>
#include <hal/samples.h>
#include <pipeline/base/expected.h>
#include <recordings/device_kind.h>

namespace replica::recordings {

// Bumped whenever what is written changes; readers open every earlier version they know.
// 1: unchunked MCAP, JSON messages (recordings/samples/walk-v1.mcap).
// 2: zstd chunks with CRCs and message indexes, summary, JSON Schemas, /replica/recorder.
// 3: the lamp selector: /hal/lamp_selector (id 7), lamp_seq in frames, lamp_selector in the
// session.
// 4: what was shown, on standard Foxglove channels (ids 8-13): /replica/display_digest (XXH3-64 of
// every frame sent to the panel), /replica/thumbnail (foxglove.CompressedImage), /tf
// (foxglove.FrameTransforms), /replica/eye (foxglove.PoseInFrame), /replica/light (the decided
// light), /replica/log (foxglove.Log). Replay reads only the digests; the rest is for people.
// 5: raw in, processed out: /replica/raw/tracker (id 14: opentrack datagrams, HID input reports
// and descriptors) and /replica/raw/accel (id 15: IIO raw values, scale, offset, mounting) beside
// the processed samples; the reader attaches them to their samples by sequence number.
constexpr int kFormatVersion = 6;

// Limits on a recording, which is untrusted input (docs/recordings.md, 'Limits'): its file size,
// one message's size (a 2048-pixel spectrum is about 12 KiB of JSON), and a spectrum's pixels
// (the USB2000+ has 2048).
constexpr std::uint64_t kMaxRecordingBytes = 2ULL << 30;
constexpr std::size_t kMaxMessageBytes = 1u << 20;
constexpr std::size_t kMaxSpectrumCounts = 16384;

// For each rendered frame: its tick time and exactly which sample of each device it consumed (by
// the device's sequence number), so replay never has to guess timing.
struct FrameRecord {
    std::uint64_t frameIndex = 0;
    std::int64_t tickNs = 0;
    // Device kind -> sequence number of the sample consumed; absent: no sample yet (or, in
    // recordings made before the device kind, none recorded).
    std::map<const DeviceKindBase*, std::uint32_t> sequences;
    std::optional<std::uint32_t> sequence(const DeviceKindBase& kind) const
    {
        const auto it = sequences.find(&kind);
        return it != sequences.end() ? std::optional<std::uint32_t>(it->second) : std::nullopt;
    }
    void setSequence(const DeviceKindBase& kind, std::optional<std::uint32_t> seq)
    {
        if (seq) {
            sequences[&kind] = *seq;
        } else {
            sequences.erase(&kind);
        }
    }
};

// Format 4: a digest of the 8-bit frame that went to the panel (XXH3-64, seed 0).
struct DisplayDigestRecord {
    std::uint64_t frameIndex = 0;
    std::int64_t tickNs = 0;
    std::uint64_t rgba = 0;
};

// Format 4: a thumbnail of the displayed frame (PNG bytes), at session time tNs.
struct ThumbnailRecord {
    std::int64_t tNs = 0;
    std::uint64_t frameIndex = 0;
    std::vector<std::uint8_t> png;
};

// Format 4: where things were for a frame, as the renderer used them: the eye in the booth frame,
// the panel's tilt (about the booth's x axis; the "panel" frame is the booth frame so rotated) and
// the tracker's mount in the booth.
struct PosesRecord {
    std::int64_t tNs = 0;
    glm::dvec3 eyeBoothM{0.0};
    double tiltRad = 0.0;
    glm::dvec3 trackerBoothM{0.0}; // the tracker's origin (unrotated)
};

// Format 4: the light the appliance decided to render with, written when it changes.
struct LightRecord {
    std::int64_t tNs = 0;
    std::uint64_t frameIndex = 0;
    std::string mode;                // "lamp" or "direct-sensor"
    int lamp = -1;                   // booth lamp index, -1 in direct-sensor mode
    std::string name;                // the lamp's name, or "unknown"
    std::optional<double> cctK, duv; // of the light rendered with; none where CCT is undefined
    double distance = 0.0;           // classifier's shape distance to the nearest stored lamp
    std::string why;                 // one line: what decided it
};

// Format 4: one of the appliance's warnings or errors (foxglove.Log levels: 3 warning, 4 error,
// 5 fatal).
struct LogRecord {
    std::int64_t tNs = 0;
    int level = 3;
    std::string name; // the logger's area
    std::string message;
};

// The running appliance's error (platform/loop/error_probe.h): CIEDE2000 between the frame's XYZ
// and the exact reference at n random pixels of the surface, at frame frameIndex. Not replayed.
struct ErrorProbeRecord {
    std::int64_t tNs = 0;
    std::uint64_t frameIndex = 0;
    std::uint64_t n = 0;
    double meanDe00 = 0.0;
    double p95De00 = 0.0;
    double maxDe00 = 0.0;
    double budgetP95 = 1.0; // the error budget the probe is held to
    double cpuMs = 0.0;     // the probe's CPU time (reference and ΔE00, at idle priority)
};

// Describes the session: enough to re-create the renderer's inputs other than the samples.
struct SessionInfo {
    std::string softwareVersion; // "replica 0.1.0"
    std::string configJson;      // the resolved run configuration (size, rate, scene, ...), JSON
    std::string boothModel;      // booth model identifier
    std::string scene;           // scene identifier
    std::string displayProfile;  // display profile identifier
    std::int64_t wallClockStartNs = 0; // Unix time (ns) at session time 0, for viewers' dates
    // Device kind -> the source behind it. An optional kind without an entry (or with an empty
    // model) was not there: e.g. no lamp selector, or a recording older than it.
    std::map<const DeviceKindBase*, hal::DeviceInfo> devices;
    const hal::DeviceInfo& device(const DeviceKindBase& kind) const
    {
        static const hal::DeviceInfo kNone;
        const auto it = devices.find(&kind);
        return it != devices.end() ? it->second : kNone;
    }
};

struct Recording {
    int formatVersion = 0;
    SessionInfo session;
    // Each device kind's samples in time order (an AnySamples holding std::vector<Sample>, see
    // device_kind.h), in the order of the kinds read; the reader puts an entry for every kind it
    // knows, empty when the file has none.
    struct DeviceSamples {
        const DeviceKindBase* kind = nullptr;
        AnySamples samples;
    };
    std::vector<DeviceSamples> devices;
    std::vector<FrameRecord> frames;
    std::vector<DisplayDigestRecord> displayDigests; // format 4; empty when none were recorded
    std::vector<LightRecord> lights;                 // format 4: the decided light, on change
    // Format 4: thumbnails of what the panel showed, tNs the shown frame's tick (session time) and
    // frameIndex the frame of that tick (0 where no frame has it).
    std::vector<ThumbnailRecord> thumbnails;
    // Format 5: raw messages that found no use: their sample is not in the recording (dropped by
    // the recorder), or a HID report's descriptor is not (lost with a damaged chunk).
    std::uint64_t unmatchedRaw = 0;
    std::uint64_t droppedMessages = 0;   // what the writer recorded as dropped (queue full)
    std::uint64_t rejectedNonFinite = 0; // samples the writer refused: a value was NaN or infinite

    // The kind's samples (a kind the recording has no entry for gets an empty one).
    template <typename Sample>
    std::vector<Sample>& samples(const DeviceKind<Sample>& kind)
    {
        for (auto& d : devices) {
            if (d.kind == &kind) {
                return DeviceKind<Sample>::of(d.samples);
            }
        }
        devices.push_back({&kind, kind.emptySamples()});
        return DeviceKind<Sample>::of(devices.back().samples);
    }
    template <typename Sample>
    const std::vector<Sample>& samples(const DeviceKind<Sample>& kind) const
    {
        static const std::vector<Sample> kNone;
        const auto* s = samplesOf(kind);
        return s != nullptr ? DeviceKind<Sample>::of(*s) : kNone;
    }
    // The kind's samples; null when the recording has no entry for it.
    const AnySamples* samplesOf(const DeviceKindBase& kind) const
    {
        for (const auto& d : devices) {
            if (d.kind == &kind) {
                return &d.samples;
            }
        }
        return nullptr;
    }
    // How many samples of this kind the recording holds.
    std::size_t count(const DeviceKindBase& kind) const
    {
        const auto* s = samplesOf(kind);
        return s != nullptr ? kind.count(*s) : 0;
    }
};

struct WriterOptions {
    // The device kinds whose channels the file gets (the registry; a test adds its own).
    DeviceKinds kinds = deviceKinds();
    // The open chunk is closed, written and fdatasync'ed at most this long after its first
    // message: a power cut loses at most about this much.
    std::chrono::milliseconds flushInterval{500};
    std::size_t chunkBytes = 256 * 1024; // ...or once it holds this many uncompressed bytes
    std::size_t queueCapacity = 16384;   // samples waiting for the writer thread; beyond: dropped
    // Called once, from the writer thread, on the first I/O failure (disk full, file deleted, ...).
    // Recording stops there; what was written stays readable.
    std::function<void(const Error&)> onError;
    // A non-empty regular file at the path is overwritten; false refuses it ('replica run
    // --record' without --force). A symbolic link there is always refused.
    bool overwrite = true;
};

struct WriterStats {
    std::uint64_t messages = 0; // written into chunks
    std::uint64_t dropped = 0;  // queue full
    std::uint64_t rejected = 0; // NaN/infinite values
    std::uint64_t chunks = 0;
    std::uint64_t bytes = 0; // file bytes written so far
    bool failed = false;
};

// Appends samples and frame records to a recording. write() never blocks the caller: it puts the
// sample on a bounded queue that a writer thread drains (a full queue drops the sample and counts
// it on /replica/recorder). write() must be called from one thread at a time.
class RecordingWriter : public DeviceSink
{
public:
    // Creates (truncates) the file and writes, and syncs, the header, every schema and channel and
    // the session description, so that a file that exists is a readable recording.
    static Expected<std::unique_ptr<RecordingWriter>> create(const std::filesystem::path& path,
                                                             const SessionInfo& session,
                                                             WriterOptions options = {});
    virtual ~RecordingWriter() = default;

    // A device's sample (DeviceSink::writeDevice); a kind the writer was not created with is
    // counted as rejected.
    template <typename Sample>
    void write(const DeviceKind<Sample>& kind, const Sample& s)
    {
        writeDevice(kind, AnySample(s));
    }
    // A sample of the first registered kind of its type (deviceKinds()).
    template <typename Sample>
    void write(const Sample& s)
    {
        const auto* kind = kindOfType(deviceKinds(), typeid(Sample));
        if (kind != nullptr) {
            writeDevice(*kind, AnySample(s));
        }
    }
    virtual void write(const FrameRecord& f) = 0;
    virtual void write(const DisplayDigestRecord& d) = 0;
    virtual void write(const PosesRecord& p) = 0;
    virtual void write(const LightRecord& l) = 0;
    // Thread-safe, from any thread (a thumbnail encoder, a log sink): a second bounded queue,
    // dropped and counted when full, never blocking for long.
    virtual void write(const ThumbnailRecord& t) = 0;
    virtual void write(const LogRecord& l) = 0;
    virtual void write(const ErrorProbeRecord& e) = 0;
    // Flushes everything and writes the summary and footer. Safe to call once; the destructor calls
    // it.
    virtual Expected<void> close() = 0;
    // Thread-safe snapshot of what the writer has done so far.
    virtual WriterStats stats() const = 0;
    // The session's Unix time (ns) at session time 0 (SessionInfo::wallClockStartNs).
    virtual std::int64_t wallClockStartNs() const = 0;
};

// A format this build reads, or one line naming the recording saying it is newer (update replica).
Expected<void> checkFormatVersion(const std::string& name, int formatVersion);

// Reads a whole recording. Fails with a one-line reason (missing, empty, not a recording, damaged).
// 'kinds': the device kinds to read (the registry; a channel of no kind there is skipped).
Expected<Recording> readRecording(const std::filesystem::path& path,
                                  const DeviceKinds& kinds = deviceKinds());

// What a file holds and what is wrong with it, for 'replica inspect'.
struct ChannelReport {
    std::uint16_t id = 0;
    std::string topic, schemaName, messageEncoding;
    std::uint64_t messages = 0;
    std::uint64_t firstLogTime = 0, lastLogTime = 0;
};
struct FileReport {
    std::uint64_t fileBytes = 0;
    std::string library;
    std::vector<ChannelReport> channels; // by id
    std::uint64_t messages = 0, chunks = 0;
    bool indexed = false;            // has a summary (statistics, chunk indexes)
    std::vector<std::string> damage; // empty: the file is sound
    std::uint64_t damageCount = 0;
};
// Fails only when the file cannot be read at all; damage is reported in the result.
Expected<FileReport> inspectRecording(const std::filesystem::path& path);

} // namespace replica::recordings
