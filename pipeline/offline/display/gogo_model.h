// The gain-offset-gamma tone models under the tone fits (pipeline/offline/display/tone_fit.h; Berns
// 1996): GOG, v = scale * max(gain x + 1 - gain, 0)^gamma, and GOGO with an output offset, their
// weighted least-squares fit, and the GOGO's linearised domain in which GOG is a straight line.
// Parameters: {scale, gain, gamma, offset}; x is the count over full drive.
#pragma once

#include <array>
#include <vector>

#include <pipeline/offline/display/tone_fit.h>

namespace replica::pipeline::display {

// GOG or GOGO (any other shape: GOGO) at x.
double gogoEval(const std::array<double, 4>& p, double x, ToneShape shape);

// Starting point: scale from the top reading, gamma from a log-log line through the mid-tones.
std::array<double, 4> gogoStart(const std::vector<double>& x, const std::vector<double>& v);

// Levenberg-Marquardt on the weighted squared residuals of GOG (3 parameters) or GOGO (4).
std::array<double, 4> fitGogo(const std::vector<double>& x,
                              const std::vector<double>& v,
                              const std::vector<double>& w,
                              ToneShape shape,
                              std::array<double, 4> p);

// The GOGO's linearised domain: y = g^-1((v - offset) / scale) with g(y) = sign(y) |y|^gamma, in
// which the GOG part is the straight line linearBase = max(gain x + 1 - gain, 0).
double linearise(const std::array<double, 4>& p, double v);
double delinearise(const std::array<double, 4>& p, double y);
double linearBase(const std::array<double, 4>& p, double x);

// The residual of v from the GOGO in the linearised domain, and its weights (the value domain's
// weights through the slope).
void linearisedResidual(const std::array<double, 4>& p,
                        const std::vector<double>& x,
                        const std::vector<double>& v,
                        const std::vector<double>& w,
                        std::vector<double>& e,
                        std::vector<double>& wl);

} // namespace replica::pipeline::display
