// What a lamp switch costs the appliance's frame: for each shipped scene, the appliance is built as
// 'replica run' builds it (the planner's per-lamp settings from the shipped plan, or the fixed
// rules), with no warm-up, with every pass warmed up at start (BoothScenePass::warmUp), and as
// 'replica run' does (platform/output/pass_warm_up.h: the first frame's pass alone before it, the
// others compiled by a thread of its own after it, then drawn once each in the loop's idle time;
// the frames on the first lamp, 33 ms apart, go on until that is done), and the lamps are visited
// in turn twice (A B C A B C), 'frames' frames each with the viewer walking past. Printed per
// configuration: the build time (the warm-up included), the time to the first frame shown (build
// and first frame), the median of the frames that follow no switch, each switch frame (the first
// frame of a lamp) and the worst of them. The first visit to a lamp is where a pass not yet drawn
// compiles its shaders; the second visit is the switch as it costs once everything is compiled.
// Wall clock, whole frame (both passes, display read-back). Run it with
// MESA_SHADER_CACHE_DISABLE=true: Mesa's on-disk shader cache otherwise hides the compilation after
// the first run (the appliance's first start after an install or upgrade is cold). The 'replica
// run' rows need the cache (the thread's compilation reaches the loop's context through it): each
// gets an empty one of its own (MESA_SHADER_CACHE_DIR, a fresh folder), the cold cache of a first
// start. Their warm-up cell says how long the thread took and each idle-time warm-up's delay to the
// next frame. Usage: replica_bench_lamp_switch [--frames N] [--size WxH] [--scene NAME]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <tests/benchmarks/frame_bench_args.h>

#include <pipeline/base/data_dir.h>
#include <platform/appliance.h>
#include <platform/output/pass_warm_up.h>

using namespace replica;
using namespace replica::pipeline;

