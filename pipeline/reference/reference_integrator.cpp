// Reference integration over every light texel, spectral per pixel.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <thread>
#include <tuple>
#include <utility>

#include <glm/geometric.hpp>

#include <pipeline/reference/reference_integrator.h>
#include <pipeline/reference/wall_radiosity.h>

namespace replica::pipeline::reference {

TexelCloud texelCloud(const booth::BoothLight& light)
{
    TexelCloud c;
    c.normal = light.normal();
    c.texelAreaM2 = light.texelAreaM2();
    for (int y = 0; y < light.luminance.height; ++y) {
        for (int x = 0; x < light.luminance.width; ++x) {
            const double l = light.luminance.at(x, y);
            if (l > 0.0) {
                c.position.push_back(light.pointAtTexel(x + 0.5, y + 0.5));
                c.cdM2.push_back(l);
            }
        }
    }
    return c;
}

TexelSums integrateTexels(const TexelCloud& light,
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
    TexelSums s;
    const double a = light.texelAreaM2;
    for (std::size_t k = 0; k < light.position.size(); ++k) {
        Vec3 d = light.position[k] - p;
        const double d2 = glm::dot(d, d);
        if (!(d2 > 0.0)) {
            continue; // the point is the texel centre: direction undefined, no contribution
        }
        d /= std::sqrt(d2);
        const double d2c = std::max(d2, a); // at most one texel's worth of solid angle per texel
        const double cosL = -glm::dot(light.normal, d);
        const double cosG = glm::dot(nGeo, d);
        if (!(cosL > 0.0) || !(cosG > 0.0)) {
            continue;
        }
        const double l = light.cdM2[k];
        const double dw = a * cosL / d2c;
        s.geoIrradiance += l * cosG * dw;
        const double cosS = glm::dot(nShade, d);
        if (!(cosS > 0.0)) {
            continue;
        }
        if (!aboveHorizon(sinHorizonByAzimuth, d, cosG, right, up)) {
            continue; // below the relief's horizon
        }
        s.irradiance += l * cosS * dw;
        if (specular) {
            s.specular += l * brdf::wardEval(model, alpha, nShade, d, toEye) * cosS * dw;
        }
    }
    return s;
}

namespace {

// What every pixel of a reference frame shares: the light's texels, its unit-luminance spectrum
// and white, the scene's normal map; and the per-pixel evaluation itself (renderReference's
// frame and referenceAt's samples both go through pixel()).
struct PixelCounts {
    long flare = 0, behind = 0, bad = 0;
};

class PixelReference
{
public:
    PixelReference(const surface::SurfaceScene& scene,
                   const booth::BoothLight& light,
                   const shading::View& view,
                   const colour::Observer& obs,
                   const ReferenceOptions& options)
        : scene_(scene), view_(view), obs_(obs), options_(options), cloud_(texelCloud(light)),
          unitSpd_(booth::unitLuminanceSpd(obs, light.spd)),
          white_(colour::spectrumToXyz(obs, unitSpd_)), flat_(scene.flat()),
          normals_(flat_ ? std::vector<Vec3>{} : surface::normalMap(scene.relief)),
          glossy_(scene.glossy())
    {}

    const std::vector<Vec3>& normals() const { return normals_; }
    std::size_t horizonSize() const
    {
        return static_cast<std::size_t>(flat_ ? 0 : options_.horizonAzimuths);
    }

    // The exact XYZ at one shading point; 'horizon' is scratch of horizonSize() entries.
    colour::Xyz
    pixel(const shading::ShadingPoint& sp, std::vector<double>& horizon, PixelCounts& c) const
    {
        for (std::size_t k = 0; k < horizon.size(); ++k) {
            const double phi = 2.0 * std::numbers::pi * static_cast<double>(k) /
                               static_cast<double>(horizon.size());
            horizon[k] = surface::exactSinHorizon(scene_.relief, sp.texX, sp.texY, phi,
                                                  options_.horizonDistanceM);
        }
        Vec3 toEye = view_.eye - sp.p;
        const double eyeDist = glm::length(toEye);
        toEye = eyeDist > 0.0 ? toEye / eyeDist : sp.nGeo;
        const bool behind = !(glm::dot(toEye, sp.nGeo) > 0.0);
        c.behind += behind ? 1 : 0;
        const TexelSums t =
                integrateTexels(cloud_, sp.p, sp.nGeo, sp.nShade, toEye, scene_.model, scene_.alpha,
                                glossy_ && !behind, flat_ ? nullptr : &horizon, sp.right, sp.up);
        const colour::Spectrum rho = scene_.reflectance(sp.tx, sp.ty);
        colour::Spectrum radiance =
                (rho * (t.irradiance / std::numbers::pi) + scene_.rhoS * t.specular) * unitSpd_;
        double geoIrradiance = t.geoIrradiance;
        if (options_.walls != nullptr) {
            const WallSums w = integrateWalls(*options_.walls, sp.p, sp.nGeo, sp.nShade, toEye,
                                              scene_.model, scene_.alpha, glossy_ && !behind,
                                              flat_ ? nullptr : &horizon, sp.right, sp.up);
            radiance = radiance +
                       (rho * w.irradiance * (1.0 / std::numbers::pi) + scene_.rhoS * w.specular) *
                               unitSpd_;
            geoIrradiance += w.geoIrradianceY;
        }
        const colour::Xyz surfaceXyz = colour::spectrumToXyz(obs_, radiance);
        const colour::Xyz flare =
                white_ * (shading::kScreenFlareRho * geoIrradiance / std::numbers::pi);
        colour::Xyz out = shading::subtractFlare(surfaceXyz, flare, c.flare);
        if (!std::isfinite(out.x) || !std::isfinite(out.y) || !std::isfinite(out.z)) {
            ++c.bad;
            out = colour::Xyz(0.0);
        }
        return out;
    }

