// The running appliance measures its own error: every few seconds of session time the frame
// thread reads pass 1's XYZ (before the display inverse) at a few hundred random pixels of the
// surface, and a worker thread at idle priority (SCHED_IDLE, nice 19) evaluates the exact
// reference (pipeline/reference, renderReference's per-pixel code) at the same pixels for the
// frame's SceneState and takes the CIEDE2000 between them, Lab white the frame's white. Each
// probe's p95/max goes to the recording (/replica/error_probe) and to the run's summary beside
// the frame times. Nothing it does changes a frame: it reads the XYZ target after the frame was
// presented and before the next one is drawn; a replay does not probe (docs/recordings.md).
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include <pipeline/render/booth_scene_pass.h>
#include <pipeline/render/renderer.h>
#include <pipeline/render/surface_layout.h>
#include <pipeline/scene/scene_state.h>
#include <recordings/recording.h>

namespace replica::platform {

struct Appliance;

// The planner's error budget (docs/accuracy.md): a probe whose p95 ΔE00 is above it is "over".
constexpr double kErrorProbeBudgetP95 = 1.0;
// Pixels per probe and the kiosk's default period: docs/performance.md ("Error probe") measures
// the cost they are chosen from.
constexpr int kErrorProbePixels = 200;
constexpr double kKioskErrorProbeS = 10.0;

struct ErrorProbeOptions {
    double periodS = 0.0; // session time between probes; 0: off
    int pixels = kErrorProbePixels;
    double budgetP95 = kErrorProbeBudgetP95;
};

// What the reference needs of the run's fixed setup (the booth renderer's): the pointers are the
// setup's and live as long as it does.
struct ProbeScene {
    const pipeline::surface::SurfaceScene* scene = nullptr;
    const pipeline::booth::Booth* booth = nullptr;
    const pipeline::colour::Observer* observer = nullptr;
    pipeline::scene::StandModel stand;
    pipeline::render::SurfaceLayout layout; // framebuffer pixel -> surface (u, v)
    double luminanceScale = 1.0;            // the direct-sensor emitter's dimmer
};
ProbeScene probeScene(const pipeline::render::BoothSceneSetup& setup);

// n pixels of a width x height frame drawn at random (seeded: the same seed, the same pixels)
// among those that show the surface (the black surround is not the surface's error).
std::vector<pipeline::render::FramePixel> probePixels(const pipeline::render::SurfaceLayout& layout,
                                                      int width,
                                                      int height,
                                                      int n,
                                                      std::uint64_t seed);

struct ProbeError {
    std::uint64_t n = 0;
    double mean = 0.0;
    double p95 = 0.0;
    double max = 0.0;
};

// The exact reference for 'state' at 'pixels' of a width x height frame against 'xyz' (4 floats
// per pixel, as Renderer::readXyzPixels gives them): the CIEDE2000 per pixel, Lab white the
// reference frame's white, and its mean, 95th percentile and maximum. 'stop' (when given) is asked
// before each pixel; once it says true the result is nothing.
std::optional<ProbeError> measureError(const ProbeScene& scene,
                                       const pipeline::scene::SceneState& state,
                                       int width,
                                       int height,
                                       const std::vector<pipeline::render::FramePixel>& pixels,
                                       const std::vector<float>& xyz,
                                       const std::function<bool()>& stop = {});

struct ErrorProbeStats {
    std::uint64_t probes = 0;
    std::uint64_t overBudget = 0; // p95 above ErrorProbeOptions::budgetP95
    std::uint64_t skipped = 0;    // due while the worker was still on the previous one
    double worstP95 = 0.0;
    double worstMax = 0.0;
    double sumP95 = 0.0;
    double cpuMsTotal = 0.0;                    // the worker's CPU time (reference and ΔE00)
    double readMsTotal = 0.0;                   // frame thread: reading the pixels back
    double firstTickS = -1.0, lastTickS = -1.0; // session time of the first and last probe
};

class ErrorProbe
{
public:
    // Null when the options are off or the renderer is not the booth renderer (said in a log
    // line).
    static std::unique_ptr<ErrorProbe> create(const Appliance& appliance,
                                              ErrorProbeOptions options,
                                              recordings::RecordingWriter* writer);
    ~ErrorProbe();
    ErrorProbe(const ErrorProbe&) = delete;
    ErrorProbe& operator=(const ErrorProbe&) = delete;

    // The file the next probes go to (a kiosk session's next one; null: none).
    void setWriter(recordings::RecordingWriter* writer);
    // After each presented frame, on the frame thread: starts a probe when one is due.
    void onFrame(const recordings::FrameRecord& frame, const pipeline::scene::SceneState& state);
    // Stops the worker; a probe it had not finished is finished here, on the calling thread at
    // its priority (the loop is over: no frame to keep on time), so that a run's last probe is
    // not lost on a busy machine where the idle-priority worker gets no time. The destructor
    // calls it.
    void finish();
    ErrorProbeStats stats() const;
    const ErrorProbeOptions& options() const { return options_; }

private:
    ErrorProbe(const Appliance& appliance,
               ErrorProbeOptions options,
               recordings::RecordingWriter* writer);
    struct Job {
        pipeline::scene::SceneState state;
        std::vector<pipeline::render::FramePixel> pixels;
        std::vector<float> xyz;
    };
    void workerLoop();
    // Measures and records the job; false when 'cancel' stopped it first.
    bool complete(const Job& job, const std::atomic<bool>* cancel);

    const Appliance& appliance_;
    ErrorProbeOptions options_;
    ProbeScene scene_;
    std::int64_t nextNs_ = 0;
    mutable std::mutex mutex_;
    std::condition_variable wake_;
    std::optional<Job> job_;
    bool busy_ = false;
    bool stopping_ = false;
    std::atomic<bool> cancel_{false};
    recordings::RecordingWriter* writer_ = nullptr;
    ErrorProbeStats stats_;
    std::thread worker_;
};

// The summary's "error_probe" object and its log line: probes, how many were over the budget,
// the worst p95 and max, the CPU cost per probe and as a share of one core over the run.
nlohmann::json errorProbeJson(const ErrorProbeStats& s, const ErrorProbeOptions& o, double wallS);
// Speed and error side by side: frames over the period and probes over the error budget.
void logSpeedAndError(const ErrorProbeStats& s,
                      const ErrorProbeOptions& o,
                      std::uint64_t framesOverPeriod,
                      std::uint64_t frames,
                      double wallS);

} // namespace replica::platform
