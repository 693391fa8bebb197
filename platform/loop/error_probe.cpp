// The appliance's own error, measured off the frame's critical path (error_probe.h).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <random>

#include <fmt/format.h>
#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <pipeline/colour/ciede2000.h>
#include <pipeline/colour/cielab.h>
#include <pipeline/reference/reference_integrator.h>
#include <platform/appliance.h>
#include <platform/logging.h>
#include <platform/loop/error_probe.h>

namespace replica::platform {
namespace {

namespace render = pipeline::render;

double threadCpuMs()
{
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}

// The calling thread runs only when a core has nothing else to do (SCHED_IDLE), and at nice 19
// where SCHED_IDLE is refused.
void idlePriority()
{
    sched_param p{};
    p.sched_priority = 0;
    if (pthread_setschedparam(pthread_self(), SCHED_IDLE, &p) != 0) {
        logger("probe")->debug("SCHED_IDLE refused; nice 19 only");
    }
    setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), 19);
}

// Where the frame's pixel (x, row y from the bottom) lies on the surface, as the booth pass's
// shader maps it (booth_main.glsl surfaceUv and texelPosition, here in double).
pipeline::reference::SurfaceSample surfaceSample(const render::SurfaceLayout& l,
                                                 const pipeline::surface::SurfaceScene& scene,
                                                 int w,
                                                 int h,
                                                 const render::FramePixel& p)
{
    const double fx = p.x + 0.5;
    const double fy = p.y + 0.5;
    pipeline::reference::SurfaceSample s;
    s.u = l.offset.x + l.scale.x * fx / w;
    s.v = l.offset.y + l.scale.y * (1.0 - fy / h);
    const double sx = std::max(l.scale.x, 1e-9);
    const double sy = std::max(l.scale.y, 1e-9);
    const double left = -l.offset.x * w / sx;
    const double top = h * (1.0 + l.offset.y / sy);
    s.texel = {(fx - left) * scene.width / (w / sx), (top - fy) * scene.height / (h / sy)};
    return s;
}

bool onSurface(const pipeline::reference::SurfaceSample& s)
{
    return s.u >= 0.0 && s.u < 1.0 && s.v >= 0.0 && s.v < 1.0;
}

} // namespace

ProbeScene probeScene(const render::BoothSceneSetup& setup)
{
    ProbeScene p;
    p.scene = &setup.scene;
    p.booth = &setup.booth;
    p.observer = &setup.observer;
    p.stand = setup.stand;
    p.layout = render::layoutOnPanel(setup.scene, setup.stand);
    p.luminanceScale = setup.luminanceScale;
    return p;
}

std::vector<render::FramePixel>
probePixels(const render::SurfaceLayout& layout, int width, int height, int n, std::uint64_t seed)
{
    std::vector<render::FramePixel> out;
    const render::PixelRect r = render::surfaceRect(layout, width, height);
    if (r.width <= 0 || r.height <= 0 || n <= 0) {
        return out;
    }
    // Any surface works for the (u, v) test: it depends on the layout only.
    pipeline::surface::SurfaceScene unit;
    unit.width = 1;
    unit.height = 1;
    std::mt19937_64 rng(seed);
    std::uniform_int_distribution<int> xs(r.x, r.x + r.width - 1);
    std::uniform_int_distribution<int> ys(r.y, r.y + r.height - 1);
    // The rectangle is the surface widened by a pixel: nearly every draw lands on it.
    for (int tries = 0; static_cast<int>(out.size()) < n && tries < 20 * n; ++tries) {
        const render::FramePixel p{xs(rng), ys(rng)};
        if (onSurface(surfaceSample(layout, unit, width, height, p))) {
            out.push_back(p);
        }
    }
    return out;
}