    // A perfect diffuser at the panel centre: the frame's Lab white, and its Y.
    std::pair<colour::Xyz, double> white() const
    {
        const Vec3 n = view_.panel.normal;
        const TexelSums centre =
                integrateTexels(cloud_, view_.panel.centre, n, n, n, scene_.model, scene_.alpha,
                                false, nullptr, view_.panel.right, view_.panel.up);
        double e = centre.geoIrradiance;
        if (options_.walls != nullptr) {
            e += integrateWalls(*options_.walls, view_.panel.centre, n, n, n, scene_.model,
                                scene_.alpha, false, nullptr, view_.panel.right, view_.panel.up)
                         .geoIrradianceY;
        }
        const double y = e / std::numbers::pi;
        return {white_ * y, y};
    }

private:
    const surface::SurfaceScene& scene_;
    const shading::View& view_;
    const colour::Observer& obs_;
    const ReferenceOptions& options_;
    TexelCloud cloud_;
    colour::Spectrum unitSpd_;
    colour::Xyz white_;
    bool flat_;
    std::vector<Vec3> normals_;
    bool glossy_;
};

} // namespace

shading::XyzFrame renderReference(const surface::SurfaceScene& scene,
                                  const booth::BoothLight& light,
                                  const shading::View& view,
                                  const colour::Observer& obs,
                                  const ReferenceOptions& options)
{
    shading::XyzFrame frame;
    frame.width = view.pixelsX;
    frame.height = view.pixelsY;
    frame.xyz.assign(static_cast<std::size_t>(frame.width) * static_cast<std::size_t>(frame.height),
                     colour::Xyz(0.0));
    const PixelReference ref(scene, light, view, obs, options);
    const auto renderRows = [&](int y0, int y1, PixelCounts& c) {
        std::vector<double> horizon(ref.horizonSize());
        for (int py = y0; py < y1; ++py) {
            for (int px = 0; px < frame.width; ++px) {
                const shading::ShadingPoint sp =
                        shading::shadingPoint(view, scene, ref.normals(), px, py);
                frame.xyz[static_cast<std::size_t>(py) * frame.width + px] =
                        ref.pixel(sp, horizon, c);
            }
        }
    };
    const int threads = std::clamp(options.threads, 1, std::max(frame.height, 1));
    std::vector<PixelCounts> counts(static_cast<std::size_t>(threads));
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t) {
        const int y0 = frame.height * t / threads;
        const int y1 = frame.height * (t + 1) / threads;
        pool.emplace_back(renderRows, y0, y1, std::ref(counts[static_cast<std::size_t>(t)]));
    }
    for (auto& th : pool) {
        th.join();
    }
    for (const auto& c : counts) {
        frame.flareClamped += c.flare;
        frame.eyeBehindPixels += c.behind;
        frame.nonFinite += c.bad;
    }
    std::tie(frame.whiteXyz, frame.whiteY) = ref.white();
    return frame;
}

ReferenceSamples referenceAt(const surface::SurfaceScene& scene,
                             const booth::BoothLight& light,
                             const shading::View& view,
                             const colour::Observer& obs,
                             const std::vector<SurfaceSample>& points,
                             const ReferenceOptions& options,
                             const std::function<bool()>& stop)
{
    const PixelReference ref(scene, light, view, obs, options);
    ReferenceSamples out;
    out.xyz.reserve(points.size());
    std::vector<double> horizon(ref.horizonSize());
    PixelCounts c;
    for (const auto& p : points) {
        if (stop && stop()) {
            break;
        }
        const shading::ShadingPoint sp =
                shading::shadingPointAt(view, scene, ref.normals(), p.u, p.v, p.texel);
        out.xyz.push_back(ref.pixel(sp, horizon, c));
    }
    std::tie(out.whiteXyz, out.whiteY) = ref.white();
    return out;
}

double
polygonIrradiance(const std::vector<Vec3>& corners, const Vec3& p, const Vec3& n, double luminance)
{
    double sum = 0.0;
    const std::size_t m = corners.size();
    for (std::size_t k = 0; k < m; ++k) {
        const Vec3 a = glm::normalize(corners[k] - p);
        const Vec3 b = glm::normalize(corners[(k + 1) % m] - p);
        const Vec3 c = glm::cross(a, b);
        const double len = glm::length(c);
        if (!(len > 0.0)) {
            continue;
        }
        const double angle = std::atan2(len, glm::dot(a, b));
        sum += angle * glm::dot(n, c / len);
    }
    return 0.5 * luminance * std::abs(sum);
}

} // namespace replica::pipeline::reference
