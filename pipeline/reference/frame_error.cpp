// CIELAB and CIEDE2000 in double.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include <pipeline/reference/frame_error.h>

namespace replica::pipeline::reference {
namespace {

double labF(double t)
{
    constexpr double kEps = 216.0 / 24389.0;
    constexpr double kKappa = 24389.0 / 27.0;
    return t > kEps ? std::cbrt(t) : (kKappa * t + 16.0) / 116.0;
}

double deg(double r)
{
    return r * 180.0 / std::numbers::pi;
}

double rad(double d)
{
    return d * std::numbers::pi / 180.0;
}

} // namespace

Lab xyzToLab(const colour::Xyz& xyz, const colour::Xyz& white)
{
    if (!(white.x > 0.0 && white.y > 0.0 && white.z > 0.0)) {
        return Lab{};
    }
    const double fx = labF(xyz.x / white.x);
    const double fy = labF(xyz.y / white.y);
    const double fz = labF(xyz.z / white.z);
    return Lab{116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)};
}

double ciede2000(const Lab& x, const Lab& y)
{
    const double c1 = std::hypot(x.a, x.b);
    const double c2 = std::hypot(y.a, y.b);
    const double cBar = 0.5 * (c1 + c2);
    const double cBar7 = std::pow(cBar, 7.0);
    const double g = 0.5 * (1.0 - std::sqrt(cBar7 / (cBar7 + std::pow(25.0, 7.0))));
    const double a1 = (1.0 + g) * x.a;
    const double a2 = (1.0 + g) * y.a;
    const double cp1 = std::hypot(a1, x.b);
    const double cp2 = std::hypot(a2, y.b);
    const auto hue = [](double b, double a) {
        if (a == 0.0 && b == 0.0) {
            return 0.0;
        }
        double h = deg(std::atan2(b, a));
        return h < 0.0 ? h + 360.0 : h;
    };
    const double hp1 = hue(x.b, a1);
    const double hp2 = hue(y.b, a2);
    const double dL = y.l - x.l;
    const double dC = cp2 - cp1;
    double dh = 0.0;
    if (cp1 * cp2 != 0.0) {
        dh = hp2 - hp1;
        if (dh > 180.0) {
            dh -= 360.0;
        } else if (dh < -180.0) {
            dh += 360.0;
        }
    }
    const double dH = 2.0 * std::sqrt(cp1 * cp2) * std::sin(rad(dh) / 2.0);
    const double lBar = 0.5 * (x.l + y.l);
    const double cpBar = 0.5 * (cp1 + cp2);
    double hBar = hp1 + hp2;
    if (cp1 * cp2 != 0.0) {
        if (std::abs(hp1 - hp2) <= 180.0) {
            hBar = 0.5 * (hp1 + hp2);
        } else if (hp1 + hp2 < 360.0) {
            hBar = 0.5 * (hp1 + hp2 + 360.0);
        } else {
            hBar = 0.5 * (hp1 + hp2 - 360.0);
        }
    }
    const double t = 1.0 - 0.17 * std::cos(rad(hBar - 30.0)) + 0.24 * std::cos(rad(2.0 * hBar)) +
                     0.32 * std::cos(rad(3.0 * hBar + 6.0)) -
                     0.20 * std::cos(rad(4.0 * hBar - 63.0));
    const double dTheta = 30.0 * std::exp(-((hBar - 275.0) / 25.0) * ((hBar - 275.0) / 25.0));
    const double cpBar7 = std::pow(cpBar, 7.0);
    const double rc = 2.0 * std::sqrt(cpBar7 / (cpBar7 + std::pow(25.0, 7.0)));
    const double l50 = (lBar - 50.0) * (lBar - 50.0);
    const double sl = 1.0 + 0.015 * l50 / std::sqrt(20.0 + l50);
    const double sc = 1.0 + 0.045 * cpBar;
    const double sh = 1.0 + 0.015 * cpBar * t;
    const double rt = -std::sin(rad(2.0 * dTheta)) * rc;
    const double tl = dL / sl;
    const double tc = dC / sc;
    const double th = dH / sh;
    return std::sqrt(std::max(tl * tl + tc * tc + th * th + rt * tc * th, 0.0));
}

FrameError compareFrames(const shading::XyzFrame& reference, const shading::XyzFrame& test)
{
    FrameError e;
    const std::size_t n = std::min(reference.xyz.size(), test.xyz.size());
    if (n == 0) {
        return e;
    }
    std::vector<double> d(n);
    double sum = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
        d[k] = ciede2000(xyzToLab(reference.xyz[k], reference.whiteXyz),
                         xyzToLab(test.xyz[k], reference.whiteXyz));
        sum += d[k];
    }
    e.mean = sum / static_cast<double>(n);
    std::sort(d.begin(), d.end());
    e.max = d.back();
    e.p95 = d[std::min(n - 1,
                       static_cast<std::size_t>(std::ceil(0.95 * static_cast<double>(n))) - 1)];
    return e;
}

} // namespace replica::pipeline::reference
