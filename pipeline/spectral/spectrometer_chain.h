// The spectrometer signal chain: raw detector counts to a relative spectral power distribution on
// the working grid (dark subtraction, non-linearity, integration time, responsivity, band
// integration).
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <vector>

#include <pipeline/base/expected.h>
#include <pipeline/colour/spectrum.h>

namespace replica::pipeline::spectral {

// Plain copy of what the spectrometer reports with each spectrum (pipeline/ does not see hal/
// types).
struct RawSpectrum {
    std::span<const std::uint16_t> counts;
    std::uint32_t integrationTimeUs = 0;
    std::array<double, 4> wavelengthCoeffs{}; // nm = c0 + c1 p + c2 p^2 + c3 p^3
    std::array<double, 8>
            nonlinearityCoeffs{}; // corrected = c / sum_i a_i c^i (SeaBreeze convention)
};

// The instrument's relative irradiance responsivity (counts per unit power per second).
struct SpectrometerCalibration {
    std::vector<double> wavelengthNm;
    std::vector<double> responsivity;
    // The electrically dark (optically masked) pixels, read for the dark level: 6..20 on the
    // USB2000+ (its protocol notes; hal/spectrometer/usb2000_protocol.h, SeaBreeze). Pixel 21
    // sees light.
    int darkPixelFirst = 6;
    int darkPixelLast = 20;
};

// How far a spectrum's brightest pixel stands above the dark level, against the detector's noise:
// the largest count after the dark pixels less the dark pixels' mean, and the dark pixels'
// standard deviation (their read noise and fixed pattern). Both NaN when the counts are too few.
struct SignalLevel {
    double peakAboveDark = 0.0;
    double darkNoise = 0.0;
};
SignalLevel signalLevel(std::span<const std::uint16_t> counts, const SpectrometerCalibration& cal);
// Below this many times the dark noise (at least 1 count) the brightest pixel is too close to the
// noise to tell a light's colour: its shape is noise (the probe's SNR 3 read CIE A anywhere from
// 2727 to 3121 K), though its level still says how much light there is.
inline constexpr double kMinPeakOverDarkNoise = 10.0;

// Reads a calibration CSV with columns wavelength_nm,responsivity.
Expected<SpectrometerCalibration> loadSpectrometerCalibration(const std::filesystem::path& path);

// Converts one raw spectrum. Fails when the counts are too few for the dark pixels, the integration
// time is zero, or the calibrated wavelengths do not cover the working grid.
Expected<colour::Spectrum> countsToSpectrum(const RawSpectrum& raw,
                                            const SpectrometerCalibration& cal);

struct ChainOptions {
    // Boxcar smoothing over 2 w + 1 neighbouring pixels (SeaBreeze's "boxcar width" w), applied to
    // the dark-subtracted, linearised counts before the responsivity; 0 = none. It trades noise for
    // resolution: w = 5 averages about 4 nm, well inside one 10 nm band.
    int boxcarHalfWidth = 0;
    // Stray-light correction: the fraction of the peak signal that the instrument scatters evenly
    // onto every pixel (characterised once, e.g. with a long-pass filter: USB2000+ data sheet
    // 0.05 %). Subtracted from the linearised counts as f / (1 + f) of their peak. 0 = none.
    double strayLightFraction = 0.0;
    // Added to every pixel's wavelength from the EEPROM polynomial (the shift found against known
    // lamp lines by estimateWavelengthOffset). 0 = the polynomial as it is.
    double wavelengthOffsetNm = 0.0;
};

// Mercury lines every fluorescent lamp carries (NIST, air wavelengths), for the wavelength check.
inline constexpr std::array<double, 3> kMercuryLinesNm{404.656, 435.833, 546.074};

// How far the EEPROM wavelength polynomial is off, from known emission lines in the spectrum
// itself: for each line within +-searchNm of its place, the centre of the peak (three-point
// Gaussian fit on the dark-subtracted counts) is compared with the line's wavelength. Returns the
// mean of (true - found) over the lines found, to be added to every pixel's wavelength; nullopt
// when fewer than minLines clear lines (peak at least 'contrast' times the local baseline above it)
// are present, as under an incandescent lamp.
struct LineSearchOptions {
    double searchNm = 1.5;
    double contrast = 1.0;
    int minLines = 2;
};
std::optional<double> estimateWavelengthOffset(const RawSpectrum& raw,
                                               const SpectrometerCalibration& cal,
                                               std::span<const double> linesNm,
                                               const LineSearchOptions& options = {});

// The same with options.
Expected<colour::Spectrum> countsToSpectrum(const RawSpectrum& raw,
                                            const SpectrometerCalibration& cal,
                                            const ChainOptions& options);

// Auto-integration: the integration time for the next spectrum, chosen so that the highest raw
// pixel (dark included, as the saturation level applies to raw counts) lands near targetFraction of
// the saturation level. Assumes counts grow in proportion to integration time above the dark level.
struct AutoIntegrationParams {
    double saturationCounts = 65535.0; // EEPROM slot 17, or 65535 when not programmed
    double targetFraction = 0.75;      // aim for the peak here...
    double toleranceFraction = 0.15;   // ...and leave the time alone within +-15 % of the target
    std::uint32_t minUs = 1'000;       // hardware-protocols.md: 1 ms .. 65 s in 1 ms steps
    std::uint32_t maxUs = 65'000'000;
    std::uint32_t stepUs = 1'000;
};

struct AutoIntegrationDecision {
    std::uint32_t integrationTimeUs = 0;
    bool saturated = false; // the spectrum just read reached the saturation level
    bool changed = false;
};

// darkCounts is the electrical dark level (mean of the masked pixels). A saturated spectrum says
// only that the peak is too high, not by how much: the time is cut to a quarter.
AutoIntegrationDecision nextIntegrationTime(std::span<const std::uint16_t> counts,
                                            double darkCounts,
                                            std::uint32_t currentUs,
                                            const AutoIntegrationParams& params = {});

} // namespace replica::pipeline::spectral
