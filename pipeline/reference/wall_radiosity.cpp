// Radiosity of the booth's walls and their light at a point.
#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>

#include <pipeline/reference/reference_integrator.h>
#include <pipeline/reference/wall_radiosity.h>
#include <pipeline/shading/realtime_model.h>
#include <pipeline/surface/relief.h>

namespace replica::pipeline::reference {
namespace {

// K_jk: the projected solid angle of patch k seen from patch j's centre (row by row).
std::vector<double> formFactors(const std::vector<booth::WallPatch>& patches)
{
    const std::size_t n = patches.size();
    std::vector<double> k(n * n, 0.0);
    for (std::size_t j = 0; j < n; ++j) {
        const Vec3 p = patches[j].centre();
        for (std::size_t i = 0; i < n; ++i) {
            if (i == j) {
                continue;
            }
            const auto c = patches[i].corners();
            k[j * n + i] = polygonIrradiance({c.begin(), c.end()}, p, patches[j].normal, 1.0);
        }
    }
    return k;
}

// Gauss-Seidel on l = r / pi (E + K l) for one reflectance r; returns the iterations.
int solveBand(const std::vector<double>& k,
              const std::vector<double>& e,
              double r,
              const WallSolveOptions& options,
              std::vector<double>& l,
              double& residual)
{
    const std::size_t n = e.size();
    l.assign(n, 0.0);
    residual = 0.0;
    if (!(r > 0.0)) {
        return 0;
    }
    for (int it = 1; it <= options.maxIterations; ++it) {
        double change = 0.0;
        double largest = 0.0;
        for (std::size_t j = 0; j < n; ++j) {
            double sum = e[j];
            for (std::size_t i = 0; i < n; ++i) {
                sum += k[j * n + i] * l[i];
            }
            const double next = r / std::numbers::pi * sum;
            change = std::max(change, std::abs(next - l[j]));
            largest = std::max(largest, std::abs(next));
            l[j] = next;
        }
        residual = largest > 0.0 ? change / largest : 0.0;
        if (residual <= options.tolerance) {
            return it;
        }
    }
    return options.maxIterations;
}

} // namespace

booth::WallLight solveRadiosity(std::vector<booth::WallPatch> patches,
                                const std::vector<double>& directIrradiance,
                                const colour::Spectrum& reflectance,
                                const colour::Spectrum& unitSpd,
                                const colour::Observer& obs,
                                const WallSolveOptions& options)
{
    booth::WallLight out;
    out.patches = std::move(patches);
    const std::size_t n = out.patches.size();
    out.radiance.assign(n, colour::Spectrum{});
    const std::vector<double> k = formFactors(out.patches);
    // Bands of equal reflectance share one solve (all of them for a neutral wall).
    std::vector<std::size_t> solved;
    std::vector<double> l;
    for (std::size_t b = 0; b < colour::kBands; ++b) {
        const auto same = std::find_if(solved.begin(), solved.end(), [&](std::size_t s) {
            return reflectance[s] == reflectance[b];
        });
        if (same != solved.end()) {
            for (std::size_t j = 0; j < n; ++j) {
                out.radiance[j][b] = out.radiance[j][*same];
            }
            continue;
        }
        double residual = 0.0;
        out.iterations = std::max(out.iterations, solveBand(k, directIrradiance, reflectance[b],
                                                            options, l, residual));
        out.residual = std::max(out.residual, residual);
        for (std::size_t j = 0; j < n; ++j) {
            out.radiance[j][b] = l[j];
        }
        solved.push_back(b);
    }
    out.luminance.resize(n);
    for (std::size_t j = 0; j < n; ++j) {
        out.luminance[j] = colour::spectrumToXyz(obs, out.radiance[j] * unitSpd).y;
    }
    return out;
}

booth::WallLight solveWalls(const booth::BoothWalls& walls,
                            const booth::BoothLight& lamp,
                            const colour::Observer& obs,
                            const WallSolveOptions& options)
{
    std::vector<booth::WallPatch> patches = booth::wallPatches(walls, options.patchM);
    const TexelCloud cloud = texelCloud(lamp);
    const int m = std::max(options.subsamples, 1);
    std::vector<double> e(patches.size(), 0.0);
    for (std::size_t j = 0; j < patches.size(); ++j) {
        const booth::WallPatch& q = patches[j];
        const Vec3 right = glm::normalize(q.u);
        const Vec3 up = glm::normalize(q.v);
        double sum = 0.0;
        for (int b = 0; b < m; ++b) {
            for (int a = 0; a < m; ++a) {
                const Vec3 p = q.origin + (a + 0.5) / m * q.u + (b + 0.5) / m * q.v;
                sum += integrateTexels(cloud, p, q.normal, q.normal, q.normal,
                                       brdf::WardModel::WardDurGuarded, 0.1, false, nullptr, right,
                                       up)
                               .geoIrradiance;
            }
        }
        e[j] = sum / (m * m);
    }
    return solveRadiosity(std::move(patches), e, walls.reflectance,
                          booth::unitLuminanceSpd(obs, lamp.spd), obs, options);
}

bool aboveHorizon(const std::vector<double>* sinHorizonByAzimuth,
                  const Vec3& d,
                  double cosG,
                  const Vec3& right,
                  const Vec3& up)
{
    const int azimuths =
            sinHorizonByAzimuth != nullptr ? static_cast<int>(sinHorizonByAzimuth->size()) : 0;
    if (azimuths == 0) {
        return true;
    }
    return cosG > surface::atAzimuth(sinHorizonByAzimuth->data(), azimuths, glm::dot(d, right),
                                     glm::dot(d, up));
}

WallSums integrateWalls(const booth::WallLight& walls,
                        const Vec3& p,
                        const Vec3& nGeo,
                        const Vec3& nShade,
                        const Vec3& toEye,
                        brdf::WardModel model,
                        double alpha,
                        bool specular,
                        const std::vector<double>* sinHorizonByAzimuth,
                        const Vec3& right,
                        const Vec3& up)
{
    WallSums s;
    const bool facet = nShade != nGeo;
    for (std::size_t k = 0; k < walls.patches.size(); ++k) {
        const booth::WallPatch& q = walls.patches[k];
        if (!(glm::dot(q.normal, p - q.origin) > 0.0)) {
            continue; // behind the wall or in its plane
        }
        const auto c = q.corners();
        Vec3 v[4];
        for (int i = 0; i < 4; ++i) {
            v[i] = c[static_cast<std::size_t>(i)] - p;
        }
        Vec3 geo[shading::kMaxClippedVertices];
        const int ng = shading::clipToHorizon(v, 4, nGeo, geo);
        if (ng == 0) {
            continue;
        }
        const double omegaGeo = shading::projectedSolidAngle(geo, ng, nGeo);
        s.geoIrradianceY += omegaGeo * walls.luminance[k];
        double omega = omegaGeo;
        if (facet) {
            Vec3 both[shading::kMaxClippedVertices];
            const int nb = shading::clipToHorizon(geo, ng, nShade, both);
            omega = nb == 0 ? 0.0 : shading::projectedSolidAngle(both, nb, nShade);
        }
        const Vec3 d = glm::normalize(q.centre() - p);
        if (!(omega > 0.0) || !aboveHorizon(sinHorizonByAzimuth, d, glm::dot(nGeo, d), right, up)) {
            continue;
        }
        s.irradiance = s.irradiance + walls.radiance[k] * omega;
        if (specular) {
            s.specular =
                    s.specular +
                    walls.radiance[k] * (brdf::wardEval(model, alpha, nShade, d, toEye) * omega);
        }
    }
    return s;
}

} // namespace replica::pipeline::reference
