// Confusion, flicker and separability of the light classifier under simulated noise.
#include <algorithm>
#include <cmath>

#include <pipeline/offline/spectral/classifier_study.h>

namespace replica::pipeline::spectral {
namespace {

Spectrum unitNorm(const Spectrum& s)
{
    double n = 0.0;
    for (double v : s.v) {
        n += v * v;
    }
    return n > 0.0 ? s * (1.0 / std::sqrt(n)) : s;
}

} // namespace

ConfusionMatrix classifierConfusion(const std::vector<StoredLight>& lights,
                                    const LightClassifierParams& params,
                                    const BandNoiseParams& noise,
                                    int trials,
                                    std::uint64_t seed)
{
    ConfusionMatrix m;
    for (const auto& l : lights) {
        m.labels.push_back(l.name);
    }
    m.labels.emplace_back("unknown");
    m.trials = trials;
    m.counts.assign(lights.size(), std::vector<int>(lights.size() + 1, 0));
    auto classifier = LightClassifier::create(lights, params);
    if (!classifier) {
        return m;
    }
    NoiseSource rng(seed);
    for (std::size_t t = 0; t < lights.size(); ++t) {
        for (int i = 0; i < trials; ++i) {
            const auto c = classifier->nearest(senseWithNoise(lights[t].spd, noise, rng));
            const std::size_t col = c.index < 0 ? lights.size() : static_cast<std::size_t>(c.index);
            ++m.counts[t][col];
        }
    }
    return m;
}

int classifierFlicker(const std::vector<StoredLight>& lights,
                      const LightClassifierParams& params,
                      const BandNoiseParams& noise,
                      const Spectrum& truth,
                      int samples,
                      std::uint64_t seed)
{
    auto classifier = LightClassifier::create(lights, params);
    if (!classifier) {
        return -1;
    }
    NoiseSource rng(seed);
    int changes = 0;
    int last = -2;
    for (int i = 0; i < samples; ++i) {
        const int answer = classifier->update(senseWithNoise(truth, noise, rng)).index;
        if (i >= params.confirmSamples && answer != last) {
            ++changes;
        }
        last = answer;
    }
    return changes;
}

double noiseFloorDistance(const Spectrum& spd,
                          const BandNoiseParams& noise,
                          int trials,
                          double quantile,
                          std::uint64_t seed)
{
    NoiseSource rng(seed);
    std::vector<double> d;
    for (int i = 0; i < trials; ++i) {
        d.push_back(spectralShapeDistance(senseWithNoise(spd, noise, rng), spd));
    }
    std::sort(d.begin(), d.end());
    if (d.empty()) {
        return 0.0;
    }
    const auto k = static_cast<std::size_t>(
            std::clamp(quantile, 0.0, 1.0) * static_cast<double>(d.size() - 1) + 0.5);
    return d[k];
}

SeparableDifference minimumSeparableDifference(const std::vector<StoredLight>& lights,
                                               const LightClassifierParams& params,
                                               const BandNoiseParams& noise,
                                               std::size_t index,
                                               const Spectrum& other,
                                               int trials,
                                               std::uint64_t seed)
{
    SeparableDifference out;
    auto classifier = LightClassifier::create(lights, params);
    if (!classifier || index >= lights.size()) {
        return out;
    }
    const Spectrum base = unitNorm(lights[index].spd);
    const Spectrum away = unitNorm(other);
    auto stillTaken = [&](double alpha) {
        const Spectrum mix = base * (1.0 - alpha) + away * alpha;
        NoiseSource rng(seed);
        int taken = 0;
        for (int i = 0; i < trials; ++i) {
            taken += classifier->nearest(senseWithNoise(mix, noise, rng)).index ==
                     static_cast<int>(index);
        }
        return taken > trials / 100;
    };
    // Bisection on alpha: the taken fraction falls as the mixture moves away (monotone in
    // practice).
    double lo = 0.0;
    double hi = 1.0;
    if (stillTaken(hi)) {
        return out;
    }
    for (int it = 0; it < 30; ++it) {
        const double mid = 0.5 * (lo + hi);
        (stillTaken(mid) ? lo : hi) = mid;
    }
    out.mixFraction = hi;
    out.shapeDistance = spectralShapeDistance(base * (1.0 - hi) + away * hi, base);
    return out;
}

} // namespace replica::pipeline::spectral
