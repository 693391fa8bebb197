// Per-frame costs of the skeleton loop at 960x600: rendering with each readback choice, and hashing
// a frame for its digest. Prints figures; never fails on timing.
#include <benchmark/benchmark.h>

#include <pipeline/base/data_dir.h>
#include <pipeline/display/nominal_display.h>
#include <pipeline/render/gles_renderer.h>
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

} // namespace

BENCHMARK_MAIN();
