// The gain-offset-gamma tone models and their linearised domain.
#include <algorithm>
#include <cmath>

#include <pipeline/base/linear_solve.h>
#include <pipeline/offline/display/gogo_model.h>

namespace replica::pipeline::display {
namespace {

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

// dy/dv, with |v - offset| held above 1e-4 of the scale so that a reading at black keeps a finite
// (tiny) weight instead of an infinite slope.
double lineariseSlope(const std::array<double, 4>& p, double v)
{
    const double q = std::max(std::abs((v - p[3]) / p[0]), 1e-4);
    return std::pow(q, 1.0 / p[2] - 1.0) / (p[2] * p[0]);
}

} // namespace

double gogoEval(const std::array<double, 4>& p, double x, ToneShape shape)
{
    const double u = p[1] * x + (1.0 - p[1]);
    const double base = u > 0.0 ? p[0] * std::pow(u, p[2]) : 0.0;
    return shape == ToneShape::Gog ? base : base + p[3];
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

} // namespace replica::pipeline::display
