// CCT by golden-section search for the nearest Planckian chromaticity in (u, v).
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include <pipeline/colour/cct.h>

namespace replica::pipeline::colour {
namespace {

constexpr double kMinK = 1000.0;
constexpr double kMaxK = 100000.0;
constexpr double kMaxDuv = 0.05;

Uv locusUv(const Observer& obs, double kelvin)
{
    return xyzToUv1960(spectrumToXyz(obs, planckianSpectrum(kelvin)));
}

double distance(const Uv& a, const Uv& b)
{
    return std::hypot(a.u - b.u, a.v - b.v);
}

} // namespace

Spectrum planckianSpectrum(double temperatureK)
{
    // Planck's law without c1 (it cancels in the 560 nm normalisation); lambda in metres.
    auto radiance = [temperatureK](double nm) {
        const double lambda = nm * 1e-9;
        return 1.0 / (std::pow(lambda, 5.0) * std::expm1(kPlanckC2 / (lambda * temperatureK)));
    };
    const double ref = radiance(560.0);
    Spectrum s;
    for (std::size_t i = 0; i < kBands; ++i) {
        s[i] = radiance(bandCentreNm(i)) / ref;
    }
    return s;
}

Uv xyzToUv1960(const Xyz& xyz)
{
    const double d = xyz.x + 15.0 * xyz.y + 3.0 * xyz.z;
    if (!(d > 0.0)) {
        return Uv{};
    }
    return Uv{4.0 * xyz.x / d, 6.0 * xyz.y / d};
}

Expected<Cct> correlatedColourTemperature(const Observer& obs, const Xyz& xyz)
{
    if (!std::isfinite(xyz.x) || !std::isfinite(xyz.y) || !std::isfinite(xyz.z)) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("correlated colour temperature: XYZ ({}, {}, {}) is not "
                                     "finite",
                                     xyz.x, xyz.y, xyz.z));
    }
    if (!(xyz.y > 0.0) || !(xyz.x + 15.0 * xyz.y + 3.0 * xyz.z > 0.0)) {
        return makeError(ErrorCode::InvalidArgument,
                         "correlated colour temperature: the light has no luminance (Y <= 0)");
    }
    const Uv target = xyzToUv1960(xyz);
    // Coarse scan in reciprocal temperature (the locus is nearly uniform in mired), then a
    // golden-section search in the bracketing interval, also in mired.
    constexpr int kSteps = 200;
    const double mLo = 1e6 / kMaxK;
    const double mHi = 1e6 / kMinK;
    int best = 0;
    double bestD = std::numeric_limits<double>::infinity();
    for (int i = 0; i <= kSteps; ++i) {
        const double m = mLo + (mHi - mLo) * i / kSteps;
        const double d = distance(target, locusUv(obs, 1e6 / m));
        if (d < bestD) {
            bestD = d;
            best = i;
        }
    }
    double a = mLo + (mHi - mLo) * std::max(best - 1, 0) / kSteps;
    double b = mLo + (mHi - mLo) * std::min(best + 1, kSteps) / kSteps;
    const double invPhi = (std::sqrt(5.0) - 1.0) / 2.0;
    double c = b - invPhi * (b - a);
    double d = a + invPhi * (b - a);
    double fc = distance(target, locusUv(obs, 1e6 / c));
    double fd = distance(target, locusUv(obs, 1e6 / d));
    while (b - a > 1e-9) {
        if (fc < fd) {
            b = d;
            d = c;
            fd = fc;
            c = b - invPhi * (b - a);
            fc = distance(target, locusUv(obs, 1e6 / c));
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + invPhi * (b - a);
            fd = distance(target, locusUv(obs, 1e6 / d));
        }
    }
    const double mired = 0.5 * (a + b);
    const double kelvin = 1e6 / mired;
    const Uv onLocus = locusUv(obs, kelvin);
    const double dist = distance(target, onLocus);
    // At an end of the search the nearest point may lie beyond it: refused, unless the end itself
    // is nearer than just past it (a 1000 K radiator is at the end, and within the range).
    const bool atEnd = mired <= mLo + 1e-6 || mired >= mHi - 1e-6;
    const double beyondMired = mired <= mLo + 1e-6 ? mLo - 1e-3 : mHi + 1e-3;
    if (atEnd && distance(target, locusUv(obs, 1e6 / beyondMired)) < dist) {
        return makeError(
                ErrorCode::InvalidArgument,
                fmt::format("correlated colour temperature: chromaticity (u={:.4f}, v={:.4f}) lies "
                            "beyond the {}-{} K range of the search",
                            target.u, target.v, kMinK, kMaxK));
    }
    if (dist > kMaxDuv) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("correlated colour temperature: chromaticity (u={:.4f}, "
                                     "v={:.4f}) is {:.4f} "
                                     "from the Planckian locus; CCT is undefined beyond {}",
                                     target.u, target.v, dist, kMaxDuv));
    }
    // Sign of Duv (ANSI C78.377): positive above the locus. With temperature rising the locus runs
    // towards smaller u and v, so the normal (tv, -tu) of the tangent (tu, tv) points to larger v.
    const Uv ahead = locusUv(obs, 1e6 / (mired - 1e-3));
    const double tu = ahead.u - onLocus.u;
    const double tv = ahead.v - onLocus.v;
    const double side = tv * (target.u - onLocus.u) - tu * (target.v - onLocus.v);
    return Cct{kelvin, side >= 0.0 ? dist : -dist};
}

} // namespace replica::pipeline::colour
