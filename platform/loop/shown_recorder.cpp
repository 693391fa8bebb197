// What the panel showed, recorded off the frame's critical path where it costs (the thumbnail).
#include <cmath>

#include <fmt/format.h>

#include <pipeline/base/data_dir.h>
#include <pipeline/colour/cct.h>
#include <pipeline/display/icc_profile.h>
#include <pipeline/spectral/spectrometer_chain.h>
#include <platform/image/png_metadata.h>
#include <platform/image/thumbnail.h>
#include <platform/logging.h>
#include <platform/loop/frame_digest.h>
#include <platform/loop/shown_recorder.h>

namespace replica::platform {
namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point t0)
{
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

int foxgloveLevel(spdlog::level::level_enum l)
{
    switch (l) {
    case spdlog::level::warn:
        return 3;
    case spdlog::level::err:
        return 4;
    case spdlog::level::critical:
        return 5;
    case spdlog::level::info:
        return 2;
    default:
        return 1;
    }
}

} // namespace

ShownRecorder::ShownRecorder(recordings::RecordingWriter* writer,
                             const Appliance& appliance,
                             ShownOptions options)
    : writer_(writer), start_(Clock::now()), appliance_(appliance), options_(options)
{
    if (auto obs = pipeline::colour::loadCie1931(dataDir()); obs) {
        observer_ = std::move(*obs);
    }
    if (options_.log) {
        // Session time of a message: since the recorder was made, just before the first tick;
        // those logged before it (the process's start-up) at 0.
        logTap_ = followLogs([this](const LoggedMessage& m) {
            recordings::LogRecord r;
            r.tNs = std::max<std::int64_t>(
                    0,
                    std::chrono::duration_cast<std::chrono::nanoseconds>(m.time - start_).count());
            r.level = foxgloveLevel(m.level);
            r.name = m.area;
            r.message = m.message;
            std::lock_guard lock(writerMutex_);
            logs_.push_back(r);
            if (logs_.size() > kLogHistoryLimit) {
                logs_.erase(logs_.begin());
            }
            if (writer_ != nullptr) {
                writer_->write(r);
            }
        });
    }
    if (options_.thumbnailHz > 0.0 && options_.thumbnailWidth > 0) {
        if (auto icc = pipeline::display::iccProfileBytes(appliance_.displayModel); icc) {
            icc_ = std::move(*icc);
            iccName_ = appliance_.displayModel.name;
        } else {
            logger("rec")->warn("thumbnails are tagged sRGB: {}", icc.error().message);
        }
        encoder_ = std::thread([this] { encoderLoop(); });
    }
}

ShownRecorder::~ShownRecorder()
{
    finish();
}

pipeline::render::Readback ShownRecorder::readback() const
{
    const bool thumbnails = options_.thumbnailHz > 0.0 && options_.thumbnailWidth > 0;
    return options_.displayDigests || thumbnails ? pipeline::render::Readback::Display
                                                 : pipeline::render::Readback::None;
}

void ShownRecorder::setWriter(recordings::RecordingWriter* writer)
{
    {
        std::lock_guard lock(writerMutex_);
        if (writer == writer_) {
            return;
        }
        writer_ = writer;
        ++writerGeneration_;
        if (writer_ != nullptr) {
            for (const auto& r : logs_) {
                writer_->write(r);
            }
        }
    }
    // The new file's first frame records the eye, the light and a thumbnail afresh.
    lastPose_.reset();
    lastLamp_ = -2;
    lastLightSpectrum_.reset();
    lastLightNs_ = 0;
    nextThumbnailNs_ = 0;
}

void ShownRecorder::onFrame(const recordings::FrameRecord& frame,
                            const pipeline::scene::SceneState& state,
                            const pipeline::render::RenderedFrame& image)
{
    if (options_.displayDigests && !image.rgba.empty()) {
        const auto t0 = Clock::now();
        write(recordings::DisplayDigestRecord{frame.frameIndex, frame.tickNs, xxh3_64(image.rgba)});
        std::lock_guard lock(mutex_);
        stats_.digestMsTotal += msSince(t0);
        ++stats_.digests;
    }
    if (encoder_.joinable() && !image.rgba.empty() && frame.tickNs >= nextThumbnailNs_) {
        const auto period = static_cast<std::int64_t>(std::llround(1e9 / options_.thumbnailHz));
        nextThumbnailNs_ += period;
        if (nextThumbnailNs_ <= frame.tickNs) {
            nextThumbnailNs_ = frame.tickNs + period; // fell behind (a long frame): no burst
        }
        const auto t0 = Clock::now();
        std::lock_guard lock(mutex_);
        if (pending_) {
            ++stats_.thumbnailsSkipped; // the encoder has not taken the previous one yet
        }
        // Reuse the buffer's memory: one copy of the frame, once per thumbnail period.
        Pending p = pending_ ? std::move(*pending_) : Pending{};
        p.tNs = frame.tickNs;
        p.frameIndex = frame.frameIndex;
        {
            std::lock_guard writerLock(writerMutex_);
            p.generation = writerGeneration_;
            p.wallStartNs = writer_ != nullptr ? writer_->wallClockStartNs() : 0;
        }
        p.width = image.width;
        p.height = image.height;
        p.rgba.assign(image.rgba.begin(), image.rgba.end());
        pending_ = std::move(p);
        stats_.copyMsTotal += msSince(t0);
        wake_.notify_one();
    }
    const bool moved = !lastPose_ || lastPose_->eyeBoothM != state.eyeBoothM ||
                       lastPose_->tiltRad != state.tiltRad;
    if (moved && (!lastPose_ || state.tickNs - lastPoseNs_ >= options_.posePeriodNs)) {
        write(recordings::PosesRecord{frame.tickNs, state.eyeBoothM, state.tiltRad,
                                      appliance_.sceneEstimator->trackerInBooth().translation});
        lastPose_ = state;
        lastPoseNs_ = state.tickNs;
        std::lock_guard lock(mutex_);
        ++stats_.poses;
    }
    recordLight(frame, state);
}

