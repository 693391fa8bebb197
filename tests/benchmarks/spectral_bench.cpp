// Accuracy and per-pixel cost of the colour representations (docs/accuracy.md). Prints the accuracy
// table (CIEDE2000 against the 36-band calculation, issue 3's normalisation) and then times the
// per-pixel shading of each representation in float, as a shader would run it.
#include <cstdio>
#include <random>
#include <vector>

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <pipeline/base/data_dir.h>
#include <pipeline/spectral/accuracy.h>
#include <pipeline/spectral/representation_catalogue.h>

namespace {

using namespace replica;
using namespace replica::pipeline::spectral;

const char* const kReps[] = {"rgb3", "paper6", "replica_k6", "general_k6", "pca6", "spectral36"};

void printAccuracyTable()
{
    auto obs = pipeline::colour::loadCie1931(dataDir());
    auto d65 = loadCieIlluminant(dataDir(), "D65");
    if (!obs || !d65) {
        std::fprintf(stderr, "cannot load the observer or D65\n");
        return;
    }
    auto lights = evaluationLightNames();
    for (const char* extra : {"F12", "FL3.15", "LED-V1", "LED-RGB1"}) {
        lights.emplace_back(extra); // lights no basis was trained on
    }
    for (const char* setName : {"colorchecker", "tcs14"}) {
        auto set = loadReflectanceSet(dataDir(), setName);
        if (!set) {
            continue;
        }
        std::printf("\n%s (%zu samples): CIEDE2000 mean / std / p90 / max\n\n", setName,
                    set->size());
        std::printf("| light |");
        for (const char* r : kReps) {
            std::printf(" %s |", r);
        }
        std::printf("\n|---|");
        for (std::size_t i = 0; i < std::size(kReps); ++i) {
            std::printf("---|");
        }
        std::printf("\n");
        for (const auto& l : lights) {
            auto light = loadCieIlluminant(dataDir(), l);
            std::printf("| %s |", l.c_str());
            for (const char* r : kReps) {
                auto rep = makeRepresentation(dataDir(), *obs, *d65, r);
                auto res = rep ? evaluateRepresentation(*obs, *d65, **rep, *light, *set)
                               : Expected<AccuracyReport>(tl::unexpected(rep.error()));
                if (!res) {
                    std::printf(" error |");
                    continue;
                }
                const auto& s = res->stats;
                std::printf(" %.3f / %.3f / %.3f / %.3f |", s.mean, s.std, s.p90, s.max);
            }
            std::printf("\n");
        }
    }
    std::printf("\n");
}

// Per-pixel work: XYZ = sum_k t_k m_k, float, over a frame's worth of texels.
template <std::size_t N>
void shadeFrame(benchmark::State& state)
{
    constexpr std::size_t kPixels = 1 << 16;
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<float> texels(kPixels * N);
    for (auto& t : texels) {
        t = u(rng);
    }
    float m[N][3];
    for (std::size_t k = 0; k < N; ++k) {
        for (auto& c : m[k]) {
            c = u(rng);
        }
    }
    std::vector<float> out(kPixels * 3);
    for (auto _ : state) {
        for (std::size_t p = 0; p < kPixels; ++p) {
            const float* t = &texels[p * N];
            float x = 0.0f, y = 0.0f, z = 0.0f;
            for (std::size_t k = 0; k < N; ++k) {
                x += t[k] * m[k][0];
                y += t[k] * m[k][1];
                z += t[k] * m[k][2];
            }
            out[p * 3] = x;
            out[p * 3 + 1] = y;
            out[p * 3 + 2] = z;
        }
        benchmark::DoNotOptimize(out.data());
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) *
                            static_cast<int64_t>(kPixels));
}

// Recomputing the per-light vectors when the light changes (CPU, double).
void lightVectors(benchmark::State& state, const char* name)
{
    auto obs = pipeline::colour::loadCie1931(dataDir());
    auto d65 = loadCieIlluminant(dataDir(), "D65");
    auto f11 = loadCieIlluminant(dataDir(), "F11");
    auto rep = makeRepresentation(dataDir(), *obs, *d65, name);
    if (!rep) {
        state.SkipWithError(rep.error().message.c_str());
        return;
    }
    for (auto _ : state) {
        auto v = (*rep)->lightVectors(*f11);
        benchmark::DoNotOptimize(v.data());
    }
}

BENCHMARK_TEMPLATE(shadeFrame, 3)->Name("shade_per_pixel/rgb3");
BENCHMARK_TEMPLATE(shadeFrame, 6)->Name("shade_per_pixel/six_channel(paper6,replica_k6)");
BENCHMARK_TEMPLATE(shadeFrame, 36)->Name("shade_per_pixel/spectral36");
BENCHMARK_CAPTURE(lightVectors, rgb3, "rgb3");
BENCHMARK_CAPTURE(lightVectors, paper6, "paper6");
BENCHMARK_CAPTURE(lightVectors, replica_k6, "replica_k6");
BENCHMARK_CAPTURE(lightVectors, spectral36, "spectral36");

} // namespace

int main(int argc, char** argv)
{
    printAccuracyTable();
    benchmark::Initialize(&argc, argv);
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
