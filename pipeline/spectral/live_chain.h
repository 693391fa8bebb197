// The appliance's spectrometer chain as the kiosk runs it (state/light_estimator.cpp) and as
// 'replica spectral eval --sensed' measures it (its "appliance chain" row: sensed_light.cpp feeds
// the simulated scans through this same class): countsToSpectrum with the instrument's
// characterised stray light subtracted, the EEPROM wavelength polynomial shifted by what the
// mercury lines of a fluorescent lamp say (remembered for a light without lines), and the spectra
// of a steady light averaged. A spectrum whose shape leaves the running average by more than
// steadyDistance starts a new average with itself alone, so a lamp change reaches the classifier
// in the same spectrum as without averaging.
#pragma once

#include <array>
#include <cstdint>
#include <deque>
#include <optional>
#include <span>
#include <vector>

#include <pipeline/base/expected.h>
#include <pipeline/colour/spectrum.h>
#include <pipeline/spectral/spectrometer_chain.h>

namespace replica::pipeline::spectral {

// What the site knows of its instrument ('replica calibrate spectrometer'; without it the data
// sheet's figures): the stray light's share of the peak signal, and the wavelength shift (true -
// EEPROM polynomial) found against the mercury lines of a fluorescent booth lamp.
struct InstrumentCalibration {
    double strayLightFraction = 5e-4; // USB2000+ data sheet: 0.05 %
    double wavelengthOffsetNm = 0.0;
};

struct LiveChainOptions {
    bool strayLight = true;      // subtract InstrumentCalibration::strayLightFraction
    bool wavelengthLines = true; // refine the shift against the mercury lines of each average
    int averageSpectra = 5;      // at most this many spectra of a steady light (1: none)
    // The shape distance (spectralShapeDistance) from the running average beyond which a spectrum
    // is another light: below the classifier's accept distance (0.05), above one spectrum's
    // noise (the data-sheet instrument on a narrow tri-band lamp or an RGB LED stays within it,
    // tests/unit/spectral/sensed_light_test.cpp). The booth's lamps are 0.15 or more apart.
    double steadyDistance = 0.04;

    // The chain of recordings made before these options (and of '--no-sensing-corrections'):
    // countsToSpectrum with default options, one spectrum at a time.
    static LiveChainOptions none()
    {
        LiveChainOptions o;
        o.strayLight = false;
        o.wavelengthLines = false;
        o.averageSpectra = 1;
        return o;
    }
};

class LiveSpectrometerChain
{
public:
    LiveSpectrometerChain() = default;
    LiveSpectrometerChain(SpectrometerCalibration calibration,
                          InstrumentCalibration instrument,
                          LiveChainOptions options);

    // One spectrum in; the spectrum to use now out (the average of the steady run it joined).
    // Fails as countsToSpectrum does; a failed spectrum leaves the average as it was.
    Expected<colour::Spectrum> add(const RawSpectrum& raw);

    // How many spectra the last result averaged; the wavelength shift it applied.
    int averaged() const { return static_cast<int>(window_.size()); }
    double wavelengthOffsetNm() const { return offsetNm_; }
    const LiveChainOptions& options() const { return options_; }
    const InstrumentCalibration& instrument() const { return instrument_; }

    // The running average's spectra and the remembered shift (the state a rotated session file's
    // head saves, state/light_estimator.h).
    struct State {
        std::vector<std::vector<std::uint16_t>> window;
        double offsetNm = 0.0;
        std::uint32_t integrationTimeUs = 0; // the window's spectra's
        std::array<double, 4> wavelengthCoeffs{};
        std::array<double, 8> nonlinearityCoeffs{};
    };
    State state() const;
    void restore(const State& s);

private:
    ChainOptions chainOptions() const;
    Expected<colour::Spectrum> convert(const RawSpectrum& raw) const;

    SpectrometerCalibration calibration_;
    InstrumentCalibration instrument_;
    LiveChainOptions options_ = LiveChainOptions::none();
    std::deque<std::vector<std::uint16_t>> window_;
    // The integration time and coefficients the window's spectra share.
    RawSpectrum format_;
    double offsetNm_ = 0.0;
};

} // namespace replica::pipeline::spectral

namespace replica::pipeline::spectral {

// 'replica calibrate spectrometer': the wavelength shift from the mercury lines of a fluorescent
// lamp. The spectra (of one steady lamp; saturated ones left out) are averaged in runs of 'group'
// consecutive spectra of the same integration time, each run's lines give a shift
// (estimateWavelengthOffset), and the result is their median. Nullopt when no run shows two lines
// (not a fluorescent lamp).
struct ShiftCalibration {
    double offsetNm = 0.0;
    int runs = 0;          // runs whose lines were found
    double spreadNm = 0.0; // max - min of the runs' shifts
};
std::optional<ShiftCalibration> calibrateWavelengthShift(std::span<const RawSpectrum> spectra,
                                                         const SpectrometerCalibration& cal,
                                                         int group = 10);

// The stray light from spectra of a lamp through a long-pass filter that blocks everything below
// cutOnNm: what reaches the pixels from 20 nm above the grating's first order edge to 20 nm below
// the cut-on is stray, relative to the peak (dark-subtracted, linearised counts, averaged over the
// spectra). Nullopt without a usable spectrum or pixel range.
std::optional<double> strayLightFromLongPass(std::span<const RawSpectrum> spectra,
                                             const SpectrometerCalibration& cal,
                                             double cutOnNm);

} // namespace replica::pipeline::spectral
