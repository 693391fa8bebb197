// Noise-robust tone-curve fits.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <random>

#include <pipeline/base/assert.h>
#include <pipeline/base/linear_solve.h>
#include <pipeline/display/tone_fit.h>

namespace replica::pipeline::display {
namespace {

double gogoEval(const std::array<double, 4>& p, double x, ToneShape shape)
{
    const double u = p[1] * x + (1.0 - p[1]);
    const double base = u > 0.0 ? p[0] * std::pow(u, p[2]) : 0.0;
    return shape == ToneShape::Gog ? base : base + p[3];
}

double weightedCost(const std::array<double, 4>& p,
                    ToneShape shape,
                    const std::vector<double>& x,
                    const std::vector<double>& v,
                    const std::vector<double>& w)
{
    double c = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) {
        const double r = v[i] - gogoEval(p, x[i], shape);
        c += w[i] * r * r;
    }
    return c;
}

void clampParams(std::array<double, 4>& p)
{
    p[0] = std::max(p[0], 1e-12);
    p[1] = std::clamp(p[1], 0.05, 20.0);
    p[2] = std::clamp(p[2], 0.1, 10.0);
}

// Starting point: scale from the top reading, gamma from a log-log line through the mid-tones.
std::array<double, 4> gogoStart(const std::vector<double>& x, const std::vector<double>& v)
{
    std::size_t top = 0;
    for (std::size_t i = 0; i < x.size(); ++i) {
        if (x[i] > x[top]) {
            top = i;
        }
    }
    const double s = v[top] > 0.0 ? v[top] : 1.0;
    double sxx = 0.0;
    double sxy = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) {
        const double q = v[i] / s;
        if (x[i] > 0.0 && q > 0.02 && q < 0.9) {
            sxx += std::log(x[i]) * std::log(x[i]);
            sxy += std::log(x[i]) * std::log(q);
        }
    }
    const double gamma = sxx > 0.0 ? std::clamp(sxy / sxx, 0.3, 6.0) : 2.2;
    return {s, 1.0, gamma, 0.0};
}

// Levenberg-Marquardt on the weighted squared residuals of GOG (3 parameters) or GOGO (4).
std::array<double, 4> fitGogo(const std::vector<double>& x,
                              const std::vector<double>& v,
                              const std::vector<double>& w,
                              ToneShape shape,
                              std::array<double, 4> p)
{
    const std::size_t np = shape == ToneShape::Gog ? 3 : 4;
    if (shape == ToneShape::Gog) {
        p[3] = 0.0;
    }
    clampParams(p);
    double cost = weightedCost(p, shape, x, v, w);
    double mu = 1e-3;
    for (int it = 0; it < 200; ++it) {
        std::vector<double> jtj(np * np, 0.0);
        std::vector<double> jtr(np, 0.0);
        for (std::size_t i = 0; i < x.size(); ++i) {
            if (w[i] == 0.0) {
                continue;
            }
            const double u = p[1] * x[i] + (1.0 - p[1]);
            std::array<double, 4> g{0.0, 0.0, 0.0, 1.0};
            if (u > 0.0) {
                const double up = std::pow(u, p[2]);
                g[0] = up;
                g[1] = p[0] * p[2] * std::pow(u, p[2] - 1.0) * (x[i] - 1.0);
                g[2] = p[0] * up * std::log(u);
            }
            const double r = v[i] - gogoEval(p, x[i], shape);
            for (std::size_t a = 0; a < np; ++a) {
                jtr[a] += w[i] * g[a] * r;
                for (std::size_t b = 0; b < np; ++b) {
                    jtj[a * np + b] += w[i] * g[a] * g[b];
                }
            }
        }
        bool improved = false;
        for (int tries = 0; tries < 12 && !improved; ++tries) {
            std::vector<double> a = jtj;
            for (std::size_t d = 0; d < np; ++d) {
                a[d * np + d] += mu * std::max(jtj[d * np + d], 1e-300);
            }
            std::vector<double> step = jtr;
            if (std::vector<double> lhs = a; !solveLinear(lhs, step, np)) {
                mu *= 10.0;
                continue;
            }
            std::array<double, 4> q = p;
            for (std::size_t d = 0; d < np; ++d) {
                q[d] += step[d];
            }
            clampParams(q);
            const double c = weightedCost(q, shape, x, v, w);
            if (c <= cost) {
                const double gain = cost - c;
                p = q;
                improved = true;
                mu = std::max(mu / 3.0, 1e-12);
                if (gain <= 1e-14 * cost || cost == 0.0) {
                    cost = c;
                    return p;
                }
                cost = c;
            } else {
                mu *= 4.0;
            }
        }
        if (!improved) {
            break;
        }
    }
    return p;
}

