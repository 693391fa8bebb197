// The exact CPU reference: double precision, full 36-band spectra, every texel of the luminance
// image with the exact BRDF and horizon visibility from the height field. Slow, simple, obviously
// right.
#pragma once

#include <functional>
#include <vector>

#include <glm/vec2.hpp>

#include <pipeline/booth/booth_light.h>
#include <pipeline/booth/booth_walls.h>
#include <pipeline/colour/xyz.h>
#include <pipeline/shading/frame.h>
#include <pipeline/shading/view.h>
#include <pipeline/surface/surface_scene.h>

namespace replica::pipeline::reference {

using Vec3 = glm::dvec3;

struct ReferenceOptions {
    double horizonDistanceM = 0.01; // how far the exact horizon march reaches
    int horizonAzimuths = 360;      // per-pixel exact horizon resolution (1 degree)
    int threads = 2;
    // The booth's walls lit by this light (reference::solveWalls), or none: their light is added
    // to every pixel (diffuse and specular), to the flare and to the white. Not owned.
    const booth::WallLight* walls = nullptr;
};

// The emitter's texels with non-zero luminance, as points in the booth frame.
struct TexelCloud {
    std::vector<Vec3> position;
    std::vector<double> cdM2;
    Vec3 normal{0.0, -1.0, 0.0};
    double texelAreaM2 = 0.0;
};

TexelCloud texelCloud(const booth::BoothLight& light);

// Irradiance (lux) at p on a facet with normal n from every texel: sum L a cos_l cos_s / d^2, d^2
// clamped at one texel area (a point touching the emitter gets a bounded contribution). visibility,
// if given, returns 0/1 for a unit direction.
struct TexelSums {
    double irradiance = 0.0;    // lux, shading normal, horizon applied
    double specular = 0.0;      // cd/m^2 for rho_s = 1
    double geoIrradiance = 0.0; // lux on the bare panel (geometric normal, no relief): for flare
};

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
                          const Vec3& up);

// Renders the whole frame. Needs the observer for the spectral-to-XYZ step.
shading::XyzFrame renderReference(const surface::SurfaceScene& scene,
                                  const booth::BoothLight& light,
                                  const shading::View& view,
                                  const colour::Observer& obs,
                                  const ReferenceOptions& options = {});

// One point of the surface to evaluate: surface (u, v) in [0, 1]^2 (v down the surface) and its
// fractional texel position (what a frame's pixel centre maps to: shading::shadingPointAt).
struct SurfaceSample {
    double u = 0.5;
    double v = 0.5;
    glm::dvec2 texel{0.0};
};

struct ReferenceSamples {
    std::vector<colour::Xyz> xyz; // one per point, as renderReference computes a pixel
    colour::Xyz whiteXyz{0.0};    // the frame's Lab white (XyzFrame::whiteXyz)
    double whiteY = 0.0;
};

// The exact reference at a list of surface points instead of every pixel: what the running
// appliance's error probe compares a few hundred of its frame's pixels with (renderReference's
// per-pixel code, on the calling thread). 'stop', when given, is asked before each point: once it
// says true the samples end there (xyz shorter than points).
ReferenceSamples referenceAt(const surface::SurfaceScene& scene,
                             const booth::BoothLight& light,
                             const shading::View& view,
                             const colour::Observer& obs,
                             const std::vector<SurfaceSample>& points,
                             const ReferenceOptions& options = {},
                             const std::function<bool()>& stop = {});

// Lambert's contour formula: irradiance at p (normal n) from a uniform Lambertian polygon of
// luminance L: E = L/2 * sum_edges angle_k * (n . unit(v_k x v_{k+1})), with v_k the unit vectors
// to the corners. Exact when the polygon lies wholly above the tangent plane of p.
double
polygonIrradiance(const std::vector<Vec3>& corners, const Vec3& p, const Vec3& n, double luminance);

} // namespace replica::pipeline::reference
