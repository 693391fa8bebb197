// Band-level spectrometer noise.
#include <algorithm>
#include <cmath>
#include <numbers>

#include <pipeline/offline/spectral/band_noise.h>

namespace replica::pipeline::spectral {

double bandResponsivity(std::size_t band)
{
    // A smooth bell on the working grid, 1 at 550 nm and about 0.25 at 380 and 730 nm, like the
    // combined grating and ILX511B detector efficiency of a USB2000+ with a #2 grating.
    const double x = (colour::bandCentreNm(band) - 550.0) / 150.0;
    return 0.2 + 0.8 * std::exp(-0.5 * x * x * 1.6);
}

double NoiseSource::uniform()
{
    // SplitMix64 (Steele, Lea & Flood 2014).
    state_ += 0x9E3779B97F4A7C15ULL;
    std::uint64_t z = state_;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    z ^= z >> 31;
    return (static_cast<double>(z >> 11) + 0.5) * (1.0 / 9007199254740992.0);
}

double NoiseSource::gaussian()
{
    if (haveSpare_) {
        haveSpare_ = false;
        return spare_;
    }
    const double u1 = uniform();
    const double u2 = uniform();
    const double r = std::sqrt(-2.0 * std::log(u1));
    spare_ = r * std::sin(2.0 * std::numbers::pi * u2);
    haveSpare_ = true;
    return r * std::cos(2.0 * std::numbers::pi * u2);
}

Spectrum senseWithNoise(const Spectrum& spd, const BandNoiseParams& params, NoiseSource& noise)
{
    // Counts per unit of SPD, chosen as auto-integration would: the brightest band at the peak
    // level.
    double peak = 0.0;
    for (std::size_t b = 0; b < colour::kBands; ++b) {
        peak = std::max(peak, spd[b] * (params.silicon ? bandResponsivity(b) : 1.0));
    }
    if (!(peak > 0.0)) {
        return spd;
    }
    const double countsPerUnit = params.peakFraction * params.fullScaleCounts / peak;
    Spectrum out;
    for (std::size_t b = 0; b < colour::kBands; ++b) {
        const double resp = params.silicon ? bandResponsivity(b) : 1.0;
        const double signal = std::max(0.0, spd[b] * resp * countsPerUnit);
        const double variance = params.shotVariancePerCount * signal +
                                params.readNoiseCounts * params.readNoiseCounts;
        const double sigma = params.noiseScale * std::sqrt(variance / params.pixelsPerBand);
        const double sensed = signal + sigma * noise.gaussian();
        out[b] = sensed / (resp * countsPerUnit);
    }
    return out;
}

} // namespace replica::pipeline::spectral