// The k-th derivative at each run of k + 1 knots as coefficients of the values there
// (k! times the divided difference), and the run's length as its weight in the integral.
struct Penalty {
    std::vector<std::vector<double>> rows; // rows[j]: coefficients of knots j .. j + k
    std::vector<double> length;
};

Penalty penaltyRows(const std::vector<double>& x, int order)
{
    Penalty p;
    const std::size_t k = static_cast<std::size_t>(order);
    double factorial = 1.0;
    for (int i = 2; i <= order; ++i) {
        factorial *= i;
    }
    for (std::size_t j = 0; j + k < x.size(); ++j) {
        // Divided differences built up as coefficient vectors over knots j .. j + k.
        std::vector<std::vector<double>> dd(k + 1);
        for (std::size_t i = 0; i <= k; ++i) {
            dd[i].assign(k + 1, 0.0);
            dd[i][i] = 1.0;
        }
        for (std::size_t level = 1; level <= k; ++level) {
            for (std::size_t i = 0; i + level <= k; ++i) {
                const double span = x[j + i + level] - x[j + i];
                for (std::size_t c = 0; c <= k; ++c) {
                    dd[i][c] = (dd[i + 1][c] - dd[i][c]) / span;
                }
            }
        }
        std::vector<double> row(k + 1);
        for (std::size_t c = 0; c <= k; ++c) {
            row[c] = factorial * dd[0][c];
        }
        p.rows.push_back(std::move(row));
        p.length.push_back((x[j + k] - x[j]) / static_cast<double>(k));
    }
    return p;
}

// Solves (diag(w) + lambda P) c = diag(w) e, P the integrated squared 'order'-th derivative of
// the values at the knots x (strictly increasing), by a banded Cholesky factorisation.
std::vector<double> smoothSpline(const std::vector<double>& x,
                                 const std::vector<double>& e,
                                 const std::vector<double>& w,
                                 double lambda,
                                 int order,
                                 const Penalty& pen)
{
    const std::size_t n = x.size();
    const std::size_t k = static_cast<std::size_t>(order);
    const std::size_t bw = k + 1;
    // a[i * bw + d] = A(i, i - d).
    std::vector<double> a(n * bw, 0.0);
    for (std::size_t i = 0; i < n; ++i) {
        a[i * bw] = w[i];
    }
    for (std::size_t j = 0; j < pen.rows.size(); ++j) {
        const double s = lambda * pen.length[j];
        for (std::size_t r = 0; r <= k; ++r) {
            for (std::size_t c = 0; c <= r; ++c) {
                a[(j + r) * bw + (r - c)] += s * pen.rows[j][r] * pen.rows[j][c];
            }
        }
    }
    std::vector<double> l(n * bw, 0.0);
    for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t d = std::min(k, i); d >= 1; --d) {
            const std::size_t j = i - d;
            double s = a[i * bw + d];
            for (std::size_t m = d + 1; m <= k && m <= i; ++m) {
                s -= l[i * bw + m] * l[j * bw + (m - d)];
            }
            l[i * bw + d] = s / l[j * bw];
        }
        double s = a[i * bw];
        for (std::size_t m = 1; m <= k && m <= i; ++m) {
            s -= l[i * bw + m] * l[i * bw + m];
        }
        l[i * bw] = std::sqrt(std::max(s, 1e-300));
    }
    std::vector<double> y(n);
    for (std::size_t i = 0; i < n; ++i) {
        double s = w[i] * e[i];
        for (std::size_t d = 1; d <= k && d <= i; ++d) {
            s -= l[i * bw + d] * y[i - d];
        }
        y[i] = s / l[i * bw];
    }
    std::vector<double> c(n);
    for (std::size_t i = n; i-- > 0;) {
        double s = y[i];
        for (std::size_t d = 1; d <= k && i + d < n; ++d) {
            s -= l[(i + d) * bw + d] * c[i + d];
        }
        c[i] = s / l[i * bw];
    }
    return c;
}

