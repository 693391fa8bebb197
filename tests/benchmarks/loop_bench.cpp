// Per-frame costs of the appliance loop at 960x600: the booth renderer as 'replica run' builds it
// (both passes) for each shipped scene, with the eye moving and the tilt still (pass 1 draws from
// its cache) and with the tilt moving every frame (pass 1 recomputes); hashing a frame for its
// digest; a booth lamp change with a fixed and the adaptive basis. Prints figures; never fails on
// timing.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <random>
#include <string>
#include <tuple>

#include <benchmark/benchmark.h>
#include <state/tilt_estimator.h>

#include <pipeline/base/data_dir.h>
#include <pipeline/booth/booth_model.h>
#include <pipeline/render/booth_shading_pass.h>
#include <pipeline/render/gles_renderer.h>
#include <pipeline/spectral/adaptive_encoding.h>
#include <platform/appliance.h>
#include <platform/loop/frame_digest.h>
#include <platform/output/output.h>

namespace {

using namespace replica;

const char* const kScenes[] = {"colorchecker", "metamer", "painting", "glossy-cylinder"};

// One appliance per scene, specular sample count and cache slices, built once (the GL context
// lives in it).
platform::Appliance* appliance(int scene, int specularSamples, int cacheSlices)
{
    static std::map<std::tuple<int, int, int>, std::unique_ptr<platform::Appliance>> built;
    const std::tuple<int, int, int> key{scene, specularSamples, cacheSlices};
    auto it = built.find(key);
    if (it != built.end()) {
        return it->second.get();
    }
    built.clear();         // one GL context at a time
    platform::RunConfig c; // the defaults 'replica run' uses
    c.width = 960;
    c.height = 600;
    c.sceneDir = std::string("scenes/") + kScenes[scene];
    c.specularSamples = specularSamples;
    c.cacheSlices = cacheSlices;
    // REPLICA_BENCH_SPECULAR_GRID=T: the specular term every T texels (0: per pixel) instead of
    // the scene's default spacing (shading::defaultSpecularGrid), for an A/B of spacings.
    if (const char* grid = std::getenv("REPLICA_BENCH_SPECULAR_GRID")) {
        c.specularGrid = std::atoi(grid);
    }
    // REPLICA_BENCH_LIGHTS=N: N median-cut lights instead of 32 (the glossy cylinder's d65 plan
    // takes 128).
    if (const char* lights = std::getenv("REPLICA_BENCH_LIGHTS")) {
        c.boothLights = std::atoi(lights);
    }
    // REPLICA_BENCH_DIFFUSE_GRID=T: likewise for the diffuse grid (shading::defaultDiffuseGrid).
    if (const char* grid = std::getenv("REPLICA_BENCH_DIFFUSE_GRID")) {
        c.diffuseGrid = std::atoi(grid);
    }
    // REPLICA_BENCH_POINT_LIGHTS or REPLICA_BENCH_AREA_LIGHTS set: eq. (1) from point lights or
    // from areas on every scene (for an A/B of the two in one build: tests/benchmarks/ab_loop.sh
    // with wrappers that set them); neither: as the appliance chooses for the scene.
    if (std::getenv("REPLICA_BENCH_POINT_LIGHTS") != nullptr) {
        c.areaLights = 0;
    } else if (std::getenv("REPLICA_BENCH_AREA_LIGHTS") != nullptr) {
        c.areaLights = 1;
    }
    auto app = platform::buildAppliance(c);
    if (!app) {
        std::fprintf(stderr, "appliance: %s\n", app.error().message.c_str());
        return nullptr;
    }
    return (built[key] = std::move(*app)).get();
}

// Arg 0: scene; arg 1: 0 = eye moving, tilt still; 1 = tilt moving 1 degree a frame (pass 1
// recomputes its cached part on nearly every frame); arg 2: specular samples; arg 3: the bands a
// tilt's recompute is spread over (RunConfig::cacheSlices).
void BM_ApplianceFrame(benchmark::State& st)
{
    auto* app = appliance(static_cast<int>(st.range(0)), static_cast<int>(st.range(2)),
                          static_cast<int>(st.range(3)));
    if (app == nullptr) {
        st.SkipWithError("no EGL/GLES context or appliance");
        return;
    }
    const bool tiltMoves = st.range(1) != 0;
    st.SetLabel(std::string(kScenes[st.range(0)]) +
                (tiltMoves ? ", tilt moving (recompute)" : ", eye moving, tilt still") + ", " +
                std::to_string(app->config.specularSamples) + " specular samples" +
                (st.range(2) == platform::kAutoSpecularSamples ? " (the default)" : "") +
                (tiltMoves
                         ? ", cache in " + std::to_string(app->config.cacheSlices) + " slices" +
                                   (st.range(3) == platform::kDefaultCacheSlices ? " (the default)"
                                                                                 : "")
                         : std::string()));
    pipeline::scene::SceneState state;
    state.lampIndex = 2; // d65-fluorescent
    state.illuminant = app->booth.lights[2].referenceSpectrum;
    state.emitterLuminanceCdM2 = app->booth.lights[2].nominalLuminanceCdM2;
    state.tiltRad = 0.35;
    pipeline::render::RenderedFrame frame;
    // The tilt estimator's held and diffuse tilts, as the appliance's state stage gives them.
    state::TiltEstimator tilts({0.0, app->config.cacheSlices});
    const auto estimate = [&](bool lightChanged) {
        state.lightChanged = lightChanged;
        tilts.sense(state.tiltRad);
        tilts.write(state);
    };
    estimate(true);
    if (!app->renderer->render(state, frame, pipeline::render::Readback::Display)) {
        st.SkipWithError("first frame failed");
        return;
    }
    double t = 0.0;
    int step = 0;
    for (auto _ : st) {
        t += 1.0 / 60.0;
        state.eyeBoothM.x = 0.25 * std::sin(t); // the viewer walks past
        if (tiltMoves) {
            // A triangle wave between 10 and 30 degrees, 1 degree a frame: the held tilt (a
            // 16-frame mean) moves past its 0.15-degree hold on nearly every frame.
            const int phase = step++ % 40;
            const double deg = 10.0 + (phase < 20 ? phase : 40 - phase);
            state.tiltRad = deg * 3.14159265358979 / 180.0;
        }
        estimate(false);
        auto ok = app->renderer->render(state, frame, pipeline::render::Readback::Display);
        benchmark::DoNotOptimize(ok);
    }
    st.counters["fps"] =
            benchmark::Counter(static_cast<double>(st.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_ApplianceFrame)
        ->ArgsProduct({{0, 1, 2, 3},
                       {0, 1},
                       {platform::kAutoSpecularSamples},
                       {platform::kDefaultCacheSlices}}) // the defaults
        ->Apply([](benchmark::internal::Benchmark* b) {
            // The painting tilting with its recompute in 1 to 4 bands (the default is above).
            for (const int slices : {1, 2, 3, 4}) {
                if (slices != platform::kDefaultCacheSlices) {
                    b->Args({2, 1, platform::kAutoSpecularSamples, slices});
                }
            }
        })
        ->Args({0, 0, 48, platform::kDefaultCacheSlices}) // the default before the lod bias was 0
        ->Args({2, 0, 48, platform::kDefaultCacheSlices})
        ->Args({2, 0, 16, platform::kDefaultCacheSlices})
        ->Args({3, 0, 48, platform::kDefaultCacheSlices}) // the cylinder's d65 plan: 48 samples
        ->Args({3, 1, 48, platform::kDefaultCacheSlices})
        ->Args({2, 0, 12, platform::kDefaultCacheSlices}) // the painting's default before 8
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();

// A lamp change in every frame at 960x600 (the appliance's defaults; arg: scene), the tilt still:
// the hiccup a new lamp costs the running appliance (a new light, the surface re-encoded for it,
// the cache recomputed whole).
void BM_ApplianceLampChange(benchmark::State& st)
{
    auto* app = appliance(static_cast<int>(st.range(0)), platform::kAutoSpecularSamples,
                          platform::kDefaultCacheSlices);
    if (app == nullptr) {
        st.SkipWithError("no EGL/GLES context or appliance");
        return;
    }
    st.SetLabel(std::string(kScenes[st.range(0)]) + ", tungsten and d65-fluorescent in turn");
    pipeline::scene::SceneState state;
    state.tiltRad = 0.35;
    pipeline::render::RenderedFrame frame;
    int lamp = 0;
    for (auto _ : st) {
        lamp = lamp == 0 ? 2 : 0;
        state.lampIndex = lamp;
        state.illuminant = app->booth.lights[static_cast<std::size_t>(lamp)].referenceSpectrum;
        state.emitterLuminanceCdM2 =
                app->booth.lights[static_cast<std::size_t>(lamp)].nominalLuminanceCdM2;
        auto ok = app->renderer->render(state, frame, pipeline::render::Readback::Display);
        benchmark::DoNotOptimize(ok);
    }
}
BENCHMARK(BM_ApplianceLampChange)->DenseRange(0, 2)->Unit(benchmark::kMillisecond)->UseRealTime();

// A headless GL context for the benchmarks that draw without an appliance; null without EGL.
platform::Output* glContext()
{
    static std::unique_ptr<platform::Output> out = [] {
        auto o = platform::createHeadlessOutput();
        return o ? std::move(*o) : std::unique_ptr<platform::Output>{};
    }();
    return out.get();
}

// One frame's digests at 960x600: the RGBA32F XYZ frame (9.2 MB) and the 8-bit display frame
// (2.3 MB), as 'replica run --digests' hashes them. Arg 1: FNV-1a (digest format 1), 2: XXH3-64
// (format 2). Arg 3: XXH3-64 of the display frame alone (what a recording's
// /replica/display_digest costs the loop).
void BM_DigestFrame(benchmark::State& st)
{
    const auto which = st.range(0);
    const std::size_t xyzBytes = which == 3 ? 0 : 960 * 600 * 16;
    std::vector<std::uint8_t> xyz(xyzBytes), rgba(960 * 600 * 4);
    std::mt19937 rng(11);
    for (auto& b : xyz) {
        b = static_cast<std::uint8_t>(rng());
    }
    for (auto& b : rgba) {
        b = static_cast<std::uint8_t>(rng());
    }
    const auto hash = which == 1 ? platform::DigestHash::Fnv1a64 : platform::DigestHash::Xxh3_64;
    for (auto _ : st) {
        if (!xyz.empty()) {
            benchmark::DoNotOptimize(platform::frameHash(hash, xyz));
        }
        benchmark::DoNotOptimize(platform::frameHash(hash, rgba));
    }
    st.SetBytesProcessed(static_cast<std::int64_t>(st.iterations() * (xyz.size() + rgba.size())));
}
BENCHMARK(BM_DigestFrame)->Arg(1)->Arg(2)->Arg(3)->Unit(benchmark::kMillisecond);

// The booth pass on a lamp change, on a tiny viewport so that the frame's own shading hardly
// counts: the cost of a lamp change in the loop. Arg 0: same lamp every frame (no change); 1: lamp
// change every frame with the fixed replica_k6 basis (new median cut and light upload); 2: the
// same with adaptive_k6 (also a new basis and the coefficient textures re-encoded and uploaded,
// synchronously in that frame). The colorchecker scene, default booth settings.
void BM_BoothLampChange(benchmark::State& st)
{
    namespace pr = pipeline::render;
    if (glContext() == nullptr) {
        st.SkipWithError("no EGL/GLES context");
        return;
    }
    const bool adaptive = st.range(0) == 2;
    pr::BoothSceneSetup s;
    s.booth = *pipeline::booth::loadBooth(dataDir() / "booth");
    s.scene = *pipeline::surface::loadScene(dataDir() / "scenes" / "colorchecker");
    s.observer = *pipeline::colour::loadCie1931(dataDir());
    if (adaptive) {
        auto e = pipeline::spectral::AdaptiveEncoder::createDefault(dataDir());
        s.adaptive = std::make_shared<const pipeline::spectral::AdaptiveEncoder>(std::move(*e));
        s.basis = s.adaptive->generalBasis();
    } else {
        s.basis = *pipeline::colour::loadDefaultChannelBasis(dataDir());
    }
    const double texels = static_cast<double>(s.scene.width) * s.scene.height;
    auto pass = pr::BoothScenePass::create(std::move(s));
    auto target = pr::XyzTarget::create(8, 5);
    if (!pass || !target) {
        st.SkipWithError("cannot create the booth pass");
        return;
    }
    (*target)->bind();
    pipeline::scene::SceneState state;
    state.lampIndex = 0;
    for (auto _ : st) {
        if (st.range(0) != 0) {
            state.lampIndex = state.lampIndex == 0 ? 2 : 0;
        }
        auto ok = (*pass)->draw(state, 8, 5);
        glFinish();
        benchmark::DoNotOptimize(ok);
    }
    st.counters["texels"] = texels;
    st.counters["encodings"] = static_cast<double>((*pass)->encodings());
}
BENCHMARK(BM_BoothLampChange)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

} // namespace

BENCHMARK_MAIN();
