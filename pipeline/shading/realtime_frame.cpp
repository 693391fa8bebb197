// The CPU model's frame (renderRealtime): the grids, then every pixel's eq. (1)-(3) with the
// screen flare subtracted, rows split over threads.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <thread>
#include <vector>

#include <glm/geometric.hpp>

#include <pipeline/shading/frame.h>
#include <pipeline/shading/realtime_model.h>
#include <pipeline/shading/wall_field.h>

namespace replica::pipeline::shading {
namespace {

// Rows [0, rows) split over 'threads': f(thread, first row, end row).
template <class F>
void inParallel(int threads, int rows, const F& f)
{
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t) {
        pool.emplace_back(f, t, rows * t / threads, rows * (t + 1) / threads);
    }
    for (auto& th : pool) {
        th.join();
    }
}

// One frame of renderRealtime: what every pixel and grid node shares, and the passes in order.
class RealtimeFrame
{
public:
    RealtimeFrame(const PreparedScene& ps,
                  const PreparedLight& light,
                  const View& view,
                  const colour::Observer& obs,
                  const RenderSettings& settings)
        : ps_(ps), scene_(*ps.scene), light_(light), view_(view), obs_(obs), settings_(settings),
          relief_(settings.reliefPass && !ps.normals.empty()),
          specular_(settings.specularPass && scene_.glossy()),
          normals_(relief_ ? ps.normals : none_),
          // The GL pass's half-float horizons: the same rounded sines here.
          horizon_(relief_ && settings.horizonDirections > 0 ? &ps.horizonHalf : nullptr),
          nl_(light.light->normal()), texelArea_(light.light->texelAreaM2()),
          // Eq. (1) from the regions' areas or from their centroids (RenderSettings::areaLights).
          diffuse_(settings.areaLights ? areaLightIrradiance : pointLightIrradiance),
          specXyz_(colour::spectrumToXyz(obs, scene_.rhoS * light.unitSpd)),
          threads_(std::clamp(settings.threads, 1, std::max(view.pixelsY, 1)))
    {}

    XyzFrame render()
    {
        XyzFrame frame;
        frame.width = view_.pixelsX;
        frame.height = view_.pixelsY;
        frame.xyz.assign(static_cast<std::size_t>(frame.width) *
                                 static_cast<std::size_t>(frame.height),
                         colour::Xyz(0.0));
        // The grids first, every node (as the GL pass's modes 2 and 3 do).
        specularNodes_ = specular_ ? gridNodes(scene_, settings_.specularGrid) : GridNodes{};
        specularGrid_ = gridValues(specularNodes_, [&](const ShadingPoint& sp) {
            const Vec3 toEye = towardEye(sp);
            return glm::dot(toEye, sp.nGeo) > 0.0 ? specularAt(sp, toEye) : 0.0;
        });
        diffuseNodes_ = gridNodes(scene_, settings_.diffuseGrid);
        diffuseGrid_ = gridValues(diffuseNodes_, [&](const ShadingPoint& sp) {
            return diffuse_(light_.points, nl_, texelArea_, withMacroNormal(sp), nullptr, 0.0,
                            false);
        });
        // On relief the grid also holds eq. (1) with the node's facet and horizons (the GL's
        // mode 3 writes both into one RG32F texel).
        diffuseReliefGrid_ =
                relief_ ? gridValues(diffuseNodes_,
                                     [&](const ShadingPoint& sp) {
                                         return diffuse_(light_.points, nl_, texelArea_, sp,
                                                         horizon_, settings_.horizonSoftness, true);
                                     })
                        : std::vector<double>{};
        if (settings_.walls && light_.walls != nullptr) {
            walls_ = wallField(*light_.walls, view_.panel, scene_);
        }
        std::vector<Counts> counts(static_cast<std::size_t>(threads_));
        inParallel(threads_, frame.height, [&](int t, int y0, int y1) {
            for (int py = y0; py < y1; ++py) {
                for (int px = 0; px < frame.width; ++px) {
                    frame.xyz[static_cast<std::size_t>(py) * frame.width + px] =
                            pixel(px, py, counts[static_cast<std::size_t>(t)]);
                }
            }
        });
        for (const auto& c : counts) {
            frame.flareClamped += c.flare;
            frame.eyeBehindPixels += c.behind;
            frame.nonFinite += c.bad;
        }
        frame.whiteY = panelWhiteY(light_, view_.panel, settings_.areaLights);
        if (walls_) {
            frame.whiteY += walls_->whiteLux / std::numbers::pi;
        }
        frame.whiteXyz = light_.white * frame.whiteY;
        return frame;
    }

private:
    struct Counts {
        long flare = 0, behind = 0, bad = 0;
    };

    // The unit vector from a shading point to the eye (the macro normal with the eye on it).
    Vec3 towardEye(const ShadingPoint& sp) const
    {
        const Vec3 toEye = view_.eye - sp.p;
        const double eyeDist = glm::length(toEye);
        return eyeDist > 0.0 ? toEye / eyeDist : sp.nGeo;
    }