std::optional<ProbeError> measureError(const ProbeScene& ps,
                                       const pipeline::scene::SceneState& state,
                                       int width,
                                       int height,
                                       const std::vector<render::FramePixel>& pixels,
                                       const std::vector<float>& xyz,
                                       const std::function<bool()>& stop)
{
    ProbeError e;
    const auto& lamps = ps.booth->lights;
    const bool isLamp =
            state.lampIndex >= 0 && static_cast<std::size_t>(state.lampIndex) < lamps.size();
    // The light the booth pass drew with (BoothScenePass::selectLight): the lamp, or the uniform
    // emitter of the sensed spectrum.
    const pipeline::booth::BoothLight light =
            isLamp ? lamps[static_cast<std::size_t>(state.lampIndex)]
                   : render::uniformEmitter(lamps.front(),
                                            state.emitterLuminanceCdM2 * ps.luminanceScale,
                                            state.illuminant);
    pipeline::shading::View view;
    view.panel = pipeline::scene::panelPose(ps.stand, state.tiltRad);
    view.eye = state.eyeBoothM;
    view.pixelsX = width;
    view.pixelsY = height;
    std::vector<pipeline::reference::SurfaceSample> points;
    points.reserve(pixels.size());
    for (const auto& p : pixels) {
        points.push_back(surfaceSample(ps.layout, *ps.scene, width, height, p));
    }
    const auto ref = pipeline::reference::referenceAt(*ps.scene, light, view, *ps.observer, points,
                                                      {}, stop);
    if (ref.xyz.size() < points.size()) {
        return std::nullopt; // stopped
    }
    const std::size_t n = std::min(pixels.size(), xyz.size() / 4);
    if (n == 0) {
        return e;
    }
    std::vector<double> d(n);
    double sum = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
        const pipeline::colour::Xyz gl(xyz[4 * k], xyz[4 * k + 1], xyz[4 * k + 2]);
        d[k] = pipeline::colour::ciede2000(pipeline::colour::xyzToLab(ref.xyz[k], ref.whiteXyz),
                                           pipeline::colour::xyzToLab(gl, ref.whiteXyz));
        sum += d[k];
    }
    std::sort(d.begin(), d.end());
    e.n = n;
    e.mean = sum / static_cast<double>(n);
    e.max = d.back();
    e.p95 = d[std::min(n - 1,
                       static_cast<std::size_t>(std::ceil(0.95 * static_cast<double>(n))) - 1)];
    return e;
}

std::unique_ptr<ErrorProbe> ErrorProbe::create(const Appliance& appliance,
                                               ErrorProbeOptions options,
                                               recordings::RecordingWriter* writer)
{
    if (!(options.periodS > 0.0) || options.pixels <= 0) {
        return nullptr;
    }
    if (!appliance.boothScene) {
        logger("probe")->warn("--error-probe: the flat renderer has no exact reference; no probes");
        return nullptr;
    }
    return std::unique_ptr<ErrorProbe>(new ErrorProbe(appliance, options, writer));
}

ErrorProbe::ErrorProbe(const Appliance& appliance,
                       ErrorProbeOptions options,
                       recordings::RecordingWriter* writer)
    : appliance_(appliance), options_(options), scene_(probeScene(appliance.boothScene->setup())),
      writer_(writer), worker_([this] { workerLoop(); })
{}

ErrorProbe::~ErrorProbe()
{
    finish();
}

void ErrorProbe::setWriter(recordings::RecordingWriter* writer)
{
    std::lock_guard lock(mutex_);
    writer_ = writer;
}

void ErrorProbe::onFrame(const recordings::FrameRecord& frame,
                         const pipeline::scene::SceneState& state)
{
    // Before the first light (the default lamp unset) the frame is black, as is its reference:
    // nothing to measure yet.
    const bool unlit = state.lampIndex < 0 && !(state.emitterLuminanceCdM2 > 0.0);
    if (frame.tickNs < nextNs_ || unlit) {
        return;
    }
    const auto period = static_cast<std::int64_t>(std::llround(options_.periodS * 1e9));
    nextNs_ = frame.tickNs + period;
    {
        std::lock_guard lock(mutex_);
        if (busy_ || stopping_) {
            ++stats_.skipped; // the worker is still on the previous probe
            return;
        }
    }
    const auto t0 = std::chrono::steady_clock::now();
    Job job;
    job.state = state;
    const int w = appliance_.config.width;
    const int h = appliance_.config.height;
    job.pixels = probePixels(scene_.layout, w, h, options_.pixels, frame.frameIndex);
    if (auto ok = appliance_.renderer->readXyzPixels(job.pixels, job.xyz); !ok) {
        logger("probe")->warn("frame {}: {}", frame.frameIndex, ok.error().message);
        return;
    }
    const double readMs =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                    .count();
    std::lock_guard lock(mutex_);
    stats_.readMsTotal += readMs;
    job_ = std::move(job);
    busy_ = true;
    wake_.notify_one();
}

void ErrorProbe::workerLoop()
{
    idlePriority();
    for (;;) {
        Job job;
        {
            std::unique_lock lock(mutex_);
            wake_.wait(lock, [this] { return job_.has_value() || stopping_; });
            if (stopping_) {
                return; // finish() completes a job left here
            }
            job = std::move(*job_);
            job_.reset();
        }
        if (!complete(job, &cancel_)) {
            std::lock_guard lock(mutex_);
            job_ = std::move(job); // finish() completes it
            return;
        }
    }
}

