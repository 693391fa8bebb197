// The display fit's crosstalk candidates (pipeline/offline/display/display_fit.h): none, the
// one-parameter "uniform" family and the nine-entry "full" family of DisplayModel's crosstalk term,
// each fitted by weighted least squares to the additive model's residuals and kept only where
// cross-validation says it predicts better.
#pragma once

#include <vector>

#include <pipeline/display/display_model.h>
#include <pipeline/offline/display/measurement_set.h>

namespace replica::pipeline::display {

// Sets the model's crosstalk term and the report's crosstalk figures. The one-parameter family is
// kept where its fitted coefficient over all off-ramp colours is more than three standard errors
// from zero (the error from the fit's own weighted residuals, so the meter's noise as these
// readings show it) and five-fold cross-validation says it predicts better by at least 0.001 dE00
// (a noise-free additive panel's coefficient can sit many of its tiny standard errors from zero
// through the tone curves' interpolation, but its held-out gain is rounding). The nine-entry
// family is kept only where its paired held-out dE00 gains beat the additive model, and then
// the one-parameter one, by more than two standard errors (as the matrix refinement) and
// 0.001. An additive panel keeps C = 0 exactly. Why the coefficient and not the paired gains
// for the one-parameter family: most of its signal is in one reading (white, then the three
// secondaries), and one colour's gain among 61 cannot pass a paired two-standard-error test
// (it left the term out on 2 of seeds 1001..1020 of the crosstalk panel at 0.2 % noise,
// white off by 0.8 counts). All colours, not the training half: the decision needs every
// colour. The fit's held-out figures then include a term fitted with the held-out colours.
void chooseCrosstalk(DisplayModel& model,
                     const std::vector<Measurement>& colours,
                     const glm::dvec3& refWhite,
                     FitReport& report);

} // namespace replica::pipeline::display