    // The specular term (rho_s = 1) seen along toEye.
    double specularAt(const ShadingPoint& sp, const Vec3& toEye) const
    {
        return filteredSpecular(light_, sp, toEye, scene_.model, scene_.alpha,
                                settings_.specularSamples, horizon_, settings_.horizonSoftness,
                                settings_.specularLodBias, settings_.specularNearestLevel);
    }

    // f at every node of a grid (none for {0, 0}), non-finite values as 0.
    template <class F>
    std::vector<double> gridValues(GridNodes nodes, const F& f) const
    {
        std::vector<double> values(static_cast<std::size_t>(nodes.x) *
                                   static_cast<std::size_t>(nodes.y));
        if (nodes.x == 0) {
            return values;
        }
        inParallel(threads_, nodes.y, [&](int, int j0, int j1) {
            for (int j = j0; j < j1; ++j) {
                for (int i = 0; i < nodes.x; ++i) {
                    const ShadingPoint sp = shadingPointAt(view_, scene_, normals_,
                                                           static_cast<double>(i) / (nodes.x - 1),
                                                           static_cast<double>(j) / (nodes.y - 1));
                    const double v = f(sp);
                    values[static_cast<std::size_t>(j) * static_cast<std::size_t>(nodes.x) +
                           static_cast<std::size_t>(i)] = std::isfinite(v) ? v : 0.0;
                }
            }
        });
        return values;
    }

    // Eq. (1)-(2), the specular term and the flare subtracted, at pixel (px, py).
    colour::Xyz pixel(int px, int py, Counts& c) const
    {
        const ShadingPoint sp = shadingPoint(view_, scene_, normals_, px, py);
        const Vec3 toEye = towardEye(sp);
        const bool behind = !(glm::dot(toEye, sp.nGeo) > 0.0);
        c.behind += behind ? 1 : 0;
        const double u = (px + 0.5) / view_.pixelsX;
        const double v = (py + 0.5) / view_.pixelsY;
        double eGeo = diffuseNodes_.x > 0 ? gridValue(diffuseGrid_, diffuseNodes_, u, v)
                                          : diffuse_(light_.points, nl_, texelArea_,
                                                     withMacroNormal(sp), nullptr, 0.0, false);
        double e = eGeo;
        if (relief_) {
            // Eq. (1)'s horizons bilinear at the pixel's point on the surface, or between the
            // grid's nodes, where they were taken at each node's point.
            e = diffuseNodes_.x > 0 ? gridValue(diffuseReliefGrid_, diffuseNodes_, u, v)
                                    : diffuse_(light_.points, nl_, texelArea_, sp, horizon_,
                                               settings_.horizonSoftness, true);
        }
        if (walls_) {
            const double wallGeo = wallFieldAt(*walls_, u, v, sp.nGeo, sp.nGeo);
            e += relief_ ? wallFieldAt(*walls_, u, v, sp.nGeo, sp.nShade) : wallGeo;
            eGeo += wallGeo;
        }
        if (!settings_.diffusePass) {
            e = 0.0;
        }
        colour::Xyz xyz(0.0);
        if (settings_.channels == ChannelRep::Basis6) {
            const colour::ChannelCoeffs cc = scene_.channels(ps_.paletteCoeffs, sp.tx, sp.ty);
            for (std::size_t k = 0; k < colour::kChannels; ++k) {
                xyz += light_.channelXyz[k] * cc[k];
            }
            xyz *= e / std::numbers::pi;
        } else {
            xyz = colour::spectrumToXyz(obs_, scene_.reflectance(sp.tx, sp.ty) * light_.unitSpd) *
                  (e / std::numbers::pi);
        }
        if (specular_ && specularNodes_.x > 0) {
            xyz += specXyz_ * gridValue(specularGrid_, specularNodes_, u, v);
        } else if (specular_ && !behind) {
            xyz += specXyz_ * specularAt(sp, toEye);
        }
        const colour::Xyz flare = light_.white * (kScreenFlareRho * eGeo / std::numbers::pi);
        colour::Xyz out = subtractFlare(xyz, flare, c.flare);
        if (!std::isfinite(out.x) || !std::isfinite(out.y) || !std::isfinite(out.z)) {
            ++c.bad;
            out = colour::Xyz(0.0);
        }
        return out;
    }

    const std::vector<Vec3> none_;
    const PreparedScene& ps_;
    const surface::SurfaceScene& scene_;
    const PreparedLight& light_;
    const View& view_;
    const colour::Observer& obs_;
    const RenderSettings& settings_;
    const bool relief_;
    const bool specular_;
    const std::vector<Vec3>& normals_;
    const surface::HorizonMap* horizon_;
    const Vec3 nl_;
    const double texelArea_;
    decltype(&pointLightIrradiance) diffuse_;
    const colour::Xyz specXyz_;
    const int threads_;
    GridNodes specularNodes_, diffuseNodes_;
    std::vector<double> specularGrid_, diffuseGrid_, diffuseReliefGrid_;
    std::optional<WallField> walls_;
};

} // namespace

XyzFrame renderRealtime(const PreparedScene& ps,
                        const PreparedLight& light,
                        const View& view,
                        const colour::Observer& obs,
                        const RenderSettings& settings)
{
    return RealtimeFrame(ps, light, view, obs, settings).render();
}

} // namespace replica::pipeline::shading