// The penalty's scale, so that the lambda grid is dimensionless: trace(W) / trace(P).
double lambdaScale(const std::vector<double>& w, const Penalty& pen)
{
    double trP = 0.0;
    for (std::size_t j = 0; j < pen.rows.size(); ++j) {
        for (double q : pen.rows[j]) {
            trP += pen.length[j] * q * q;
        }
    }
    const double trW = std::accumulate(w.begin(), w.end(), 0.0);
    return trP > 0.0 && trW > 0.0 ? trW / trP : 1.0;
}

std::vector<double> lambdaGrid()
{
    std::vector<double> g;
    for (int k = -24; k <= 16; ++k) {
        g.push_back(std::pow(10.0, 0.5 * k));
    }
    return g;
}

// Cubic Hermite through (knots, values) with three-point slopes; constant beyond the ends.
double hermite(const std::vector<double>& k, const std::vector<double>& v, double t)
{
    const std::size_t n = k.size();
    if (n == 0) {
        return 0.0;
    }
    if (n == 1 || !(t > k.front())) {
        return v.front();
    }
    if (t >= k.back()) {
        return v.back();
    }
    auto slope = [&](std::size_t i) {
        if (i == 0) {
            return (v[1] - v[0]) / (k[1] - k[0]);
        }
        if (i + 1 == n) {
            return (v[n - 1] - v[n - 2]) / (k[n - 1] - k[n - 2]);
        }
        const double h0 = k[i] - k[i - 1];
        const double h1 = k[i + 1] - k[i];
        return ((v[i + 1] - v[i]) / h1 * h0 + (v[i] - v[i - 1]) / h0 * h1) / (h0 + h1);
    };
    const auto it = std::upper_bound(k.begin(), k.end(), t);
    const std::size_t i = static_cast<std::size_t>(it - k.begin()) - 1;
    const double h = k[i + 1] - k[i];
    const double s = (t - k[i]) / h;
    const double s2 = s * s;
    const double s3 = s2 * s;
    return (2 * s3 - 3 * s2 + 1) * v[i] + (s3 - 2 * s2 + s) * h * slope(i) +
           (-2 * s3 + 3 * s2) * v[i + 1] + (s3 - s2) * h * slope(i + 1);
}

struct Sorted {
    std::vector<std::size_t> order; // sorted index -> sample index
    std::vector<double> count;
    std::vector<double> x;
    std::vector<double> v;
    std::vector<double> w;
};

// The GOGO's linearised domain: y = g^-1((v - offset) / scale) with g(y) = sign(y) |y|^gamma, in
// which the GOG part is the straight line max(gain x + 1 - gain, 0).
double linearise(const std::array<double, 4>& p, double v)
{
    const double q = (v - p[3]) / p[0];
    return q >= 0.0 ? std::pow(q, 1.0 / p[2]) : -std::pow(-q, 1.0 / p[2]);
}

double delinearise(const std::array<double, 4>& p, double y)
{
    return p[3] + p[0] * (y >= 0.0 ? std::pow(y, p[2]) : -std::pow(-y, p[2]));
}

double linearBase(const std::array<double, 4>& p, double x)
{
    return std::max(p[1] * x + (1.0 - p[1]), 0.0);
}

// dy/dv, with |v - offset| held above 1e-4 of the scale so that a reading at black keeps a finite
// (tiny) weight instead of an infinite slope.
double lineariseSlope(const std::array<double, 4>& p, double v)
{
    const double q = std::max(std::abs((v - p[3]) / p[0]), 1e-4);
    return std::pow(q, 1.0 / p[2] - 1.0) / (p[2] * p[0]);
}

