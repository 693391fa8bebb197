// Ward lobes, Walter sampling and closed-form weights; every division and sqrt is guarded.
#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>

#include <pipeline/brdf/ward.h>

namespace replica::pipeline::brdf {
namespace {

constexpr double kPi = std::numbers::pi;

} // namespace

const char* wardModelName(WardModel m)
{
    switch (m) {
    case WardModel::Ward1992:
        return "ward-1992";
    case WardModel::WardDur:
        return "ward-duer";
    case WardModel::WardDurGuarded:
        return "ward-duer-guarded";
    case WardModel::Gmd:
        return "ward-gmd";
    }
    return "?";
}

Frame Frame::fromNormal(const Vec3& n)
{
    // Duff et al. 2017, "Building an Orthonormal Basis, Revisited": continuous except at n.z = -1.
    const double sign = std::copysign(1.0, n.z);
    const double a = -1.0 / (sign + n.z);
    const double b = n.x * n.y * a;
    Frame f;
    f.t = Vec3(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
    f.b = Vec3(b, sign + n.y * n.y * a, -n.y);
    f.n = n;
    return f;
}

double wardEval(WardModel model, double alpha, const Vec3& n, const Vec3& i, const Vec3& o)
{
    const double ci = glm::dot(n, i);
    const double co = glm::dot(n, o);
    if (!(ci > 0.0) || !(co > 0.0)) {
        return 0.0;
    }
    const Vec3 hSum = i + o;
    const double len2 = glm::dot(hSum, hSum);
    if (!(len2 > 1e-24)) {
        return 0.0; // i = -o: no half vector
    }
    const Vec3 h = hSum / std::sqrt(len2);
    const double hz = glm::dot(n, h);
    const double hz2 = std::max(hz * hz, kMinHz2);
    const double a = std::max(alpha, kMinAlphaEval);
    // tan^2 = (1 - hz^2) / hz^2, written so that a tiny hz underflows exp cleanly to 0.
    const double e = std::exp(-std::max(1.0 - hz2, 0.0) / (hz2 * a * a));
    const double norm = 4.0 * kPi * a * a;
    const double ih = glm::dot(i, h);
    switch (model) {
    case WardModel::Ward1992:
        return e / (norm * std::sqrt(std::max(ci, kMinCosView) * std::max(co, kMinCosView)));
    case WardModel::WardDur:
        return e / (norm * std::max(ci, kMinCosView) * std::max(co, kMinCosView));
    case WardModel::WardDurGuarded:
        return e / (norm * std::max(ci * co, ih * ih * hz2 * hz2));
    case WardModel::Gmd:
        return e / (norm * ih * ih * hz2 * hz2);
    }
    return 0.0;
}

Vec3 sampleWardHalfVectorLocal(double alpha, double u1, double u2)
{
    const double u = std::clamp(u1, kMinU1, 1.0);
    const double tan2 = -alpha * alpha * std::log(u);
    const double cosT = 1.0 / std::sqrt(1.0 + tan2);
    const double sinT = std::sqrt(tan2) * cosT;
    const double phi = 2.0 * kPi * u2;
    return Vec3(sinT * std::cos(phi), sinT * std::sin(phi), cosT);
}

double wardSolidAngleWithoutOh(double alpha, double hz, double u1, int sampleCount)
{
    const double u = std::clamp(u1, kMinU1, 1.0);
    return 4.0 * kPi * alpha * alpha * hz * hz * hz / (static_cast<double>(sampleCount) * u);
}

WardSample sampleWard(WardModel model,
                      double alpha,
                      const Vec3& n,
                      const Vec3& o,
                      double u1,
                      double u2,
                      int sampleCount)
{
    WardSample s;
    const double co = glm::dot(n, o);
    if (!(co > 0.0) || sampleCount <= 0) {
        return s; // viewer at or behind the surface: no reflection
    }
    const Frame frame = Frame::fromNormal(n);
    const Vec3 hl = sampleWardHalfVectorLocal(alpha, u1, u2);
    const Vec3 h = frame.toWorld(hl);
    const double oh = glm::dot(o, h);
    if (!(oh > 0.0)) {
        return s;
    }
    s.i = 2.0 * oh * h - o;
    const double ci = glm::dot(n, s.i);
    if (!(ci > 0.0)) {
        return s;
    }
    const double hz = hl.z;
    const double hz3 = hz * hz * hz;
    switch (model) {
    case WardModel::Ward1992:
        s.weight = ci * oh * hz3 / std::sqrt(std::max(ci, kMinCosView) * std::max(co, kMinCosView));
        break;
    case WardModel::WardDur:
        s.weight = (ci / std::max(ci, kMinCosView)) * oh * hz3 / std::max(co, kMinCosView);
        break;
    case WardModel::WardDurGuarded:
        s.weight = ci * oh * hz3 / std::max(ci * co, oh * oh * hz3 * hz);
        break;
    case WardModel::Gmd:
        s.weight = ci / (oh * hz);
        break;
    }
    s.solidAngle = wardSolidAngleWithoutOh(alpha, hz, u1, sampleCount) * oh;
    s.valid = true;
    return s;
}

double wardAlbedo(WardModel model, double alpha, double thetaDeg, int grid)
{
    const double t = thetaDeg * kPi / 180.0;
    const Vec3 n(0.0, 0.0, 1.0);
    const Vec3 o(std::sin(t), 0.0, std::cos(t));
    double sum = 0.0;
    for (int a = 0; a < grid; ++a) {
        const double u1 = (a + 0.5) / grid;
        for (int b = 0; b < grid; ++b) {
            const double u2 = (b + 0.5) / grid;
            const WardSample s = sampleWard(model, alpha, n, o, u1, u2, grid * grid);
            if (s.valid) {
                sum += s.weight;
            }
        }
    }
    return sum / (static_cast<double>(grid) * grid);
}

double
wardAlbedoQuadrature(WardModel model, double alpha, double thetaDeg, int thetaSteps, int phiSteps)
{
    const double t = thetaDeg * kPi / 180.0;
    const Vec3 n(0.0, 0.0, 1.0);
    const Vec3 o(std::sin(t), 0.0, std::cos(t));
    const double dT = 0.5 * kPi / thetaSteps;
    const double dP = 2.0 * kPi / phiSteps;
    double sum = 0.0;
    for (int a = 0; a < thetaSteps; ++a) {
        const double ti = (a + 0.5) * dT;
        const double st = std::sin(ti);
        const double ct = std::cos(ti);
        for (int b = 0; b < phiSteps; ++b) {
            const double p = (b + 0.5) * dP;
            const Vec3 i(st * std::cos(p), st * std::sin(p), ct);
            sum += wardEval(model, alpha, n, i, o) * ct * st;
        }
    }
    return sum * dT * dP;
}

} // namespace replica::pipeline::brdf
