// Monotone tone curves.
#include <algorithm>
#include <cmath>

#include <pipeline/base/assert.h>
#include <pipeline/display/tone_curve.h>

namespace replica::pipeline::display {

ToneCurve::ToneCurve(std::vector<double> counts, std::vector<double> values)
    : counts_(std::move(counts)), values_(std::move(values))
{
    REPLICA_ASSERT(counts_.size() == values_.size() && counts_.size() >= 2,
                   "tone curve needs matching knots, at least two");
    const std::size_t n = counts_.size();
    std::vector<double> secant(n - 1);
    for (std::size_t i = 0; i + 1 < n; ++i) {
        const double h = counts_[i + 1] - counts_[i];
        REPLICA_ASSERT(h > 0.0, "tone curve knots must be strictly increasing");
        secant[i] = (values_[i + 1] - values_[i]) / h;
    }
    // Fritsch & Carlson (1980): start from the mean secant, zero at flat steps and extrema, and
    // limit alpha^2 + beta^2 <= 9 so the cubic never overshoots (stays monotone).
    slopes_.assign(n, 0.0);
    slopes_[0] = secant[0];
    slopes_[n - 1] = secant[n - 2];
    for (std::size_t i = 1; i + 1 < n; ++i) {
        slopes_[i] = secant[i - 1] * secant[i] <= 0.0 ? 0.0 : 0.5 * (secant[i - 1] + secant[i]);
    }
    for (std::size_t i = 0; i + 1 < n; ++i) {
        if (secant[i] == 0.0) {
            slopes_[i] = 0.0;
            slopes_[i + 1] = 0.0;
            continue;
        }
        const double a = slopes_[i] / secant[i];
        const double b = slopes_[i + 1] / secant[i];
        const double s = a * a + b * b;
        if (s > 9.0) {
            const double tau = 3.0 / std::sqrt(s);
            slopes_[i] = tau * a * secant[i];
            slopes_[i + 1] = tau * b * secant[i];
        }
    }
}

double ToneCurve::operator()(double count) const
{
    if (counts_.empty()) {
        return 0.0;
    }
    if (!(count > counts_.front())) { // also catches NaN
        return values_.front();
    }
    if (count >= counts_.back()) {
        return values_.back();
    }
    const auto it = std::upper_bound(counts_.begin(), counts_.end(), count);
    const std::size_t i = static_cast<std::size_t>(it - counts_.begin()) - 1;
    const double h = counts_[i + 1] - counts_[i];
    const double t = (count - counts_[i]) / h;
    const double t2 = t * t;
    const double t3 = t2 * t;
    return (2 * t3 - 3 * t2 + 1) * values_[i] + (t3 - 2 * t2 + t) * h * slopes_[i] +
           (-2 * t3 + 3 * t2) * values_[i + 1] + (t3 - t2) * h * slopes_[i + 1];
}

double ToneCurve::inverse(double r) const
{
    if (counts_.empty()) {
        return 0.0;
    }
    if (!(r > values_.front())) {
        return counts_.front();
    }
    if (r >= values_.back()) {
        // The first knot reaching the top (a flat shoulder returns its start).
        const auto it = std::lower_bound(values_.begin(), values_.end(), values_.back());
        return counts_[static_cast<std::size_t>(it - values_.begin())];
    }
    // Segment whose end value first reaches r, then bisection inside it (the cubic is monotone).
    const auto it = std::lower_bound(values_.begin(), values_.end(), r);
    const std::size_t hi = static_cast<std::size_t>(it - values_.begin());
    double lo = counts_[hi - 1];
    double up = counts_[hi];
    for (int k = 0; k < 60 && up - lo > 1e-12 * (1.0 + up); ++k) {
        const double mid = 0.5 * (lo + up);
        if ((*this)(mid) < r) {
            lo = mid;
        } else {
            up = mid;
        }
    }
    return 0.5 * (lo + up);
}

std::vector<double> poolAdjacentViolators(const std::vector<double>& v)
{
    // Blocks of (mean, size); merge backwards while the order is violated.
    std::vector<double> mean;
    std::vector<std::size_t> size;
    for (double x : v) {
        mean.push_back(x);
        size.push_back(1);
        while (mean.size() > 1 && mean[mean.size() - 2] > mean.back()) {
            const std::size_t n1 = size[size.size() - 2];
            const std::size_t n2 = size.back();
            const double m = (mean[mean.size() - 2] * static_cast<double>(n1) +
                              mean.back() * static_cast<double>(n2)) /
                             static_cast<double>(n1 + n2);
            mean.pop_back();
            size.pop_back();
            mean.back() = m;
            size.back() = n1 + n2;
        }
    }
    std::vector<double> out;
    out.reserve(v.size());
    for (std::size_t b = 0; b < mean.size(); ++b) {
        out.insert(out.end(), size[b], mean[b]);
    }
    return out;
}

} // namespace replica::pipeline::display
