// Fitting the display model to measurements (Day, Taplin & Berns 2004): black from the (0,0,0)
// rows, tone curves re-derived from the R, G and B ramps for each candidate matrix, and the matrix
// chosen to minimise the mean CIEDE2000 over half of the off-ramp colours; the other half is held
// out for the reported accuracy. Degenerate sets fail with a message saying what to measure.
#pragma once

#include <string>

#include <pipeline/base/expected.h>
#include <pipeline/display/display_model.h>
#include <pipeline/display/measurement_set.h>

namespace replica::pipeline::display {

struct FitOptions {
    std::string name = "display";
    std::string description;
    bool synthetic = false;
    MeasurementCondition condition = MeasurementCondition::Dark;
    int minRampLevels = 8; // distinct non-zero levels per channel ramp, full drive included
    int minColours = 6;    // off-ramp colours (training + held-out)
    double monotonicTolerance = 0.02;   // a ramp may dip by this fraction of its range (noise)
    double deadChannelFraction = 0.005; // X+Y+Z of a primary below this share of all three: dead
    int maxEvaluations = 4000; // Nelder-Mead evaluations of the matrix; 0 keeps direct primaries
};

Expected<DisplayModel> fitDisplay(const MeasurementSet& set, const FitOptions& options);

} // namespace replica::pipeline::display
