// A channel's tone response: digital count -> radiometric scalar, from measured ramp points, made
// monotone and interpolated with a shape-preserving cubic (Fritsch-Carlson), plus its inverse.
#pragma once

#include <cstddef>
#include <vector>

namespace replica::pipeline::display {

class ToneCurve
{
public:
    ToneCurve() = default;
    // counts strictly increasing; values non-decreasing (the caller enforces it with
    // poolAdjacentViolators). Both the same length, at least 2.
    ToneCurve(std::vector<double> counts, std::vector<double> values);

    // Value at a real-valued count; constant beyond the first and last knot.
    double operator()(double count) const;
    // The smallest count whose value reaches r (bisection on the monotone curve: no division by a
    // slope, so a flat toe near black cannot blow up). r below the first value gives the first
    // count, above the last value the last count.
    double inverse(double r) const;

    const std::vector<double>& counts() const { return counts_; }
    const std::vector<double>& values() const { return values_; }
    bool empty() const { return counts_.empty(); }

private:
    std::vector<double> counts_;
    std::vector<double> values_;
    std::vector<double> slopes_; // Fritsch-Carlson tangents at the knots
};

// The least-squares non-decreasing fit to v (pool adjacent violators, equal weights).
std::vector<double> poolAdjacentViolators(const std::vector<double>& v);

} // namespace replica::pipeline::display