bool ErrorProbe::complete(const Job& job, const std::atomic<bool>* cancel)
{
    const double cpu0 = threadCpuMs();
    const auto stop = [cancel] { return cancel != nullptr && cancel->load(); };
    const auto e = measureError(scene_, job.state, appliance_.config.width,
                                appliance_.config.height, job.pixels, job.xyz, stop);
    if (!e) {
        return false;
    }
    const double cpuMs = threadCpuMs() - cpu0;
    recordings::ErrorProbeRecord r;
    r.tNs = job.state.tickNs;
    r.frameIndex = job.state.frameIndex;
    r.n = e->n;
    r.meanDe00 = e->mean;
    r.p95De00 = e->p95;
    r.maxDe00 = e->max;
    r.budgetP95 = options_.budgetP95;
    r.cpuMs = cpuMs;
    const auto& st = job.state;
    logger("probe")->debug("frame {}: ΔE00 p95 {:.3f}, max {:.3f} over {} pixels ({:.0f} ms CPU); "
                           "lamp {}, encoding {}, tilt {:.4f} rad (diffuse shown at {:.4f})",
                           r.frameIndex, e->p95, e->max, e->n, cpuMs, st.lampIndex, st.encoding,
                           st.tiltRad, st.diffuse ? st.diffuse->tiltRad() : st.tiltRad);
    std::lock_guard lock(mutex_);
    if (writer_ != nullptr) {
        writer_->write(r);
    }
    ++stats_.probes;
    stats_.overBudget += e->p95 > options_.budgetP95 ? 1 : 0;
    stats_.worstP95 = std::max(stats_.worstP95, e->p95);
    stats_.worstMax = std::max(stats_.worstMax, e->max);
    stats_.sumP95 += e->p95;
    stats_.cpuMsTotal += cpuMs;
    const double tickS = static_cast<double>(job.state.tickNs) * 1e-9;
    if (stats_.firstTickS < 0.0) {
        stats_.firstTickS = tickS;
    }
    stats_.lastTickS = tickS;
    busy_ = false;
    return true;
}

void ErrorProbe::finish()
{
    {
        std::lock_guard lock(mutex_);
        stopping_ = true;
    }
    cancel_.store(true);
    wake_.notify_one();
    if (worker_.joinable()) {
        worker_.join();
    }
    std::optional<Job> left;
    {
        std::lock_guard lock(mutex_);
        left.swap(job_);
    }
    if (left) {
        complete(*left, nullptr);
    }
}

ErrorProbeStats ErrorProbe::stats() const
{
    std::lock_guard lock(mutex_);
    return stats_;
}

nlohmann::json errorProbeJson(const ErrorProbeStats& s, const ErrorProbeOptions& o, double wallS)
{
    const double n = static_cast<double>(std::max<std::uint64_t>(s.probes, 1));
    return {{"period_s", o.periodS},
            {"pixels", o.pixels},
            {"budget_p95_de00", o.budgetP95},
            {"probes", s.probes},
            {"over_budget", s.overBudget},
            {"skipped", s.skipped},
            {"p95_de00_mean", s.sumP95 / n},
            {"p95_de00_worst", s.worstP95},
            {"max_de00_worst", s.worstMax},
            {"cpu_ms_per_probe", s.cpuMsTotal / n},
            {"cpu_share_of_core", wallS > 0.0 ? s.cpuMsTotal / (wallS * 1e3) : 0.0},
            {"read_ms_per_probe", s.readMsTotal / n}};
}

void logSpeedAndError(const ErrorProbeStats& s,
                      const ErrorProbeOptions& o,
                      std::uint64_t framesOverPeriod,
                      std::uint64_t frames,
                      double wallS)
{
    const double n = static_cast<double>(std::max<std::uint64_t>(s.probes, 1));
    logger("replica")->info(
            "speed and error: {} of {} frames over the period; {} of {} probes over the error "
            "budget (p95 ΔE00 > {:g}; worst p95 {:.2f}, worst max {:.2f}, {} pixels each, every "
            "{:g} s, {} skipped while busy); probe cost {:.0f} ms CPU each at idle priority "
            "({:.2f} % of one core over the run), {:.2f} ms reading pixels in the frame",
            framesOverPeriod, frames, s.overBudget, s.probes, o.budgetP95, s.worstP95, s.worstMax,
            o.pixels, o.periodS, s.skipped, s.cpuMsTotal / n,
            wallS > 0.0 ? 100.0 * s.cpuMsTotal / (wallS * 1e3) : 0.0, s.readMsTotal / n);
}

} // namespace replica::platform
