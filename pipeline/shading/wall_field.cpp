// The walls' light on the panel for the real-time renderer.
#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>

#include <pipeline/shading/realtime_model.h>
#include <pipeline/shading/wall_field.h>

namespace replica::pipeline::shading {
namespace {

// Lagrange weights of 0, 1/2, 1 at t.
std::array<double, 3> quadraticWeights(double t)
{
    return {2.0 * (t - 0.5) * (t - 1.0), -4.0 * t * (t - 1.0), 2.0 * t * (t - 0.5)};
}

} // namespace

double wallIrradiance(const booth::WallLight& walls, const Vec3& p, const Vec3& n, Vec3* vector)
{
    double e = 0.0;
    for (std::size_t k = 0; k < walls.patches.size(); ++k) {
        const booth::WallPatch& q = walls.patches[k];
        if (!(glm::dot(q.normal, p - q.origin) > 0.0)) {
            continue;
        }
        const auto c = q.corners();
        Vec3 v[4];
        for (int i = 0; i < 4; ++i) {
            v[i] = c[static_cast<std::size_t>(i)] - p;
        }
        Vec3 clipped[kMaxClippedVertices];
        const int m = clipToHorizon(v, 4, n, clipped);
        if (m == 0) {
            continue;
        }
        e += walls.luminance[k] * projectedSolidAngle(clipped, m, n);
        if (vector != nullptr) {
            // 1/2 sum of the edges' angle times their unit normals, pointing into n's side.
            Vec3 phi(0.0);
            for (int i = 0; i < m; ++i) {
                const Vec3 a = clipped[i];
                const Vec3 b = clipped[(i + 1) % m];
                const Vec3 x = glm::cross(a, b);
                const double len = glm::length(x);
                if (len > 0.0) {
                    phi += x * (std::atan2(len, glm::dot(a, b)) / len);
                }
            }
            phi *= 0.5;
            *vector += walls.luminance[k] * (glm::dot(phi, n) < 0.0 ? -phi : phi);
        }
    }
    return e;
}

WallField
wallField(const booth::WallLight& walls, const PanelPose& panel, const surface::SurfaceScene& scene)
{
    WallField f;
    View view;
    view.panel = panel;
    const std::vector<Vec3> flat;
    for (int j = 0; j < 3; ++j) {
        for (int i = 0; i < 3; ++i) {
            const ShadingPoint sp = shadingPointAt(view, scene, flat, 0.5 * i, 0.5 * j);
            f.nodes[static_cast<std::size_t>(3 * j + i)] =
                    wallIrradiance(walls, sp.p, sp.nGeo, i == 1 && j == 1 ? &f.vector : nullptr);
        }
    }
    f.whiteLux = wallIrradiance(walls, view.panel.centre, view.panel.normal, nullptr);
    return f;
}

double wallsWhiteY(const booth::WallLight* walls, const PanelPose& panel, bool on)
{
    if (!on || walls == nullptr) {
        return 0.0;
    }
    return wallIrradiance(*walls, panel.centre, panel.normal, nullptr) / std::numbers::pi;
}

double wallFieldAt(const WallField& f, double u, double v, const Vec3& nGeo, const Vec3& nShade)
{
    const auto wu = quadraticWeights(std::clamp(u, 0.0, 1.0));
    const auto wv = quadraticWeights(std::clamp(v, 0.0, 1.0));
    double e = 0.0;
    for (std::size_t j = 0; j < 3; ++j) {
        for (std::size_t i = 0; i < 3; ++i) {
            e += wv[j] * wu[i] * f.nodes[3 * j + i];
        }
    }
    if (nShade != nGeo) {
        e += glm::dot(f.vector, nShade - nGeo);
    }
    return std::max(e, 0.0);
}

} // namespace replica::pipeline::shading
