// The spectrometer signal chain: raw detector counts to a relative spectral power distribution on
// the working grid (dark subtraction, non-linearity, integration time, responsivity, band
// integration).
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
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
    int darkPixelFirst = 6; // optically masked pixels, read for the electrical dark level
    int darkPixelLast = 21;
};

// Reads a calibration CSV with columns wavelength_nm,responsivity.
Expected<SpectrometerCalibration> loadSpectrometerCalibration(const std::filesystem::path& path);

// Converts one raw spectrum. Fails when the counts are too few for the dark pixels, the integration
// time is zero, or the calibrated wavelengths do not cover the working grid.
Expected<colour::Spectrum> countsToSpectrum(const RawSpectrum& raw,
                                            const SpectrometerCalibration& cal);

} // namespace replica::pipeline::spectral