// The residual of v from the GOGO in the linearised domain, and its weights (the value domain's
// weights through the slope).
void linearisedResidual(const std::array<double, 4>& p,
                        const std::vector<double>& x,
                        const std::vector<double>& v,
                        const std::vector<double>& w,
                        std::vector<double>& e,
                        std::vector<double>& wl)
{
    e.resize(x.size());
    wl.resize(x.size());
    for (std::size_t i = 0; i < x.size(); ++i) {
        e[i] = linearise(p, v[i]) - linearBase(p, x[i]);
        const double d = lineariseSlope(p, v[i]);
        wl[i] = w[i] / (d * d);
    }
}

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
    ToneFit fit;
    fit.maxCount = maxCount;
    fit.knots = s.count;
    const std::size_t n = s.x.size();
    if (o.forceShape && o.lambda >= 0.0 && o.warmStart) {
        // A refit of nearby data with everything fixed but the values: one least-squares fit from
        // the previous parameters.
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
    const std::array<double, 4> start = gogoStart(s.x, s.v);
    const std::array<double, 4> gog = fitGogo(s.x, s.v, s.w, ToneShape::Gog, start);
    const std::array<double, 4> gogoAll = fitGogo(s.x, s.v, s.w, ToneShape::Gogo, gog);

    const auto grid = lambdaGrid();
    // Which spline kinds take part: forcing the value-domain or the linearised spline keeps to
    // its domain; 'order' keeps to one penalty.
    auto kindUsed = [&](const SplineKind& k) {
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
    };
    std::vector<std::vector<double>> cvErr(2 + kSplineKinds.size() * grid.size(),
                                           std::vector<double>(n, 0.0));
    const bool cv = !(o.forceShape &&
                      ((o.shape != ToneShape::Spline && o.shape != ToneShape::LinearisedSpline) ||
                       o.lambda >= 0.0));
    std::vector<Penalty> penalties;
    for (const SplineKind& kind : kSplineKinds) {
        penalties.push_back(kindUsed(kind) ? penaltyRows(s.x, kind.order) : Penalty{});
    }
    if (cv) {
        // Interleaved folds over the levels between the end points (black and full drive stay
        // in every training set: leaving them out would test extrapolation).
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
            const auto pg = fitGogo(s.x, s.v, w, ToneShape::Gog, gog);
            const auto po = fitGogo(s.x, s.v, w, ToneShape::Gogo, gogoAll);
            std::vector<double> e(n);
            for (std::size_t i = 0; i < n; ++i) {
                e[i] = s.v[i] - gogoEval(po, s.x[i], ToneShape::Gogo);
            }
            std::vector<double> el;
            std::vector<double> wl;
            linearisedResidual(po, s.x, s.v, w, el, wl);
            for (std::size_t i : out) {
                cvErr[0][i] = s.v[i] - gogoEval(pg, s.x[i], ToneShape::Gog);
                cvErr[1][i] = e[i];
            }
            for (std::size_t ki = 0; ki < kSplineKinds.size(); ++ki) {
                const SplineKind& kind = kSplineKinds[ki];
                if (!kindUsed(kind)) {
                    continue;
                }
                const auto& ee = kind.linearised ? el : e;
                const auto& ww = kind.linearised ? wl : w;
                const Penalty& pen = penalties[ki];
                const double scale = lambdaScale(ww, pen);
                for (std::size_t k = 0; k < grid.size(); ++k) {
                    const auto c = smoothSpline(s.x, ee, ww, grid[k] * scale, kind.order, pen);
                    for (std::size_t i : out) {
                        cvErr[2 + ki * grid.size() + k][i] =
                                kind.linearised
                                        ? s.v[i] - delinearise(po, linearBase(po, s.x[i]) + c[i])
                                        : e[i] - c[i];
                    }
                }
            }
        }
    }
    auto score = [&](std::size_t row) {
        double acc = 0.0;
        for (std::size_t i = 0; i < n; ++i) {
            acc += s.w[i] * cvErr[row][i] * cvErr[row][i];
        }
        return acc;
    };
    // The best smoothing and order of each domain.
    std::array<std::size_t, 2> bestRow{0, 0};
    std::array<double, 2> bestScore{std::numeric_limits<double>::infinity(),
                                    std::numeric_limits<double>::infinity()};
    for (std::size_t ki = 0; ki < kSplineKinds.size(); ++ki) {
        if (!kindUsed(kSplineKinds[ki])) {
            continue;
        }
        const std::size_t d = kSplineKinds[ki].linearised ? 1 : 0;
        for (std::size_t k = 0; k < grid.size(); ++k) {
            const std::size_t r = 2 + ki * grid.size() + k;
            const double sc = score(r);
            if (sc < bestScore[d]) {
                bestScore[d] = sc;
                bestRow[d] = r;
            }
        }
    }
    // The standard error of the difference between two rows' scores (paired over the samples):
    // a row within 'oneSe' of them of the best is not told apart from it by these readings.
    auto scoreSe = [&](std::size_t a, std::size_t b) {
        double sum = 0.0;
        double sum2 = 0.0;
        for (std::size_t i = 0; i < n; ++i) {
            const double d = s.w[i] * (cvErr[a][i] * cvErr[a][i] - cvErr[b][i] * cvErr[b][i]);
            sum += d;
            sum2 += d * d;
        }
        const double nn = static_cast<double>(n);
        return std::sqrt(std::max(0.0, sum2 - sum * sum / nn) * nn / std::max(nn - 1.0, 1.0));
    };
    fit.cvScore = {score(0), score(1), bestScore[0], bestScore[1]};
    const std::size_t bestDomain = bestScore[1] < bestScore[0] ? 1 : 0;
    ToneShape shape = bestDomain == 1 ? ToneShape::LinearisedSpline : ToneShape::Spline;
    std::size_t row = bestRow[bestDomain];
    auto rowKind = [&](std::size_t r) { return kSplineKinds[(r - 2) / grid.size()]; };
    auto rowLambda = [&](std::size_t r) { return grid[(r - 2) % grid.size()]; };
    if (o.forceShape) {
        shape = o.shape;
        if (shape == ToneShape::Gog || shape == ToneShape::Gogo) {
            row = shape == ToneShape::Gog ? 0 : 1;
        } else {
            row = bestRow[shape == ToneShape::LinearisedSpline ? 1 : 0];
        }
    } else {
        // The simplest shape within 2 % (and within the one-standard-error rule) of the best
        // cross-validated error.
        double scale = 0.0;
        for (std::size_t i = 0; i < n; ++i) {
            scale += s.w[i] * s.v[i] * s.v[i];
        }
        std::size_t bestAll = row;
        for (std::size_t r : {std::size_t{1}, std::size_t{0}}) {
            if (score(r) < score(bestAll)) {
                bestAll = r;
            }
        }
        const double best = score(bestAll);
        auto within = [&](std::size_t r) {
            return score(r) <= best * 1.02 + 1e-24 * scale ||
                   score(r) <= best + o.oneSe * scoreSe(r, bestAll);
        };
        if (within(0)) {
            shape = ToneShape::Gog;
            row = 0;
        } else if (within(1)) {
            shape = ToneShape::Gogo;
            row = 1;
        }
    }
    const bool spline = shape == ToneShape::Spline || shape == ToneShape::LinearisedSpline;
    double lambda = 0.0;
    int order = o.order != 0 ? o.order : 2;
    if (spline && row >= 2) {
        lambda = rowLambda(row);
        order = rowKind(row).order;
    }
    if (o.forceShape && o.lambda >= 0.0) {
        lambda = o.lambda;
    }
    fit.shape = shape;
    fit.lambda = spline ? lambda : 0.0;
    fit.order = order;
    std::vector<double> corr;
    fitFixed(s, s.w, shape, lambda, order, shape == ToneShape::Gog ? gog : gogoAll, fit.gogo, corr);
    if (shape == ToneShape::Gog) {
        fit.gogo[3] = 0.0;
    }
    fit.correction = corr;
    fit.residual.assign(n, 0.0);
    fit.cvResidual.assign(n, 0.0);
    for (std::size_t i = 0; i < n; ++i) {
        const double r = s.v[i] - fit(s.count[i]);
        fit.residual[s.order[i]] = r;
        fit.cvResidual[s.order[i]] = cv && i > 0 ? cvErr[row][i] : r;
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
