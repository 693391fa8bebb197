// Direct-sensor mode's level for a real instrument ('replica calibrate spectrometer
// --luminance-cdm2'): the emitter luminance per unit of the calibrated reading's Y, from a
// recording of one steady lamp and that lamp's luminance as a meter reads it. The simulated
// instrument's figure (platform::kDefaultDirectCdM2PerY) is what this gives for its tungsten
// readings at the shipped lamp's 2200 cd/m^2.
#pragma once

#include <span>

#include <pipeline/base/expected.h>
#include <pipeline/colour/xyz.h>
#include <pipeline/spectral/live_chain.h>

namespace replica::pipeline::spectral {

struct DirectLevelCalibration {
    double cdm2PerY = 0.0;       // RunConfig::directCdM2PerY: luminanceCdM2 / median Y
    double medianY = 0.0;        // of the steady run's readings through the live chain
    int spectra = 0;             // in the longest steady run, which gave the level
    double spreadFraction = 0.0; // (max - min) / median of the run's Y: how steady the light was
};

// Each spectrum through the live chain as the kiosk runs it (the instrument's calibration given,
// no averaging, so that each reading's Y counts once); the longest run of consecutive spectra
// whose shape stays within the chain's steady distance of the run's first (one lamp, not a
// switch) gives the median Y, and the level is luminanceCdM2 over it. Fails with a sentence when
// no run of 5 steady spectra exists, the median Y is not positive (no light, a dark recording), or
// the luminance is not a positive finite number.
Expected<DirectLevelCalibration> calibrateDirectLevel(std::span<const RawSpectrum> spectra,
                                                      const SpectrometerCalibration& cal,
                                                      const InstrumentCalibration& instrument,
                                                      const colour::Observer& observer,
                                                      double luminanceCdM2);

} // namespace replica::pipeline::spectral
