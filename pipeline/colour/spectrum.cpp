// Working-grid spectra and band-integrating resampling.
#include <algorithm>
#include <cmath>

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
