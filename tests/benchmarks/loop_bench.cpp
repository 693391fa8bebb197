// Per-frame costs of the skeleton loop at 960x600: rendering with each readback choice, hashing a
// frame for its digest, and a booth lamp change with a fixed and the adaptive basis. Prints
// figures; never fails on timing.
#include <benchmark/benchmark.h>

#include <pipeline/base/data_dir.h>
#include <pipeline/booth/booth_model.h>
#include <pipeline/display/nominal_display.h>
#include <pipeline/render/booth_shading_pass.h>
#include <pipeline/render/gles_renderer.h>
#include <pipeline/spectral/adaptive_encoding.h>
#include <platform/loop/frame_digest.h>
#include <platform/output/output.h>

namespace {

using namespace replica;

struct Fixture {
    std::unique_ptr<platform::Output> output;
    std::unique_ptr<pipeline::render::Renderer> renderer;
    pipeline::scene::SceneState state;
};

Fixture* fixture()
{
    static Fixture* f = [] {
        auto* fx = new Fixture;
        auto out = platform::createHeadlessOutput();
        if (!out) {
            return fx;
        }
        fx->output = std::move(*out);
        pipeline::render::GlesRendererSetup s;
        s.width = 960;
        s.height = 600;
        s.booth = *pipeline::scene::loadDefaultBooth(dataDir().string());
        s.basis = pipeline::colour::boxBasis();
        s.observer = *pipeline::colour::loadCie1931(dataDir());
        s.surface =
                *pipeline::render::makeColorCheckerSurface(dataDir().string(), s.basis, 600, 400);
        s.display.model = pipeline::display::nominalDisplayModel("srgb-like-800", 800.0, 0.4);
        fx->state.illuminant = s.booth.lamps[0].spectrum;
        fx->state.emitterLuminanceCdM2 = 2200.0;
        fx->state.tiltRad = 0.35;
        auto r = pipeline::render::createGlesRenderer(std::move(s));
        if (r) {
            fx->renderer = std::move(*r);
        }
        return fx;
    }();
    return f;
}

void BM_RenderFrame(benchmark::State& st)
{
    auto* fx = fixture();
    if (!fx->renderer) {
        st.SkipWithError("no EGL/GLES context");
        return;
    }
    const auto readback = static_cast<pipeline::render::Readback>(st.range(0));
    pipeline::render::RenderedFrame frame;
    for (auto _ : st) {
        fx->state.tiltRad += 1e-4; // a new frame each time
        auto ok = fx->renderer->render(fx->state, frame, readback);
        benchmark::DoNotOptimize(ok);
    }
    st.counters["fps"] =
            benchmark::Counter(static_cast<double>(st.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_RenderFrame)
        ->Arg(static_cast<int>(pipeline::render::Readback::None))
        ->Arg(static_cast<int>(pipeline::render::Readback::Display))
        ->Arg(static_cast<int>(pipeline::render::Readback::DisplayAndXyz))
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();

void BM_DigestFrame(benchmark::State& st)
{
    std::vector<std::uint8_t> bytes(960 * 600 * (16 + 4), 0x5a);
    for (auto _ : st) {
        benchmark::DoNotOptimize(platform::fnv1a64(bytes));
    }
    st.SetBytesProcessed(static_cast<std::int64_t>(st.iterations() * bytes.size()));
}
BENCHMARK(BM_DigestFrame)->Unit(benchmark::kMillisecond);

// The booth pass on a lamp change, on a tiny viewport so that the frame's own shading hardly
// counts: the cost of a lamp change in the loop. Arg 0: same lamp every frame (no change); 1: lamp
// change every frame with the fixed replica_k6 basis (new median cut and light upload); 2: the
// same with adaptive_k6 (also a new basis and the coefficient textures re-encoded and uploaded,
// synchronously in that frame). The colorchecker scene, default booth settings.
void BM_BoothLampChange(benchmark::State& st)
{
    namespace pr = pipeline::render;
    auto* fx = fixture(); // the GL context
    if (!fx->output) {
        st.SkipWithError("no EGL/GLES context");
        return;
    }
    const bool adaptive = st.range(0) == 2;
    pr::BoothSceneSetup s;
    s.booth = *pipeline::booth::loadBooth(dataDir() / "booth");
    s.lamps = {"tungsten", "d50-fluorescent", "d65-fluorescent"};
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
