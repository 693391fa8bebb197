// CIE xyY and CIELAB conversions.
#include <cmath>

#include <fmt/format.h>

#include <pipeline/colour/cielab.h>

namespace replica::pipeline::colour {
namespace {

// CIE 015:2018 eq. 8.3: f(t) = t^(1/3) above epsilon, (kappa t + 16) / 116 below.
double labF(double t)
{
    return t > kLabEpsilon ? std::cbrt(t) : (kLabKappa * t + 16.0) / 116.0;
}

// Inverse of labF: f^3 where that exceeds epsilon, else (116 f - 16) / kappa.
double labFInverse(double f)
{
    const double f3 = f * f * f;
    return f3 > kLabEpsilon ? f3 : (116.0 * f - 16.0) / kLabKappa;
}

} // namespace

std::string Lab::toString() const
{
    return fmt::format("Lab({:.4f}, {:.4f}, {:.4f})", L, a, b);
}

XyY xyzToXyY(const Xyz& xyz, const Xyz& chromaticityOfBlack)
{
    const double sum = xyz.x + xyz.y + xyz.z;
    if (!(std::abs(sum) > 0.0)) {
        const double ws = chromaticityOfBlack.x + chromaticityOfBlack.y + chromaticityOfBlack.z;
        if (!(std::abs(ws) > 0.0)) {
            return XyY{0.0, 0.0, 0.0};
        }
        return XyY{chromaticityOfBlack.x / ws, chromaticityOfBlack.y / ws, 0.0};
    }
    return XyY{xyz.x / sum, xyz.y / sum, xyz.y};
}

Xyz xyYToXyz(const XyY& xyy)
{
    if (!(std::abs(xyy.y) > 0.0)) {
        return Xyz{0.0};
    }
    const double k = xyy.Y / xyy.y;
    return Xyz{xyy.x * k, xyy.Y, (1.0 - xyy.x - xyy.y) * k};
}

Lab xyzToLab(const Xyz& xyz, const Xyz& white)
{
    if (!(white.x > 0.0 && white.y > 0.0 && white.z > 0.0)) {
        return Lab{};
    }
    const double fx = labF(xyz.x / white.x);
    const double fy = labF(xyz.y / white.y);
    const double fz = labF(xyz.z / white.z);
    return Lab{116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)};
}

Xyz labToXyz(const Lab& lab, const Xyz& white)
{
    const double fy = (lab.L + 16.0) / 116.0;
    const double fx = fy + lab.a / 500.0;
    const double fz = fy - lab.b / 200.0;
    // Y comes straight from L* on the linear branch, so that L* < 8 round-trips exactly.
    const double yr = lab.L > kLabKappa * kLabEpsilon ? fy * fy * fy : lab.L / kLabKappa;
    return Xyz{labFInverse(fx) * white.x, yr * white.y, labFInverse(fz) * white.z};
}

} // namespace replica::pipeline::colour