void ShownRecorder::recordLight(const recordings::FrameRecord& frame,
                                const pipeline::scene::SceneState& s)
{
    const bool lampChanged = s.lampIndex != lastLamp_;
    // In direct-sensor mode the light is each new spectrum: at most once a second.
    const bool newSensed = s.lampIndex < 0 && frame.sequence(recordings::spectrometerKind()) &&
                           frame.sequence(recordings::spectrometerKind()) != lastLightSpectrum_ &&
                           frame.tickNs - lastLightNs_ >= 1'000'000'000;
    if (!lampChanged && !newSensed) {
        return;
    }
    recordings::LightRecord l;
    l.tNs = frame.tickNs;
    l.frameIndex = frame.frameIndex;
    const auto c = appliance_.sceneEstimator->classification();
    l.distance = c.distance;
    const auto& lamps = appliance_.booth.lights;
    if (s.lampIndex >= 0 && static_cast<std::size_t>(s.lampIndex) < lamps.size()) {
        l.mode = "lamp";
        l.lamp = s.lampIndex;
        l.name = lamps[static_cast<std::size_t>(s.lampIndex)].name;
        const int trusted = appliance_.sceneEstimator->lampArbiter().trustedLamp();
        l.why = trusted == s.lampIndex
                        ? fmt::format("the booth's lamp selector is set to {} (lamp {})", l.name,
                                      l.lamp)
                        : fmt::format("the spectrometer matches the stored lamp {} (shape "
                                      "distance {:.4f})",
                                      l.name, c.distance);
    } else {
        l.mode = "direct-sensor";
        l.lamp = -1;
        l.name = "unknown";
        const auto& light = appliance_.sceneEstimator->light();
        l.why = !frame.sequence(recordings::spectrometerKind())
                        ? std::string("no spectrum yet: the starting light")
                : !light.sensed()
                        ? fmt::format("no usable spectrum yet ({} refused, the last: {}): the "
                                      "starting light",
                                      light.rejectedSpectra(), light.lastRefusal())
                : light.showingWeak()
                        ? fmt::format("too little light to tell its colour (the brightest pixel "
                                      "under {:g} times the detector's noise above dark): the "
                                      "colour there was, at the reading's level, {:.1f} cd/m^2",
                                      pipeline::spectral::kMinPeakOverDarkNoise,
                                      s.emitterLuminanceCdM2)
                : appliance_.config.light == kLightDirect
                        ? fmt::format("direct-sensor mode forced (light = \"direct\"): "
                                      "rendering the sensed light at {:.0f} cd/m^2",
                                      s.emitterLuminanceCdM2)
                        : fmt::format("no stored lamp matches the sensed spectrum (nearest "
                                      "shape distance {:.4f}): rendering the sensed light at "
                                      "{:.0f} cd/m^2",
                                      c.distance, s.emitterLuminanceCdM2);
    }
    if (observer_) {
        const auto xyz = pipeline::colour::spectrumToXyz(*observer_, s.illuminant);
        if (auto cct = pipeline::colour::correlatedColourTemperature(*observer_, xyz); cct) {
            l.cctK = cct->kelvin;
            l.duv = cct->duv;
        }
    }
    write(l);
    lastLamp_ = s.lampIndex;
    lastLightNs_ = frame.tickNs;
    lastLightSpectrum_ = frame.sequence(recordings::spectrometerKind());
    std::lock_guard lock(mutex_);
    ++stats_.lightChanges;
}

void ShownRecorder::encoderLoop()
{
    for (;;) {
        Pending p;
        {
            std::unique_lock lock(mutex_);
            wake_.wait(lock, [this] { return pending_.has_value() || stopping_; });
            if (!pending_) {
                return; // stopping with nothing left
            }
            p = std::move(*pending_);
            pending_.reset();
        }
        const auto t0 = Clock::now();
        const RgbImage small = downscaleRgba(p.width, p.height, p.rgba, options_.thumbnailWidth);
        const PngMetadata meta =
                shownFrameMetadata(icc_, iccName_, p.wallStartNs, p.tNs, p.frameIndex);
        auto png = encodePngRgb(small, &meta);
        const double ms = msSince(t0);
        if (!png) {
            logger("rec")->warn("thumbnail of frame {}: {}", p.frameIndex, png.error().message);
            continue;
        }
        const auto bytes = png->size();
        {
            // A frame of the previous file is not the next file's thumbnail.
            std::lock_guard writerLock(writerMutex_);
            if (writer_ == nullptr || p.generation != writerGeneration_) {
                continue;
            }
            writer_->write(recordings::ThumbnailRecord{p.tNs, p.frameIndex, std::move(*png)});
        }
        std::lock_guard lock(mutex_);
        ++stats_.thumbnails;
        stats_.thumbnailBytes += bytes;
        stats_.encodeMsTotal += ms;
    }
}

void ShownRecorder::finish()
{
    {
        std::lock_guard lock(mutex_);
        stopping_ = true;
    }
    wake_.notify_one();
    if (encoder_.joinable()) {
        encoder_.join();
    }
    logTap_.reset();
}

ShownStats ShownRecorder::stats() const
{
    std::lock_guard lock(mutex_);
    return stats_;
}

} // namespace replica::platform
