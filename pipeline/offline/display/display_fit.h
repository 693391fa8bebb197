// Fitting the display model to measurements (Day, Taplin & Berns 2004): black from the (0,0,0)
// rows, tone curves re-derived from the R, G and B ramps for each candidate matrix, and the matrix
// chosen to minimise the mean CIEDE2000 over half of the off-ramp colours; the other half is held
// out for the reported accuracy. Degenerate sets fail with a message saying what to measure.
//
// The tone curves average the meter's noise (pipeline/offline/display/tone_fit.h: GOG, GOGO, or
// GOGO plus a smoothing spline, chosen per channel by cross-validation) of the ramp readings each
// fitted along its primary by weighted least squares, and the primaries' directions come from every
// ramp reading above a fifth of full drive, not from the one full-drive reading. The interpolating
// fit of the first profiles (every ramp reading interpolated; the shipped synthetic profile) stays
// as ToneMethod::Interpolate.
#pragma once

#include <string>

#include <pipeline/base/expected.h>
#include <pipeline/display/display_model.h>
#include <pipeline/offline/display/measurement_set.h>

namespace replica::pipeline::display {

enum class ToneMethod {
    Robust,      // noise-averaging tone curves, primaries from the whole ramps
    Interpolate, // monotone interpolation through every ramp reading, primaries at full drive
};

struct FitOptions {
    std::string name = "display";
    std::string description;
    bool synthetic = false;
    MeasurementCondition condition = MeasurementCondition::Dark;
    // Distinct non-zero levels per channel ramp, full drive included: the cross-validated tone
    // shapes need minRampLevels; a ramp with at least minGogRampLevels but fewer (an ordinary
    // 'targen -d3 -f200' set has 4) gets the parametric GOG curve alone (the robust fit), and the
    // report says so (FitReport::rampLevels).
    int minRampLevels = 8;
    int minGogRampLevels = 4;
    int minColours = 6;                 // off-ramp colours (training + held-out)
    double monotonicTolerance = 0.02;   // a ramp may dip by this fraction of its range (noise), or
                                        // by six sigma of the noise the ramp shows where larger
    double deadChannelFraction = 0.005; // X+Y+Z of a primary below this share of all three: dead
    int maxEvaluations = 4000; // Nelder-Mead evaluations of the matrix; 0 keeps direct primaries
    ToneMethod toneMethod = ToneMethod::Robust;
    // Robust: each XYZ component of a ramp reading has a relative noise with an absolute floor at
    // this share of its primary's length (the reading's weight is 1 / the variance of its fit
    // along the primary).
    double noiseFloor = 0.002;
    int bootstrapReplicates = 24; // for the inverse's expected error in counts
};

Expected<DisplayModel> fitDisplay(const MeasurementSet& set, const FitOptions& options);

} // namespace replica::pipeline::display
