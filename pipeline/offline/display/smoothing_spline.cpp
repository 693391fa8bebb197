// The smoothing spline under the tone fits.
#include <algorithm>
#include <cmath>
#include <numeric>

#include <pipeline/offline/display/smoothing_spline.h>

namespace replica::pipeline::display {

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

} // namespace replica::pipeline::display
