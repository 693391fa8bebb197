// A light as the appliance's spectrometer senses it: a pixel-level model of an Ocean Optics
// USB2000+ (optical resolution, wavelength calibration error, stray light, auto-integration, dark
// current, shot and read noise, residual non-linearity, 16-bit counts) followed by the appliance's
// own chain (spectrometer_chain.h) back to a working-grid SPD. Used to say what each impairment
// costs end to end (offline/display/colorchecker_study.h, `replica display study --sensed`,
// `replica spectral eval --sensed`). Offline: the run loop never calls it.
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <pipeline/base/expected.h>
#include <pipeline/colour/spectral_table.h>
#include <pipeline/colour/spectrum.h>
#include <pipeline/colour/xyz.h>
#include <pipeline/spectral/live_chain.h>

namespace replica::pipeline::spectral {

// A light at full resolution: a continuum (linear between samples) plus narrow emission lines
// (wavelength nm, integrated power in value x nm).
struct FineLight {
    std::string name;
    std::vector<double> wavelengthNm;
    std::vector<double> continuum;
    std::vector<std::pair<double, double>> lines;
};

// The CIE tables lump each mercury line into one 5 nm (or 10 nm) sample. This puts it back: a
// sample that stands more than 'excess' above the mean of its two neighbours and lies within one
// sample step of a mercury line (404.656, 435.833, 546.074 nm) is replaced by that mean, and the
// excess (times the sample step) becomes a line at the mercury wavelength. Smooth lights come out
// unchanged, without lines. The working-grid light of the result (fineLightToWorkingGrid) is the
// light the comparisons call real.
Expected<FineLight>
restoreLines(const colour::SpectralTable& table, const std::string& column, double excess = 0.5);

// The working-grid SPD of a fine light (triangular 10 nm bands, as every table is reduced).
Expected<colour::Spectrum> fineLightToWorkingGrid(const FineLight& light);

// What is wrong with the instrument. The defaults are the USB2000+ data sheet's figures.
struct InstrumentImpairments {
    double fwhmNm = 1.3; // Gaussian line-spread function (25 um slit, #2 grating)
    // The EEPROM polynomial's error (true - reported wavelength). The data sheet's calibration is
    // good to about +-0.5 nm: studies draw it per instrument (drawWavelengthError).
    double wavelengthErrorNm = 0.0;
    double strayFraction = 5e-4; // of the peak signal, spread evenly over every pixel
    bool noise = true;           // shot, read and dark-current noise
    double residualNonlinearity =
            3e-3; // left after the EEPROM correction: a bow this high mid-scale
};

// A uniform draw in +-maxNm, the same for a seed on every platform.
double drawWavelengthError(double maxNm, std::uint64_t seed);

// An ideal instrument: no impairment at all (the line-spread function is then one pixel wide).
InstrumentImpairments idealInstrument();

// What the appliance does about them.
struct SensingCorrections {
    bool strayLight = false;      // subtract the characterised stray light (ChainOptions)
    bool wavelengthLines = false; // find the shift against the mercury lines when there are any
    int scansAveraged = 1;        // spectra averaged before the chain (the paper reads ~5 a second)
    // The shift last found against the lines of a fluorescent lamp, applied when the light itself
    // has none (an incandescent lamp): the calibration error belongs to the instrument, not the
    // light. NaN = none known.
    double rememberedOffsetNm = std::numeric_limits<double>::quiet_NaN();
    // The appliance's own chain instead (LiveSpectrometerChain with 'chain', fed each of the
    // scansAveraged scans in turn; the instrument's calibration: its stray light, and
    // rememberedOffsetNm as the site's calibrated shift); strayLight and wavelengthLines are then
    // the chain's.
    bool applianceChain = false;
    LiveChainOptions chain;
};

struct SensedLight {
    colour::Spectrum spd;           // working grid, scaled to the real light's luminance
    double wavelengthFoundNm = 0.0; // the correction applied (0 when none)
    bool linesFound = false;
    std::uint32_t integrationTimeUs = 0; // chosen by auto-integration
    double peakCounts = 0.0;             // brightest raw pixel of the last scan
    int scansAveraged = 1;               // in the spectrum returned
};

// Senses 'light' (scansAveraged spectra after auto-integration settles). Deterministic for a seed.
// 'observer' scales the result to the real light's Y (the illuminance is taken as known from
// elsewhere: only the spectral shape comes from the spectrometer).
Expected<SensedLight> senseLight(const FineLight& light,
                                 const colour::Observer& observer,
                                 const InstrumentImpairments& impairments,
                                 const SensingCorrections& corrections,
                                 std::uint64_t seed);

// 'replica calibrate spectrometer' (calibrateWavelengthShift) on this simulated instrument:
// 'scans' spectra of 'light' after auto-integration settles, in runs of 'group'. Nullopt as
// calibrateWavelengthShift (no lines); an error for an impossible light or instrument.
Expected<std::optional<ShiftCalibration>>
calibrateShiftOnSimulatedInstrument(const FineLight& light,
                                    const InstrumentImpairments& impairments,
                                    int scans,
                                    int group,
                                    std::uint64_t seed);

} // namespace replica::pipeline::spectral
