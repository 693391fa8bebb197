// Accuracy and per-pixel cost of the colour representations (docs/accuracy.md). Prints the accuracy
// table (CIEDE2000 against the 36-band calculation, issue 3's normalisation) and then times the
// per-pixel shading of each representation in float, as a shader would run it.
#include <algorithm>
#include <cstdio>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <pipeline/base/data_dir.h>
#include <pipeline/colour/cct.h>
#include <pipeline/offline/spectral/accuracy.h>
#include <pipeline/offline/spectral/classifier_study.h>
#include <pipeline/spectral/adaptive_encoding.h>
#include <pipeline/spectral/representation_catalogue.h>

namespace {

using namespace replica;
using namespace replica::pipeline::spectral;

const char* const kReps[] = {"rgb3",       "paper6", "replica_k6", "adaptive_k6",
                             "general_k6", "pca6",   "spectral36"};

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

// What the adaptive_k6 studies below evaluate with: the observer, D65 (the representations'
// reference white), the ColorChecker and the adaptive representation.
struct AdaptiveStudy {
    pipeline::colour::Observer obs;
    Spectrum d65;
    NamedSpectra colorchecker;
    std::unique_ptr<Representation> rep;
};

std::optional<AdaptiveStudy> loadAdaptiveStudy()
{
    auto obs = pipeline::colour::loadCie1931(dataDir());
    auto d65 = loadCieIlluminant(dataDir(), "D65");
    auto set = loadReflectanceSet(dataDir(), "colorchecker");
    if (!obs || !d65 || !set) {
        return std::nullopt;
    }
    auto rep = makeRepresentation(dataDir(), *obs, *d65, "adaptive_k6");
    if (!rep) {
        return std::nullopt;
    }
    return AdaptiveStudy{std::move(*obs), *d65, std::move(*set), std::move(*rep)};
}

// adaptive_k6 encoded for one light and rendered under another: what the appliance shows between a
// light change and the end of the re-encode, and the general basis it starts from.
void printAdaptiveTransitions()
{
    auto study = loadAdaptiveStudy();
    if (!study) {
        std::fprintf(stderr, "cannot load the adaptive representation\n");
        return;
    }
    const auto& [obs, d65, set, rep] = *study;
    const auto lights = evaluationLightNames();
    // Largest error encoded for the light itself, beyond the 3 decimals of the table.
    double worst = 0.0;
    for (const char* setName : {"colorchecker", "tcs14"}) {
        auto s = loadReflectanceSet(dataDir(), setName);
        for (const auto& l : lights) {
            auto light = loadCieIlluminant(dataDir(), l);
            auto res = evaluateRepresentation(obs, d65, *rep, *light, *s);
            worst = res ? std::max(worst, res->stats.max) : 1e9;
        }
    }
    std::printf("adaptive_k6 encoded for the light present: largest CIEDE2000 over both sets and "
                "the eight lights %.2e\n\n",
                worst);
    std::printf("adaptive_k6 on the ColorChecker, encoded for the row's light, rendered under the "
                "column's: mean / max\n\n| encoded for |");
    for (const auto& l : lights) {
        std::printf(" %s |", l.c_str());
    }
    std::printf("\n|---|");
    for (std::size_t i = 0; i < lights.size(); ++i) {
        std::printf("---|");
    }
    std::printf("\n");
    std::vector<std::string> rows = {"(none: general)"};
    rows.insert(rows.end(), lights.begin(), lights.end());
    for (const auto& row : rows) {
        std::unique_ptr<Representation> fixed;
        if (row[0] != '(') {
            auto encodedFor = loadCieIlluminant(dataDir(), row);
            auto a = rep->adaptedTo(*encodedFor);
            if (!a) {
                continue;
            }
            fixed = std::move(*a);
        }
        std::printf("| %s |", row.c_str());
        for (const auto& l : lights) {
            auto light = loadCieIlluminant(dataDir(), l);
            // The general basis is (*rep) itself before adaptation; a fixed one is not adaptive.
            auto res = fixed ? evaluateRepresentation(obs, d65, *fixed, *light, set)
                             : Expected<AccuracyReport>(makeError(ErrorCode::InvalidArgument, ""));
            if (!fixed) {
                auto general = makeBasisRepresentation(obs, [&] {
                    auto enc = AdaptiveEncoder::createDefault(dataDir());
                    return enc->generalBasis();
                }());
                res = evaluateRepresentation(obs, d65, *general, *light, set);
            }
            if (!res) {
                std::printf(" error |");
                continue;
            }
            std::printf(" %.3f / %.3f |", res->stats.mean, res->stats.max);
        }
        std::printf("\n");
    }
    std::printf("\n");
}

void printClassifierStudy()
{
    std::vector<StoredLight> booth;
    for (const char* n : {"A", "F8", "F7"}) {
        auto l = loadCieIlluminant(dataDir(), n);
        if (!l) {
            return;
        }
        booth.push_back({n, *l});
    }
    const LightClassifierParams params;
    std::printf("light classifier (accept %.3f, release %.3f, margin %.3f, confirm %d)\n\n",
                params.acceptDistance, params.releaseDistance, params.switchMargin,
                params.confirmSamples);
    for (double scale : {1.0, 10.0, 30.0, 40.0}) {
        BandNoiseParams noise;
        noise.noiseScale = scale;
        const auto m = classifierConfusion(booth, params, noise, 1000, 17);
        std::printf("noise x%g (1000 single samples per lamp), rows true, columns answer:\n\n| |",
                    scale);
        for (const auto& l : m.labels) {
            std::printf(" %s |", l.c_str());
        }
        std::printf(" flicker/1000 |\n|---|");
        for (std::size_t i = 0; i <= m.labels.size(); ++i) {
            std::printf("---|");
        }
        std::printf("\n");
        for (std::size_t t = 0; t < booth.size(); ++t) {
            std::printf("| %s |", booth[t].name.c_str());
            for (int c : m.counts[t]) {
                std::printf(" %d |", c);
            }
            std::printf(" %d |\n", classifierFlicker(booth, params, noise, booth[t].spd, 1000, 23));
        }
        std::printf(
                "\nnoise floor (p99.9 shape distance of a reading from its lamp): A %.4f, F8 %.4f, "
                "F7 %.4f\n\n",
                noiseFloorDistance(booth[0].spd, noise, 2000, 0.999, 5),
                noiseFloorDistance(booth[1].spd, noise, 2000, 0.999, 5),
                noiseFloorDistance(booth[2].spd, noise, 2000, 0.999, 5));
    }
    auto all = loadAllCieIlluminants(dataDir());
    if (all) {
        std::vector<StoredLight> cie;
        for (std::size_t i = 0; i < all->size(); ++i) {
            cie.push_back({all->names[i], all->spectra[i]});
        }
        const auto m = classifierConfusion(cie, params, BandNoiseParams{}, 200, 19);
        int correct = 0;
        int unknown = 0;
        int wrong = 0;
        for (std::size_t t = 0; t < cie.size(); ++t) {
            for (std::size_t c = 0; c <= cie.size(); ++c) {
                (c == t ? correct : (c == cie.size() ? unknown : wrong)) += m.counts[t][c];
            }
        }
        std::printf(
                "all %zu CIE illuminants stored, data-sheet noise, 200 samples each: %d correct, "
                "%d unknown, %d wrong\n\n",
                cie.size(), correct, unknown, wrong);
    }
    std::printf("smallest mixture (1 - a) L + a M no longer taken for L (<= 1 %% of samples), "
                "data-sheet noise:\n\n| L | M | a | shape distance |\n|---|---|---|---|\n");
    for (std::size_t i = 0; i < booth.size(); ++i) {
        for (std::size_t j = 0; j < booth.size(); ++j) {
            if (i == j) {
                continue;
            }
            const auto s = minimumSeparableDifference(booth, params, BandNoiseParams{}, i,
                                                      booth[j].spd, 400, 29);
            std::printf("| %s | %s | %.4f | %.4f |\n", booth[i].name.c_str(), booth[j].name.c_str(),
                        s.mixFraction, s.shapeDistance);
        }
    }
    for (double t : {2900.0, 2950.0, 3000.0, 3050.0}) {
        const Spectrum p = pipeline::colour::planckianSpectrum(t);
        auto c = LightClassifier::create(booth, params);
        std::printf("Planckian %.0f K: distance from A %.4f, classified %s\n", t,
                    spectralShapeDistance(p, booth[0].spd), c->nearest(p).name.c_str());
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

// adaptive_k6 on a light change: the new basis (CPU, double), then every texel re-encoded from its
// 36 bands (float, one core), what a worker thread does before the upload.
void adaptiveBasisFor(benchmark::State& state)
{
    auto encoder = AdaptiveEncoder::createDefault(dataDir());
    auto f11 = loadCieIlluminant(dataDir(), "F11");
    if (!encoder || !f11) {
        state.SkipWithError("cannot build the adaptive encoder");
        return;
    }
    for (auto _ : state) {
        auto b = encoder->basisFor(*f11);
        benchmark::DoNotOptimize(b->project[0].v.data());
    }
}

void reencodeTexels(benchmark::State& state)
{
    constexpr std::size_t kTexels = 1 << 16;
    auto encoder = AdaptiveEncoder::createDefault(dataDir());
    auto f11 = loadCieIlluminant(dataDir(), "F11");
    auto basis = encoder && f11 ? encoder->basisFor(*f11)
                                : Expected<pipeline::colour::ChannelBasis>(
                                          makeError(ErrorCode::InvalidArgument, "no encoder"));
    if (!basis) {
        state.SkipWithError(basis.error().message.c_str());
        return;
    }
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<float> bands(kTexels * pipeline::colour::kBands);
    for (auto& b : bands) {
        b = u(rng);
    }
    std::vector<float> coeffs(kTexels * pipeline::colour::kChannels);
    for (auto _ : state) {
        encodeTexels(*basis, bands.data(), kTexels, coeffs.data());
        benchmark::DoNotOptimize(coeffs.data());
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) *
                            static_cast<int64_t>(kTexels));
}

// Direct-sensor mode: surfaces encoded for a light, shown under the light moved by a shape
// distance d (towards each other light of the issue, and by 10 % band noise), before the loop
// re-encodes: what kAdaptiveReencodeDistance trades.
void printDirectSensorDrift()
{
    auto study = loadAdaptiveStudy();
    if (!study) {
        std::fprintf(stderr, "cannot load the adaptive representation\n");
        return;
    }
    const auto& [obs, d65, set, rep] = *study;
    const auto names = evaluationLightNames();
    std::printf(
            "adaptive_k6 encoded for each of the eight lights, rendered under it moved by shape "
            "distance d towards each other light and by band noise (ColorChecker; worst over "
            "%zu x %zu moves + 8 noisy): re-encode threshold %.3f\n\n| d | worst mean | worst "
            "max | mean of means |\n|---|---|---|---|\n",
            names.size(), names.size() - 1, kAdaptiveReencodeDistance);
    for (double d : {0.0025, 0.005, 0.01, 0.02, 0.04, 0.08}) {
        std::mt19937 rng(11);
        std::normal_distribution<double> gauss(0.0, 1.0);
        double worstMean = 0.0, worstMax = 0.0, sumMean = 0.0;
        int n = 0;
        for (const auto& from : names) {
            auto l = loadCieIlluminant(dataDir(), from);
            auto encoded = rep->adaptedTo(*l);
            std::vector<Spectrum> moved;
            for (const auto& to : names) {
                auto m = loadCieIlluminant(dataDir(), to);
                if (auto s = shiftedLight(obs, *l, *m, d); to != from && s) {
                    moved.push_back(*s);
                }
            }
            for (int k = 0; k < 8; ++k) {
                Spectrum noise;
                for (std::size_t b = 0; b < pipeline::colour::kBands; ++b) {
                    noise[b] = (*l)[b] * (1.0 + 0.1 * gauss(rng));
                }
                if (auto s = shiftedLight(obs, *l, noise, d)) {
                    moved.push_back(*s);
                }
            }
            for (const auto& m : moved) {
                auto r = evaluateRepresentation(obs, d65, **encoded, m, set);
                if (r) {
                    worstMean = std::max(worstMean, r->stats.mean);
                    worstMax = std::max(worstMax, r->stats.max);
                    sumMean += r->stats.mean;
                    ++n;
                }
            }
        }
        std::printf("| %.4f | %.4f | %.4f | %.4f |\n", d, worstMean, worstMax,
                    n > 0 ? sumMean / n : 0.0);
    }
    std::printf("\n");
}

BENCHMARK_TEMPLATE(shadeFrame, 3)->Name("shade_per_pixel/rgb3");
BENCHMARK_TEMPLATE(shadeFrame, 6)
        ->Name("shade_per_pixel/six_channel(paper6,replica_k6,adaptive_k6)");
BENCHMARK_TEMPLATE(shadeFrame, 36)->Name("shade_per_pixel/spectral36");
BENCHMARK_CAPTURE(lightVectors, rgb3, "rgb3");
BENCHMARK_CAPTURE(lightVectors, paper6, "paper6");
BENCHMARK_CAPTURE(lightVectors, replica_k6, "replica_k6");
BENCHMARK_CAPTURE(lightVectors, spectral36, "spectral36");
BENCHMARK(adaptiveBasisFor)->Name("adaptive_k6/basis_per_light_change");
BENCHMARK(reencodeTexels)->Name("adaptive_k6/reencode_per_texel");

} // namespace

int main(int argc, char** argv)
{
    printAccuracyTable();
    printAdaptiveTransitions();
    printDirectSensorDrift();
    if (argc > 1 && std::string(argv[1]) == "--accuracy-only") {
        return 0; // the accuracy tables above, without the classifier study and the timings
    }
    printClassifierStudy();
    benchmark::Initialize(&argc, argv);
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