namespace {

double msSince(std::chrono::steady_clock::time_point t0)
{
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

double median(std::vector<double> v)
{
    if (v.empty()) {
        return 0.0;
    }
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

enum class WarmUp { None, All, FirstFrame };

// An empty shader cache of its own for this process's next EGL display.
void freshShaderCache()
{
    std::string dir =
            (std::filesystem::temp_directory_path() / "replica-bench-cache-XXXXXX").string();
    if (mkdtemp(dir.data()) != nullptr) {
        setenv("MESA_SHADER_CACHE_DIR", dir.c_str(), 1);
        unsetenv("MESA_SHADER_CACHE_DISABLE");
    }
}

// 'replica run''s warm-up: frames on the first lamp, 33 ms apart, until every pass is compiled.
bool settle(platform::Appliance& app, platform::PassWarmUp& warm, scene::SceneState& state)
{
    render::RenderedFrame frame;
    std::uint64_t n = 1;
    warm.afterFrame(n);
    while (!warm.settled()) {
        std::this_thread::sleep_for(std::chrono::milliseconds(33));
        if (!app.renderer->render(state, frame, render::Readback::Display)) {
            return false;
        }
        warm.afterFrame(++n);
    }
    return true;
}

bool run(const std::string& sceneName, bool planner, WarmUp mode, int frames, int w, int h)
{
    platform::RunConfig c;
    c.width = w;
    c.height = h;
    c.sceneDir = "scenes/" + sceneName;
    c.planner = planner;
    c.warmUp = mode != WarmUp::None;
    c.warmUpAfterFirstFrame = mode == WarmUp::FirstFrame;
    if (mode == WarmUp::FirstFrame) {
        freshShaderCache();
    }
    const auto t0 = std::chrono::steady_clock::now();
    auto app = platform::buildAppliance(c);
    if (!app) {
        std::fprintf(stderr, "appliance: %s\n", app.error().message.c_str());
        return false;
    }
    const double buildMs = msSince(t0);
    std::optional<platform::PassWarmUp> warm;
    if (mode == WarmUp::FirstFrame) {
        warm.emplace((*app)->boothScene, w, h);
    }
    const auto& lamps = (*app)->booth.lights;
    scene::SceneState state;
    state.tiltRad = 30.0 * 3.14159265358979323846 / 180.0;
    render::RenderedFrame frame;
    std::vector<double> steady;
    std::vector<double> firstVisit;
    std::vector<double> secondVisit;
    double t = 0.0;
    bool first = true;
    double firstMs = 0.0;
    for (int round = 0; round < 2; ++round) {
        for (std::size_t l = 0; l < lamps.size(); ++l) {
            state.lampIndex = static_cast<int>(l);
            state.illuminant = lamps[l].referenceSpectrum;
            state.emitterLuminanceCdM2 = lamps[l].nominalLuminanceCdM2;
            for (int i = 0; i < frames; ++i) {
                t += 1.0 / 60.0;
                state.eyeBoothM.x = 0.25 * std::sin(t);
                const auto f0 = std::chrono::steady_clock::now();
                if (!(*app)->renderer->render(state, frame, render::Readback::Display)) {
                    std::fprintf(stderr, "frame failed\n");
                    return false;
                }
                const double ms = msSince(f0);
                if (i == 0 && first) {
                    first = false; // the very first frame: part of the start
                    firstMs = ms;
                    if (warm && !settle(**app, *warm, state)) {
                        std::fprintf(stderr, "frame failed\n");
                        return false;
                    }
                } else if (i == 0) {
                    (round == 0 ? firstVisit : secondVisit).push_back(ms);
                } else {
                    steady.push_back(ms);
                }
            }
        }
    }
    std::string lamps1, lamps2;
    for (const double ms : firstVisit) {
        lamps1 += fmt::format(" {:.0f}", ms);
    }
    for (const double ms : secondVisit) {
        lamps2 += fmt::format(" {:.0f}", ms);
    }
    const double worst1 =
            firstVisit.empty() ? 0.0 : *std::max_element(firstVisit.begin(), firstVisit.end());
    const double worst2 =
            secondVisit.empty() ? 0.0 : *std::max_element(secondVisit.begin(), secondVisit.end());
    std::string how = mode == WarmUp::None ? "no" : "all at start";
    if (warm) {
        std::string idle;
        for (const double ms : warm->idleWarmUpMs()) {
            idle += fmt::format(" {:.0f}", ms);
        }
        how = fmt::format("first frame, then thread ({:.0f} ms) and idle time ({} ms)",
                          warm->backgroundMs(), idle.empty() ? " none" : idle);
        warm->finish();
    }
    std::printf("| %s | %s | %s | %.0f | %.0f | %.1f | %s (worst %.0f) | %s (worst %.0f) |\n",
                sceneName.c_str(), planner ? "planner" : "fixed rules", how.c_str(), buildMs,
                buildMs + firstMs, median(steady), lamps1.c_str(), worst1, lamps2.c_str(), worst2);
    std::fflush(stdout);
    return true;
}

} // namespace

int main(int argc, char** argv)
{
    replica::bench::FrameBenchArgs args;
    args.frames = 8;
    if (auto stop = replica::bench::parseFrameBenchArgs(
                argc, argv, args, 2,
                "Frame times (ms) around lamp switches, planner and fixed rules, with and without "
                "the start-up warm-up and with 'replica run''s; one table row each.")) {
        return *stop;
    }
    const int frames = args.frames;
    const int w = args.width;
    const int h = args.height;
    const std::string only = args.scene;
    std::printf("%dx%d, %d frames a lamp, lamps visited twice in turn; ms, wall clock\n\n", w, h,
                frames);
    std::printf(
            "| scene | settings | warm-up | build ms | to first frame ms | steady median | first "
            "switch to each lamp | second switch to each lamp |\n"
            "|---|---|---|---|---|---|---|---|\n");
    for (const char* scene : {"colorchecker", "metamer", "painting"}) {
        if (!only.empty() && only != scene) {
            continue;
        }
        for (const bool planner : {false, true}) {
            for (const WarmUp warm : {WarmUp::None, WarmUp::All, WarmUp::FirstFrame}) {
                if (!run(scene, planner, warm, frames, w, h)) {
                    return 1;
                }
            }
        }
    }
    return 0;
}
