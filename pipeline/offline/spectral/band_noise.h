// A band-level model of what the spectrometer chain delivers: a light's SPD on the working grid
// with the noise a USB2000+ leaves after auto-integration, dark subtraction, responsivity
// correction and 10 nm band integration. Used to test the light classifier on realistic noisy
// spectra.
#pragma once

#include <cstdint>

#include <pipeline/colour/spectrum.h>

namespace replica::pipeline::spectral {

using colour::Spectrum;

struct BandNoiseParams {
    // Auto-integration puts the highest pixel at this fraction of full scale (65535 counts).
    double peakFraction = 0.8;
    double fullScaleCounts = 65535.0;
    // Shot noise: variance in counts^2 per count of signal (USB2000+ data sheet: SNR 250:1 at full
    // signal, i.e. about 200 counts rms at 50 000 counts).
    double shotVariancePerCount = 0.8;
    // Dark (read) noise per pixel, counts rms (data sheet: 50).
    double readNoiseCounts = 50.0;
    // Pixels averaged into one 10 nm band (about 0.38 nm per pixel under a triangular 10 nm window:
    // an effective 35 independent pixels).
    double pixelsPerBand = 35.0;
    // Relative responsivity of the detector, falling towards the blue and the red: the noise after
    // dividing it out is larger there. Peak 1 near 550 nm.
    bool silicon = true;
    // Scale every noise term (1 = the data-sheet instrument; 0 = noiseless).
    double noiseScale = 1.0;
};

// Relative responsivity of a silicon CCD behind the USB2000+ grating at band b (0.2 .. 1).
double bandResponsivity(std::size_t band);

// Deterministic pseudo-random source (SplitMix64 with Box-Muller), identical on every platform.
class NoiseSource
{
public:
    explicit NoiseSource(std::uint64_t seed) : state_(seed) {}
    double uniform();  // (0, 1)
    double gaussian(); // standard normal
private:
    std::uint64_t state_;
    bool haveSpare_ = false;
    double spare_ = 0.0;
};

// The SPD as sensed: same scale as 'spd', with band-level noise. Bands may come out negative, as a
// dark-subtracted spectrometer reading does.
Spectrum senseWithNoise(const Spectrum& spd, const BandNoiseParams& params, NoiseSource& noise);

} // namespace replica::pipeline::spectral
