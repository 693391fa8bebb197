// CIEDE2000, equation by equation after Sharma, Wu & Dalal, Color Res. Appl. 30(1), 2005.
#include <cmath>
#include <numbers>

#include <pipeline/colour/ciede2000.h>

namespace replica::pipeline::colour {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kPow25To7 = 6103515625.0; // 25^7

double hueDegrees(double b, double a)
{
    if (a == 0.0 && b == 0.0) {
        return 0.0; // eq. 7: hue of a neutral is 0 by definition
    }
    const double h = std::atan2(b, a) / kDeg;
    return h < 0.0 ? h + 360.0 : h;
}

} // namespace

double ciede2000(const Lab& lab1, const Lab& lab2, const Ciede2000Weights& w)
{
    // eq. 2-6: a' rescaled by G, which depends on the mean chroma
    const double c1 = std::hypot(lab1.a, lab1.b);
    const double c2 = std::hypot(lab2.a, lab2.b);
    const double cMean = 0.5 * (c1 + c2);
    const double cMean7 = std::pow(cMean, 7.0);
    const double g = 0.5 * (1.0 - std::sqrt(cMean7 / (cMean7 + kPow25To7)));
    const double a1p = (1.0 + g) * lab1.a;
    const double a2p = (1.0 + g) * lab2.a;
    const double c1p = std::hypot(a1p, lab1.b);
    const double c2p = std::hypot(a2p, lab2.b);
    const double h1p = hueDegrees(lab1.b, a1p);
    const double h2p = hueDegrees(lab2.b, a2p);

    // eq. 8-10: differences; the hue difference is 0 when either chroma is 0
    const double dLp = lab2.L - lab1.L;
    const double dCp = c2p - c1p;
    double dhp = 0.0;
    if (c1p * c2p != 0.0) {
        dhp = h2p - h1p;
        if (dhp > 180.0) {
            dhp -= 360.0;
        } else if (dhp < -180.0) {
            dhp += 360.0;
        }
    }
    const double dHp = 2.0 * std::sqrt(c1p * c2p) * std::sin(0.5 * dhp * kDeg);

    // eq. 12-14: means; the mean hue takes the short way round the circle
    const double lMean = 0.5 * (lab1.L + lab2.L);
    const double cMeanP = 0.5 * (c1p + c2p);
    double hMean = h1p + h2p;
    if (c1p * c2p != 0.0) {
        if (std::abs(h1p - h2p) <= 180.0) {
            hMean *= 0.5;
        } else if (h1p + h2p < 360.0) {
            hMean = 0.5 * (hMean + 360.0);
        } else {
            hMean = 0.5 * (hMean - 360.0);
        }
    }

    // eq. 15-22: weighting functions and the rotation term
    const double t = 1.0 - 0.17 * std::cos((hMean - 30.0) * kDeg) +
                     0.24 * std::cos(2.0 * hMean * kDeg) +
                     0.32 * std::cos((3.0 * hMean + 6.0) * kDeg) -
                     0.20 * std::cos((4.0 * hMean - 63.0) * kDeg);
    const double dTheta = 30.0 * std::exp(-std::pow((hMean - 275.0) / 25.0, 2.0));
    const double cMeanP7 = std::pow(cMeanP, 7.0);
    const double rc = 2.0 * std::sqrt(cMeanP7 / (cMeanP7 + kPow25To7));
    const double l50 = (lMean - 50.0) * (lMean - 50.0);
    const double sl = 1.0 + 0.015 * l50 / std::sqrt(20.0 + l50);
    const double sc = 1.0 + 0.045 * cMeanP;
    const double sh = 1.0 + 0.015 * cMeanP * t;
    const double rt = -std::sin(2.0 * dTheta * kDeg) * rc;

    const double tl = dLp / (w.kL * sl);
    const double tc = dCp / (w.kC * sc);
    const double th = dHp / (w.kH * sh);
    return std::sqrt(tl * tl + tc * tc + th * th + rt * tc * th);
}

} // namespace replica::pipeline::colour
