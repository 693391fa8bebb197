// Working-grid spectra and band-integrating resampling.
#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>

#include <pipeline/colour/spectrum.h>

namespace replica::pipeline::colour {

Spectrum Spectrum::constant(double value)
{
    Spectrum s;
    s.v.fill(value);
    return s;
}

Spectrum Spectrum::operator*(const Spectrum& o) const
{
    Spectrum r;
    for (std::size_t i = 0; i < kBands; ++i) {
        r.v[i] = v[i] * o.v[i];
    }
    return r;
}

Spectrum Spectrum::operator*(double s) const
{
    Spectrum r;
    for (std::size_t i = 0; i < kBands; ++i) {
        r.v[i] = v[i] * s;
    }
    return r;
}

Spectrum Spectrum::operator+(const Spectrum& o) const
{
    Spectrum r;
    for (std::size_t i = 0; i < kBands; ++i) {
        r.v[i] = v[i] + o.v[i];
    }
    return r;
}

double Spectrum::sum() const
{
    double s = 0.0;
    for (double x : v) {
        s += x;
    }
    return s;
}

double Spectrum::max() const
{
    return *std::max_element(v.begin(), v.end());
}

namespace {

// The samples (covering 380..730 nm, increasing) linear between the two around each band centre.
Spectrum valuesAtBandCentres(const SampledSpectrum& s)
{
    const auto& wl = s.wavelengthNm;
    Spectrum out;
    std::size_t i = 0;
    for (std::size_t b = 0; b < kBands; ++b) {
        const double centre = bandCentreNm(b);
        while (i + 1 < wl.size() && wl[i + 1] <= centre) {
            ++i;
        }
        if (wl[i] == centre || i + 1 == wl.size()) {
            out.v[b] = s.value[i];
            continue;
        }
        // wl[i] < centre < wl[i + 1]: strictly increasing, so the span is positive.
        const double t = (centre - wl[i]) / (wl[i + 1] - wl[i]);
        out.v[b] = s.value[i] + t * (s.value[i + 1] - s.value[i]);
    }
    return out;
}

// The samples' piecewise-linear interpolant at lambda, constant beyond the ends (S(375) = S(380)).
double interpolantAt(const SampledSpectrum& s, double lambda)
{
    const auto& wl = s.wavelengthNm;
    if (lambda <= wl.front()) {
        return s.value.front();
    }
    if (lambda >= wl.back()) {
        return s.value.back();
    }
    const auto hi = static_cast<std::size_t>(std::upper_bound(wl.begin(), wl.end(), lambda) -
                                             wl.begin());           // wl[hi - 1] <= lambda < wl[hi]
    const double t = (lambda - wl[hi - 1]) / (wl[hi] - wl[hi - 1]); // increasing: span > 0
    return s.value[hi - 1] + t * (s.value[hi] - s.value[hi - 1]);
}

// The widest gap between samples within (centre - halfBase, centre + halfBase).
double widestGapNear(const std::vector<double>& wl, double centre, double halfBase)
{
    double widest = 0.0;
    for (std::size_t i = 0; i + 1 < wl.size(); ++i) {
        if (wl[i + 1] > centre - halfBase && wl[i] < centre + halfBase) {
            widest = std::max(widest, wl[i + 1] - wl[i]);
        }
    }
    return widest;
}

// The band's triangle integrated against the interpolant, exactly: between consecutive breakpoints
// (the triangle's corners and the samples inside it) both are linear, so Simpson's rule is exact.
double triangleOverInterpolant(const SampledSpectrum& s, double centre, double halfBase)
{
    std::vector<double> at{centre - halfBase, centre, centre + halfBase};
    for (double w : s.wavelengthNm) {
        if (w > centre - halfBase && w < centre + halfBase && w != centre) {
            at.push_back(w);
        }
    }
    std::sort(at.begin(), at.end());
    const auto f = [&](double lambda) {
        return (1.0 - std::abs(lambda - centre) / halfBase) * interpolantAt(s, lambda);
    };
    double integral = 0.0;
    for (std::size_t i = 0; i + 1 < at.size(); ++i) {
        const double a = at[i];
        const double b = at[i + 1];
        integral += (b - a) / 6.0 * (f(a) + 4.0 * f(0.5 * (a + b)) + f(b));
    }
    return integral / halfBase; // the triangle's area
}

} // namespace

Expected<Spectrum>
resampleToWorkingGrid(const SampledSpectrum& s, const std::string& what, GridSampling sampling)
{
    const auto& wl = s.wavelengthNm;
    const std::size_t n = wl.size();
    if (n < 2 || s.value.size() != n) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: needs at least two samples with one value each", what));
    }
    for (std::size_t i = 0; i < n; ++i) {
        if (!std::isfinite(wl[i]) || !std::isfinite(s.value[i])) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("{}: sample {} is not a finite number", what, i));
        }
        if (i > 0 && !(wl[i] > wl[i - 1])) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("{}: wavelengths must increase, but {} nm follows {} nm",
                                         what, wl[i], wl[i - 1]));
        }
    }
    if (wl.front() > kFirstNm || wl.back() < kLastNm) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: covers {}-{} nm but must cover at least {}-{} nm", what,
                                     wl.front(), wl.back(), kFirstNm, kLastNm));
    }

    if (sampling == GridSampling::AtBandCentre) {
        return valuesAtBandCentres(s);
    }
    constexpr double kHalfBaseNm = 10.0;
    Spectrum out;
    for (std::size_t b = 0; b < kBands; ++b) {
        const double centre = bandCentreNm(b);
        // Samples farther apart than the triangle's half base leave bands with one sample in them
        // or none, and the sum below would fill what it lacks with an end's value (a 20 nm D65 put
        // its 300 nm value into 390-530 nm, ΔE00 up to 3.9 on the ColorChecker): there the band is
        // the triangle over the samples' linear interpolant. Finer grids keep the sum, bit for bit.
        if (widestGapNear(wl, centre, kHalfBaseNm) > kHalfBaseNm) {
            out.v[b] = triangleOverInterpolant(s, centre, kHalfBaseNm);
            continue;
        }
        double weighted = 0.0;
        double weightInside = 0.0;
        for (std::size_t i = 0; i < n; ++i) {
            const double dist = std::abs(wl[i] - centre);
            if (dist >= kHalfBaseNm) {
                continue;
            }
            // Each sample stands for the interval halfway to its neighbours.
            const double lo = i > 0 ? 0.5 * (wl[i] - wl[i - 1]) : 0.5 * (wl[1] - wl[0]);
            const double hi = i + 1 < n ? 0.5 * (wl[i + 1] - wl[i]) : 0.5 * (wl[n - 1] - wl[n - 2]);
            const double w = (1.0 - dist / kHalfBaseNm) * (lo + hi);
            weighted += w * s.value[i];
            weightInside += w;
        }
        // The triangle's full discrete weight is its area, kHalfBaseNm. What lies beyond the data
        // takes the nearest edge value (the CIE convention S(375) = S(380)).
        const double missing = std::max(0.0, kHalfBaseNm - weightInside);
        const double edge =
                centre - wl.front() < wl.back() - centre ? s.value.front() : s.value.back();
        out.v[b] = (weighted + missing * edge) / (weightInside + missing);
    }
    return out;
}

} // namespace replica::pipeline::colour
