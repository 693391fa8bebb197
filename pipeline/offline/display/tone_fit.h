// Tone curves fitted through measurement noise: a parametric gain-offset-gamma model (GOG, and
// GOGO with an output offset; Berns 1996) fitted by weighted least squares, and the GOGO model
// plus a smoothing spline on its residual, its smoothing and order chosen by k-fold
// cross-validation. The spline's residual lives either in the value domain (a penalty on the
// second or third derivative) or in the GOGO's linearised domain, y = ((v - offset) / scale)^(1 /
// gamma), where the GOG model is a straight line and a curve that bends where the light is
// brightest (an S-shaped panel's shoulder) is a low-order polynomial, free under a penalty on the
// third or fourth derivative: smoothing there averages the noise without flattening the shoulder.
// The shape with the lowest cross-validated error is kept, the simplest within 2 %. With exact
// data the parametric fit is exact on a GOG panel and the spline's smoothing falls to
// interpolation elsewhere.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <pipeline/display/tone_curve.h>

namespace replica::pipeline::display {

enum class ToneShape {
    Gog,
    Gogo,
    Spline,           // GOGO plus a smoothing spline on its residual in the value domain
    LinearisedSpline, // the same in the GOGO's linearised domain
};

const char* toneShapeName(ToneShape s);

// One ramp reading projected onto its channel: count, value (radiometric, any scale) and the
// reading's weight (1 / variance, up to a common factor).
struct ToneSample {
    double count = 0.0;
    double value = 0.0;
    double weight = 1.0;
};

struct ToneFit {
    ToneShape shape = ToneShape::Spline;
    double maxCount = 255.0;
    std::array<double, 4> gogo{1.0, 1.0, 2.2, 0.0}; // scale, gain, gamma, offset
    double lambda = 0.0;                            // Spline: the penalty weight chosen
    int order = 2; // Spline: the derivative penalised (2: cubic-like, 3: quadratics are free,
                   // 4: cubics are free)
    std::vector<double> knots;      // Spline: sample counts
    std::vector<double> correction; // Spline: residual correction at the knots
    // Weighted CV error per shape (GOG, GOGO, spline, linearised spline), in the value domain.
    std::array<double, 4> cvScore{};
    std::vector<double> residual;   // value - fit at each sample (the samples' order)
    std::vector<double> cvResidual; // the same with the sample's fold left out of the fit

    double operator()(double count) const;
    // The fit sampled at every count (at most 1024 knots, both ends included) and made
    // non-decreasing; 'corrections' counts the samples the monotone step moved.
    ToneCurve curve(int* corrections = nullptr) const;
};

struct ToneFitOptions {
    int folds = 5;
    // Force a shape (no cross-validation between shapes); the spline's smoothing is still chosen
    // by cross-validation unless 'lambda' is set (>= 0).
    bool forceShape = false;
    ToneShape shape = ToneShape::Spline;
    double lambda = -1.0;
    int order = 0; // the spline's penalised derivative, 2 to 4; 0 chooses by cross-validation
    // The one-standard-error rule (Breiman et al. 1984): the simplest shape whose
    // cross-validated error is within this many standard errors of the best (paired over the
    // samples) or within 2 % of it. (Applied to the smoothing too it flattened the S-shaped
    // panel's shoulder.)
    double oneSe = 1.0;
    // A forced shape with its smoothing set (no cross-validation) starts the parametric part's
    // least squares here when 'warmStart' (a previous fit's 'gogo', for refits of nearby data).
    bool warmStart = false;
    std::array<double, 4> start{1.0, 1.0, 2.2, 0.0};
};

// Samples need not be sorted; counts must be distinct and include at least four non-zero levels.
ToneFit fitTone(const std::vector<ToneSample>& samples, double maxCount, const ToneFitOptions& o);

// The spread (1 sigma) of the fitted curve under the given per-sample noise (standard deviations in
// value units), by a parametric bootstrap of 'replicates' refits with the fit's shape and
// smoothing; returned in counts (spread / slope) at every count 1..maxCount (at most 1024 points).
// fullDriveSpread, when given, receives the spread of the value at full drive (value units).
std::vector<double> toneCountSpread(const std::vector<ToneSample>& samples,
                                    const ToneFit& fit,
                                    const std::vector<double>& sigma,
                                    int replicates,
                                    std::uint64_t seed,
                                    double* fullDriveSpread = nullptr);

} // namespace replica::pipeline::display
