// What the panel showed, into the recording (format 4): a digest of every displayed frame, a PNG
// thumbnail at a low rate (downscaled and encoded on a thread of its own, never in the frame's
// time; tagged with the display profile and its time, png_metadata.h), the eye, panel and tracker
// frames, the decided light when it changes, and the appliance's warnings and errors (those logged
// before the recorder was made included). None of it changes a frame: it reads the frame after it
// was rendered and handed to the output. One recorder serves a single --record file and a kiosk
// session's rotated files alike (setWriter).
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <pipeline/colour/xyz.h>
#include <pipeline/render/renderer.h>
#include <pipeline/scene/scene_state.h>
#include <platform/appliance.h>
#include <recordings/recording.h>

namespace replica::platform {

struct ShownOptions {
    bool displayDigests = true; // XXH3-64 of every displayed frame (/replica/display_digest)
    double thumbnailHz = 1.0;   // 0: no thumbnails
    int thumbnailWidth = 320;
    // Poses are written when they change, at most this often (session time).
    std::int64_t posePeriodNs = 100'000'000;
    bool log = true; // warnings and errors to /replica/log
};

struct ShownStats {
    std::uint64_t thumbnails = 0;        // encoded and handed to the writer
    std::uint64_t thumbnailBytes = 0;    // PNG bytes
    std::uint64_t thumbnailsSkipped = 0; // the encoder was still busy with the previous one
    double copyMsTotal = 0.0;            // frame thread: copying the frame for the encoder
    double encodeMsTotal = 0.0;          // encoder thread: downscale + PNG
    double digestMsTotal = 0.0;          // frame thread: hashing the display frame
    std::uint64_t digests = 0;
    std::uint64_t lightChanges = 0;
    std::uint64_t poses = 0;
};

class ShownRecorder
{
public:
    ShownRecorder(recordings::RecordingWriter* writer,
                  const Appliance& appliance,
                  ShownOptions options);
    ~ShownRecorder();
    ShownRecorder(const ShownRecorder&) = delete;
    ShownRecorder& operator=(const ShownRecorder&) = delete;

    // The read-back the loop must do for this (the display frame, or nothing).
    pipeline::render::Readback readback() const;
    // The file to record into from the next frame on (a kiosk session's next file; null: none).
    // A new file starts as a file of its own: every warning and error so far, the eye and
    // transforms, the light in force and a thumbnail at its first frame. Call from the frame
    // thread, between frames.
    void setWriter(recordings::RecordingWriter* writer);
    // Call after each frame was presented (the loop's frame callback).
    void onFrame(const recordings::FrameRecord& frame,
                 const pipeline::scene::SceneState& state,
                 const pipeline::render::RenderedFrame& image);
    // Encodes the pending thumbnail, stops the encoder and the log tap. Call before closing the
    // writer; the destructor calls it.
    void finish();
    ShownStats stats() const;

private:
    void encoderLoop();
    void recordLight(const recordings::FrameRecord& frame, const pipeline::scene::SceneState& s);
    template <typename Record>
    void write(const Record& r)
    {
        std::lock_guard lock(writerMutex_);
        if (writer_ != nullptr) {
            writer_->write(r);
        }
    }

    // The writer in use, and how many writers came before it; the messages logged so far (the
    // newest kLogHistoryLimit), each new file's first records.
    mutable std::mutex writerMutex_;
    recordings::RecordingWriter* writer_ = nullptr;
    std::uint64_t writerGeneration_ = 0;
    std::vector<recordings::LogRecord> logs_;
    std::chrono::steady_clock::time_point start_;
    const Appliance& appliance_;
    ShownOptions options_;
    std::optional<pipeline::colour::Observer> observer_;
    // The thumbnails' colour space: the display profile as ICC (empty: sRGB; png_metadata.h).
    std::vector<std::uint8_t> icc_;
    std::string iccName_;
    std::shared_ptr<void> logTap_;
    std::int64_t nextThumbnailNs_ = 0;
    std::int64_t lastPoseNs_ = 0;
    std::optional<pipeline::scene::SceneState> lastPose_;
    int lastLamp_ = -2;
    std::int64_t lastLightNs_ = 0;
    std::optional<std::uint32_t> lastLightSpectrum_;

    // One frame waiting for the encoder (a newer one replaces it).
    struct Pending {
        std::int64_t tNs = 0;
        std::uint64_t frameIndex = 0;
        std::uint64_t generation = 0; // the writer it belongs in
        std::int64_t wallStartNs = 0; // its session's Unix time at session time 0
        int width = 0, height = 0;
        std::vector<std::uint8_t> rgba;
    };
    mutable std::mutex mutex_;
    std::condition_variable wake_;
    std::optional<Pending> pending_;
    bool stopping_ = false;
    std::thread encoder_;
    ShownStats stats_;
};

} // namespace replica::platform
