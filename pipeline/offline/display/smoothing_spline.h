// The smoothing spline under the tone fits (pipeline/offline/display/tone_fit.h): a penalised
// least-squares correction at the knots, its penalty on the integrated squared k-th derivative, the
// penalty's dimensionless scale and grid, and the cubic Hermite interpolation between the knots.
#pragma once

#include <vector>

namespace replica::pipeline::display {

// The k-th derivative at each run of k + 1 knots as coefficients of the values there
// (k! times the divided difference), and the run's length as its weight in the integral.
struct Penalty {
    std::vector<std::vector<double>> rows; // rows[j]: coefficients of knots j .. j + k
    std::vector<double> length;
};

Penalty penaltyRows(const std::vector<double>& x, int order);

// Solves (diag(w) + lambda P) c = diag(w) e, P the integrated squared 'order'-th derivative of
// the values at the knots x (strictly increasing), by a banded Cholesky factorisation.
std::vector<double> smoothSpline(const std::vector<double>& x,
                                 const std::vector<double>& e,
                                 const std::vector<double>& w,
                                 double lambda,
                                 int order,
                                 const Penalty& pen);

// The penalty's scale, so that the lambda grid is dimensionless: trace(W) / trace(P).
double lambdaScale(const std::vector<double>& w, const Penalty& pen);

// The smoothing penalties cross-validation tries: 10^-12 to 10^8 in half decades.
std::vector<double> lambdaGrid();

// Cubic Hermite through (knots, values) with three-point slopes; constant beyond the ends.
double hermite(const std::vector<double>& k, const std::vector<double>& v, double t);

} // namespace replica::pipeline::display
