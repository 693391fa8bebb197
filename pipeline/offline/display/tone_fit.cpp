// Noise-robust tone-curve fits.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <random>

#include <pipeline/base/assert.h>
#include <pipeline/base/linear_solve.h>
#include <pipeline/offline/display/gogo_model.h>
#include <pipeline/offline/display/smoothing_spline.h>
#include <pipeline/offline/display/tone_fit.h>

namespace replica::pipeline::display {
namespace {

struct Sorted {
    std::vector<std::size_t> order; // sorted index -> sample index
    std::vector<double> count;
    std::vector<double> x;
    std::vector<double> v;
    std::vector<double> w;
};

// The splines cross-validated: the domain of the residual and the penalised derivative.
struct SplineKind {
    bool linearised = false;
    int order = 2;
};
constexpr std::array<SplineKind, 5> kSplineKinds{
        {{false, 2}, {false, 3}, {true, 2}, {true, 3}, {true, 4}}};

Sorted sortSamples(const std::vector<ToneSample>& samples, double maxCount)
{
    Sorted s;
    s.order.resize(samples.size());
    std::iota(s.order.begin(), s.order.end(), 0);
    std::sort(s.order.begin(), s.order.end(),
              [&](std::size_t a, std::size_t b) { return samples[a].count < samples[b].count; });
    for (std::size_t i : s.order) {
        s.count.push_back(samples[i].count);
        s.x.push_back(samples[i].count / maxCount);
        s.v.push_back(samples[i].value);
        s.w.push_back(samples[i].weight);
    }
    return s;
}

// The fit on weights w for a fixed shape and lambda; correction at every knot.
void fitFixed(const Sorted& s,
              const std::vector<double>& w,
              ToneShape shape,
              double lambda,
              int order,
              const std::array<double, 4>& start,
              std::array<double, 4>& params,
              std::vector<double>& correction)
{
    params =
            fitGogo(s.x, s.v, w, shape == ToneShape::Gog ? ToneShape::Gog : ToneShape::Gogo, start);
    correction.assign(s.x.size(), 0.0);
    if (shape == ToneShape::Spline) {
        std::vector<double> e(s.x.size());
        for (std::size_t i = 0; i < e.size(); ++i) {
            e[i] = s.v[i] - gogoEval(params, s.x[i], ToneShape::Gogo);
        }
        const Penalty pen = penaltyRows(s.x, order);
        correction = smoothSpline(s.x, e, w, lambda * lambdaScale(w, pen), order, pen);
    } else if (shape == ToneShape::LinearisedSpline) {
        std::vector<double> e;
        std::vector<double> wl;
        linearisedResidual(params, s.x, s.v, w, e, wl);
        const Penalty pen = penaltyRows(s.x, order);
        correction = smoothSpline(s.x, e, wl, lambda * lambdaScale(wl, pen), order, pen);
    }
}

// Which spline kinds take part: forcing the value-domain or the linearised spline keeps to its
// domain; 'order' keeps to one penalty.
bool kindUsed(const SplineKind& k, const ToneFitOptions& o, std::size_t n)
{
    if (o.order != 0 && o.order != k.order) {
        return false;
    }
    if (o.forceShape && o.shape == ToneShape::Spline && k.linearised) {
        return false;
    }
    if (o.forceShape && o.shape == ToneShape::LinearisedSpline && !k.linearised) {
        return false;
    }
    return static_cast<std::size_t>(k.order) + 1 < n;
}

// The cross-validated errors of every candidate at every sample: row 0 GOG, row 1 GOGO, then
// each spline kind at each smoothing of the grid (2 + kind * grid size + lambda index). A sample
// never left out keeps error 0.
class CvErrors
{
public:
    CvErrors(const Sorted& s, std::size_t gridSize)
        : s_(s), gridSize_(gridSize),
          err_(2 + kSplineKinds.size() * gridSize, std::vector<double>(s.x.size(), 0.0))
    {}

