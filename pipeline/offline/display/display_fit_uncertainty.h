// What the robust display fit (pipeline/offline/display/display_fit.h) reports of its own
// uncertainty: the meter's noise the ramps show, the inverse's expected error in counts, the gamut
// edge's tolerance and floor, the dE00 the held-out readings' noise alone gives, and whether the
// white reading is additive within the noise.
#pragma once

#include <vector>

#include <pipeline/display/display_model.h>
#include <pipeline/offline/display/display_fit_candidate.h>

namespace replica::pipeline::display {

// Sets the report's noise, inverse, gamut-edge and additivity figures and the model's gamut edge
// tolerance and floor. 'rows' are the measurements as read (repeats not averaged).
void reportUncertainty(DisplayModel& model,
                       const FitData& data,
                       const MatrixChoice& choice,
                       const std::vector<Measurement>& rows,
                       int bootstrapReplicates,
                       FitReport& report);

} // namespace replica::pipeline::display
