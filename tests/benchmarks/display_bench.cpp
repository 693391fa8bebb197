// Cost and accuracy of the inverse display model: per colour on the CPU (exact bisection, the
// analytic path with its 1-D tone LUT, the 33^3 tetrahedral LUT) and per 960x600 frame on the GPU
// (both shader paths, and with flare subtraction / viewing compensation off; pass 1 the booth pass
// of the ColorChecker: the eye moves, the tilt stays, so its diffuse term comes from its cache).
// Before the timings it
// prints each path's CIEDE2000 error against the exact inverse over in-gamut colours of the shipped
// profile. Prints figures; never fails on timing.
#include <algorithm>
#include <cstdio>
#include <random>
#include <vector>

#include <benchmark/benchmark.h>

#include <pipeline/base/data_dir.h>
#include <pipeline/booth/booth_model.h>
#include <pipeline/display/display_inverse.h>
#include <pipeline/display/display_profile.h>
#include <pipeline/display/xyz_difference.h>
#include <pipeline/render/booth_scene_pass.h>
#include <pipeline/render/gles_renderer.h>
#include <pipeline/surface/surface_scene.h>
#include <platform/output/output.h>

namespace {

using namespace replica;
namespace pd = pipeline::display;

const pd::DisplayModel& profile()
{
    static const pd::DisplayModel m =
            *pd::loadProfile(dataDir() / "displays" / "wide-ips-synthetic.json");
    return m;
}

const pd::DisplayInverse& inverse()
{
    static const pd::DisplayInverse inv = *pd::DisplayInverse::build(profile());
    return inv;
}

const pd::DisplayLut3d& lut3d()
{
    static const pd::DisplayLut3d lut = pd::DisplayLut3d::build(inverse(), 33);
    return lut;
}

// In-gamut targets: the forward model of random real-valued counts (a quarter of them near black).
std::vector<glm::dvec3> targets(std::size_t n)
{
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(0.0, 255.0);
    std::uniform_real_distribution<double> dark(0.0, 24.0);
    std::vector<glm::dvec3> out;
    for (std::size_t i = 0; i < n; ++i) {
        const bool d = i % 4 == 0;
        const glm::dvec3 c = d ? glm::dvec3(dark(rng), dark(rng), dark(rng))
                               : glm::dvec3(u(rng), u(rng), u(rng));
        out.push_back(profile().forward(c));
    }
    return out;
}

void printAccuracy()
{
    const auto xyz = targets(20000);
    const glm::dvec3 white = profile().whiteXyz();
    std::vector<double> analytic;
    std::vector<double> lut;
    for (const auto& t : xyz) {
        const auto a = inverse().invert(t, pd::GamutMode::HueKeeping, pd::ToneInverse::Lut);
        analytic.push_back(pd::deltaE2000Xyz(profile().forward(a.counts), t, white));
        lut.push_back(pd::deltaE2000Xyz(profile().forward(lut3d().counts(t)), t, white));
    }
    auto report = [](const char* name, std::vector<double> v) {
        std::sort(v.begin(), v.end());
        double sum = 0.0;
        for (double d : v) {
            sum += d;
        }
        std::printf("%-34s mean %.4f  p99 %.4f  max %.4f  (n = %zu)\n", name,
                    sum / static_cast<double>(v.size()), v[v.size() * 99 / 100], v.back(),
                    v.size());
    };
    std::printf("forward(inverse(x)) vs x, CIEDE2000, in-gamut colours of %s:\n",
                profile().name.c_str());
    report("analytic (M^-1 + 4096-entry 1-D)", analytic);
    report("3-D LUT 33^3 tetrahedral", lut);
}

void BM_CpuInverse(benchmark::State& st)
{
    const auto xyz = targets(1024);
    const int path = static_cast<int>(st.range(0));
    std::size_t i = 0;
    for (auto _ : st) {
        const auto& t = xyz[i++ & 1023];
        if (path == 0) {
            benchmark::DoNotOptimize(
                    inverse().invert(t, pd::GamutMode::HueKeeping, pd::ToneInverse::Exact));
        } else if (path == 1) {
            benchmark::DoNotOptimize(
                    inverse().invert(t, pd::GamutMode::HueKeeping, pd::ToneInverse::Lut));
        } else {
            benchmark::DoNotOptimize(lut3d().counts(t));
        }
    }
    st.SetLabel(path == 0 ? "exact" : (path == 1 ? "analytic" : "lut3d"));
}
BENCHMARK(BM_CpuInverse)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kNanosecond);

struct Gpu {
    std::unique_ptr<platform::Output> output;
    std::vector<std::unique_ptr<pipeline::render::Renderer>> renderers; // by variant
    pipeline::scene::SceneState state;
};

// Variants: 0 analytic, 1 3-D LUT, 2 analytic without flare or viewing compensation.
Gpu* gpu()
{
    static Gpu* g = [] {
        auto* fx = new Gpu;
        auto out = platform::createHeadlessOutput();
        if (!out) {
            return fx;
        }
        fx->output = std::move(*out);
        for (int v = 0; v < 3; ++v) {
            pipeline::render::BoothSceneSetup b;
            b.booth = *pipeline::booth::loadBooth(dataDir() / "booth");
            b.scene = *pipeline::surface::loadScene(dataDir() / "scenes" / "colorchecker");
            b.basis = *pipeline::colour::loadDefaultChannelBasis(dataDir());
            b.observer = *pipeline::colour::loadCie1931(dataDir());
            pipeline::render::GlesRendererSetup s;
            s.width = 960;
            s.height = 600;
            s.observer = b.observer;
            auto pass = pipeline::render::BoothScenePass::create(std::move(b));
            if (!pass) {
                std::fprintf(stderr, "booth pass: %s\n", pass.error().message.c_str());
                return fx;
            }
            s.boothScene = std::move(*pass);
            s.display.model = profile();
            s.display.method = v == 1 ? pipeline::render::InverseMethod::Lut3d
                                      : pipeline::render::InverseMethod::Analytic;
            s.display.flareSubtraction = v != 2;
            s.display.viewingCompensation = v != 2;
            fx->state.lampIndex = 0;
            fx->state.tiltRad = 0.35;
            auto r = pipeline::render::createGlesRenderer(std::move(s));
            if (!r) {
                std::fprintf(stderr, "renderer: %s\n", r.error().message.c_str());
                return fx;
            }
            fx->renderers.push_back(std::move(*r));
        }
        return fx;
    }();
    return g;
}

void BM_GpuFrame(benchmark::State& st)
{
    auto* g = gpu();
    const auto v = static_cast<std::size_t>(st.range(0));
    if (g->renderers.size() <= v) {
        st.SkipWithError("no EGL/GLES context");
        return;
    }
    pipeline::render::RenderedFrame frame;
    for (auto _ : st) {
        g->state.eyeBoothM.x += 1e-5; // a new frame; pass 1's diffuse term from its cache
        auto ok = g->renderers[v]->render(g->state, frame, pipeline::render::Readback::None);
        benchmark::DoNotOptimize(ok);
    }
    st.SetLabel(v == 0 ? "analytic" : (v == 1 ? "lut3d" : "analytic, no flare/viewing"));
    st.counters["oog"] = frame.gamut.outOfGamutFraction();
}
BENCHMARK(BM_GpuFrame)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

} // namespace

int main(int argc, char** argv)
{
    printAccuracy();
    benchmark::Initialize(&argc, argv);
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