    std::vector<double>& row(std::size_t r) { return err_[r]; }
    double at(std::size_t r, std::size_t i) const { return err_[r][i]; }
    static std::size_t splineRow(std::size_t kind, std::size_t lambda, std::size_t gridSize)
    {
        return 2 + kind * gridSize + lambda;
    }
    SplineKind kind(std::size_t r) const { return kSplineKinds[(r - 2) / gridSize_]; }
    std::size_t lambdaIndex(std::size_t r) const { return (r - 2) % gridSize_; }

    // The weighted sum of squared errors of a row.
    double score(std::size_t r) const
    {
        double acc = 0.0;
        for (std::size_t i = 0; i < s_.x.size(); ++i) {
            acc += s_.w[i] * err_[r][i] * err_[r][i];
        }
        return acc;
    }

    // The standard error of the difference between two rows' scores (paired over the samples):
    // a row within 'oneSe' of them of the best is not told apart from it by these readings.
    double scoreSe(std::size_t a, std::size_t b) const
    {
        const std::size_t n = s_.x.size();
        double sum = 0.0;
        double sum2 = 0.0;
        for (std::size_t i = 0; i < n; ++i) {
            const double d = s_.w[i] * (err_[a][i] * err_[a][i] - err_[b][i] * err_[b][i]);
            sum += d;
            sum2 += d * d;
        }
        const double nn = static_cast<double>(n);
        return std::sqrt(std::max(0.0, sum2 - sum * sum / nn) * nn / std::max(nn - 1.0, 1.0));
    }

private:
    const Sorted& s_;
    std::size_t gridSize_;
    std::vector<std::vector<double>> err_;
};

// A refit of nearby data with everything fixed but the values: one least-squares fit from the
// previous parameters.
ToneFit refitFixed(const Sorted& s, double maxCount, const ToneFitOptions& o)
{
    const std::size_t n = s.x.size();
    ToneFit fit;
    fit.maxCount = maxCount;
    fit.knots = s.count;
    fit.shape = o.shape;
    const bool spline = o.shape == ToneShape::Spline || o.shape == ToneShape::LinearisedSpline;
    fit.lambda = spline ? o.lambda : 0.0;
    fit.order = o.order != 0 ? o.order : 2;
    fitFixed(s, s.w, o.shape, fit.lambda, fit.order, o.start, fit.gogo, fit.correction);
    if (o.shape == ToneShape::Gog) {
        fit.gogo[3] = 0.0;
    }
    fit.residual.assign(n, 0.0);
    for (std::size_t i = 0; i < n; ++i) {
        fit.residual[s.order[i]] = s.v[i] - fit(s.count[i]);
    }
    fit.cvResidual = fit.residual;
    return fit;
}

// The parametric fits on all samples, the start of each fold's.
struct ParametricFits {
    std::array<double, 4> gog;
    std::array<double, 4> gogo;
};

// Interleaved folds over the levels between the end points (black and full drive stay in every
// training set: leaving them out would test extrapolation): each left-out sample's error under
// every candidate fitted without it.
void crossValidate(const Sorted& s,
                   const ToneFitOptions& o,
                   const ParametricFits& all,
                   const std::vector<double>& grid,
                   const std::vector<Penalty>& penalties,
                   CvErrors& cvErr)
{
    const std::size_t n = s.x.size();
    const int folds = std::max(2, o.folds);
    for (int f = 0; f < folds; ++f) {
        std::vector<double> w = s.w;
        std::vector<std::size_t> out;
        for (std::size_t i = 1; i < n; ++i) {
            if (static_cast<int>((i - 1) % static_cast<std::size_t>(folds)) == f) {
                w[i] = 0.0;
                out.push_back(i);
            }
        }
        if (out.empty()) {
            continue;
        }
        const auto pg = fitGogo(s.x, s.v, w, ToneShape::Gog, all.gog);
        const auto po = fitGogo(s.x, s.v, w, ToneShape::Gogo, all.gogo);
        std::vector<double> e(n);
        for (std::size_t i = 0; i < n; ++i) {
            e[i] = s.v[i] - gogoEval(po, s.x[i], ToneShape::Gogo);
        }
        std::vector<double> el;
        std::vector<double> wl;
        linearisedResidual(po, s.x, s.v, w, el, wl);
        for (std::size_t i : out) {
            cvErr.row(0)[i] = s.v[i] - gogoEval(pg, s.x[i], ToneShape::Gog);
            cvErr.row(1)[i] = e[i];
        }
        for (std::size_t ki = 0; ki < kSplineKinds.size(); ++ki) {
            const SplineKind& kind = kSplineKinds[ki];
            if (!kindUsed(kind, o, n)) {
                continue;
            }
            const auto& ee = kind.linearised ? el : e;
            const auto& ww = kind.linearised ? wl : w;
            const Penalty& pen = penalties[ki];
            const double scale = lambdaScale(ww, pen);
            for (std::size_t k = 0; k < grid.size(); ++k) {
                const auto c = smoothSpline(s.x, ee, ww, grid[k] * scale, kind.order, pen);
                auto& row = cvErr.row(CvErrors::splineRow(ki, k, grid.size()));
                for (std::size_t i : out) {
                    row[i] = kind.linearised
                                     ? s.v[i] - delinearise(po, linearBase(po, s.x[i]) + c[i])
                                     : e[i] - c[i];
                }
            }
        }
    }
}

// The best smoothing and order of each domain (0: value, 1: linearised): its row and score.
struct DomainBest {
    std::array<std::size_t, 2> row{0, 0};
    std::array<double, 2> score{std::numeric_limits<double>::infinity(),
                                std::numeric_limits<double>::infinity()};
};

DomainBest
bestPerDomain(const CvErrors& cvErr, const ToneFitOptions& o, std::size_t n, std::size_t gridSize)
{
    DomainBest best;
    for (std::size_t ki = 0; ki < kSplineKinds.size(); ++ki) {
        if (!kindUsed(kSplineKinds[ki], o, n)) {
            continue;
        }
        const std::size_t d = kSplineKinds[ki].linearised ? 1 : 0;
        for (std::size_t k = 0; k < gridSize; ++k) {
            const std::size_t r = CvErrors::splineRow(ki, k, gridSize);
            const double sc = cvErr.score(r);
            if (sc < best.score[d]) {
                best.score[d] = sc;
                best.row[d] = r;
            }
        }
    }
    return best;
}

// The shape kept and its row: the forced one, else the simplest shape within 2 % (and within the
// one-standard-error rule) of the best cross-validated error.
std::pair<ToneShape, std::size_t>
chooseShape(const Sorted& s, const CvErrors& cvErr, const DomainBest& best, const ToneFitOptions& o)
{
    const std::size_t bestDomain = best.score[1] < best.score[0] ? 1 : 0;
    ToneShape shape = bestDomain == 1 ? ToneShape::LinearisedSpline : ToneShape::Spline;
    std::size_t row = best.row[bestDomain];
    if (o.forceShape) {
        shape = o.shape;
        if (shape == ToneShape::Gog || shape == ToneShape::Gogo) {
            row = shape == ToneShape::Gog ? 0 : 1;
        } else {
            row = best.row[shape == ToneShape::LinearisedSpline ? 1 : 0];
        }
        return {shape, row};
    }
    double scale = 0.0;
    for (std::size_t i = 0; i < s.x.size(); ++i) {
        scale += s.w[i] * s.v[i] * s.v[i];
    }
    std::size_t bestAll = row;
    for (std::size_t r : {std::size_t{1}, std::size_t{0}}) {
        if (cvErr.score(r) < cvErr.score(bestAll)) {
            bestAll = r;
        }
    }
    const double bestScore = cvErr.score(bestAll);
    auto within = [&](std::size_t r) {
        return cvErr.score(r) <= bestScore * 1.02 + 1e-24 * scale ||
               cvErr.score(r) <= bestScore + o.oneSe * cvErr.scoreSe(r, bestAll);
    };
    if (within(0)) {
        return {ToneShape::Gog, 0};
    }
    if (within(1)) {
        return {ToneShape::Gogo, 1};
    }
    return {shape, row};
}

} // namespace

const char* toneShapeName(ToneShape s)
{
    switch (s) {
    case ToneShape::Gog:
        return "gog";
    case ToneShape::Gogo:
        return "gogo";
    case ToneShape::Spline:
        return "gogo+spline";
    case ToneShape::LinearisedSpline:
        return "gogo+linearised spline";
    }
    return "?";
}

double ToneFit::operator()(double count) const
{
    const double x = count / maxCount;
    if (shape == ToneShape::LinearisedSpline) {
        return delinearise(gogo, linearBase(gogo, x) + hermite(knots, correction, count));
    }
    double v = gogoEval(gogo, x, shape == ToneShape::Gog ? ToneShape::Gog : ToneShape::Gogo);
    if (shape == ToneShape::Spline) {
        v += hermite(knots, correction, count);
    }
    return v;
}

ToneCurve ToneFit::curve(int* corrections) const
{
    std::vector<double> counts;
    const int n = maxCount <= 1023.0 ? static_cast<int>(maxCount) + 1 : 1024;
    for (int i = 0; i < n; ++i) {
        counts.push_back(i + 1 == n ? maxCount
                                    : std::round(maxCount * static_cast<double>(i) /
                                                 static_cast<double>(n - 1)));
    }
    std::vector<double> values;
    values.reserve(counts.size());
    for (double c : counts) {
        values.push_back((*this)(c));
    }
    auto mono = poolAdjacentViolators(values);
    if (corrections != nullptr) {
        int moved = 0;
        for (std::size_t i = 0; i < mono.size(); ++i) {
            moved += mono[i] != values[i] ? 1 : 0;
        }
        *corrections = moved;
    }
    return ToneCurve(std::move(counts), std::move(mono));
}

ToneFit fitTone(const std::vector<ToneSample>& samples, double maxCount, const ToneFitOptions& o)
{
    REPLICA_ASSERT(samples.size() >= 4, "a tone fit needs at least four samples");
    const Sorted s = sortSamples(samples, maxCount);
    if (o.forceShape && o.lambda >= 0.0 && o.warmStart) {
        return refitFixed(s, maxCount, o);
    }
    const std::size_t n = s.x.size();
    ToneFit fit;
    fit.maxCount = maxCount;
    fit.knots = s.count;
    const std::array<double, 4> start = gogoStart(s.x, s.v);
    ParametricFits all;
    all.gog = fitGogo(s.x, s.v, s.w, ToneShape::Gog, start);
    all.gogo = fitGogo(s.x, s.v, s.w, ToneShape::Gogo, all.gog);

    const auto grid = lambdaGrid();
    CvErrors cvErr(s, grid.size());
    const bool cv = !(o.forceShape &&
                      ((o.shape != ToneShape::Spline && o.shape != ToneShape::LinearisedSpline) ||
                       o.lambda >= 0.0));
    std::vector<Penalty> penalties;
    for (const SplineKind& kind : kSplineKinds) {
        penalties.push_back(kindUsed(kind, o, n) ? penaltyRows(s.x, kind.order) : Penalty{});
    }
    if (cv) {
        crossValidate(s, o, all, grid, penalties, cvErr);
    }
    const DomainBest best = bestPerDomain(cvErr, o, n, grid.size());
    fit.cvScore = {cvErr.score(0), cvErr.score(1), best.score[0], best.score[1]};
    const auto [shape, row] = chooseShape(s, cvErr, best, o);
    const bool spline = shape == ToneShape::Spline || shape == ToneShape::LinearisedSpline;
    double lambda = 0.0;
    int order = o.order != 0 ? o.order : 2;
    if (spline && row >= 2) {
        lambda = grid[cvErr.lambdaIndex(row)];
        order = cvErr.kind(row).order;
    }
    if (o.forceShape && o.lambda >= 0.0) {
        lambda = o.lambda;
    }
    fit.shape = shape;
    fit.lambda = spline ? lambda : 0.0;
    fit.order = order;
    std::vector<double> corr;
    fitFixed(s, s.w, shape, lambda, order, shape == ToneShape::Gog ? all.gog : all.gogo, fit.gogo,
             corr);
    if (shape == ToneShape::Gog) {
        fit.gogo[3] = 0.0;
    }
    fit.correction = corr;
    fit.residual.assign(n, 0.0);
    fit.cvResidual.assign(n, 0.0);
    for (std::size_t i = 0; i < n; ++i) {
        const double r = s.v[i] - fit(s.count[i]);
        fit.residual[s.order[i]] = r;
        fit.cvResidual[s.order[i]] = cv && i > 0 ? cvErr.at(row, i) : r;
    }
    return fit;
}

std::vector<double> toneCountSpread(const std::vector<ToneSample>& samples,
                                    const ToneFit& fit,
                                    const std::vector<double>& sigma,
                                    int replicates,
                                    std::uint64_t seed,
                                    double* fullDriveSpread)
{
    std::mt19937_64 rng(seed);
    auto gaussian = [&rng] {
        const double u1 = (static_cast<double>(rng() >> 11) + 0.5) * 0x1.0p-53;
        const double u2 = static_cast<double>(rng() >> 11) * 0x1.0p-53;
        return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
    };
    const int nGrid = fit.maxCount <= 1023.0 ? static_cast<int>(fit.maxCount) : 1023;
    std::vector<double> grid;
    for (int i = 1; i <= nGrid; ++i) {
        grid.push_back(fit.maxCount * static_cast<double>(i) / static_cast<double>(nGrid));
    }
    std::vector<double> sum(grid.size(), 0.0);
    std::vector<double> sum2(grid.size(), 0.0);
    ToneFitOptions o;
    o.forceShape = true;
    o.shape = fit.shape;
    o.lambda = fit.lambda;
    o.order = fit.order;
    o.warmStart = true;
    o.start = fit.gogo;
    for (int b = 0; b < replicates; ++b) {
        std::vector<ToneSample> sim = samples;
        for (std::size_t i = 0; i < sim.size(); ++i) {
            sim[i].value = fit(sim[i].count) + sigma[i] * gaussian();
        }
        const ToneFit f = fitTone(sim, fit.maxCount, o);
        for (std::size_t g = 0; g < grid.size(); ++g) {
            const double d = f(grid[g]) - fit(grid[g]);
            sum[g] += d;
            sum2[g] += d * d;
        }
    }
    std::vector<double> out(grid.size());
    const double nr = static_cast<double>(std::max(replicates, 2));
    for (std::size_t g = 0; g < grid.size(); ++g) {
        const double var = std::max(0.0, (sum2[g] - sum[g] * sum[g] / nr) / (nr - 1.0));
        if (fullDriveSpread != nullptr && g + 1 == grid.size()) {
            *fullDriveSpread = std::sqrt(var);
        }
        const double lo = std::max(0.0, grid[g] - 0.5);
        const double hi = std::min(fit.maxCount, grid[g] + 0.5);
        const double slope = (fit(hi) - fit(lo)) / std::max(hi - lo, 1e-9);
        out[g] = slope > 0.0 ? std::min(std::sqrt(var) / slope, 1e6) : 1e6;
    }
    return out;
}

} // namespace replica::pipeline::display
