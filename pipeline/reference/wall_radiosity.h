// The booth's walls in the exact reference: their radiosity under one lamp solved to convergence
// (patches, Gauss-Seidel, band by band), and the light they send to a point of the surface.
#pragma once

#include <vector>

#include <pipeline/booth/booth_light.h>
#include <pipeline/booth/booth_walls.h>
#include <pipeline/brdf/ward.h>
#include <pipeline/colour/xyz.h>

namespace replica::pipeline::reference {

using Vec3 = glm::dvec3;

struct WallSolveOptions {
    double patchM = 0.05;     // the patches' largest side
    int subsamples = 2;       // per patch side: the lamp's direct light averaged over n x n points
    double tolerance = 1e-12; // stop once an update moves no radiance by more than this (relative)
    int maxIterations = 10000;
};

// Solves l = rho / pi (E + K l) for every band of 'reflectance', with K_jk the projected solid
// angle of patch k from patch j's centre (exact, Lambert's formula) and E_j the patch's direct
// irradiance (lux, relative to the lamp's unit-luminance SPD 'unitSpd'). Patches must face each
// other from the inside of a convex box (booth::wallPatches). Exposed for the closed-box test.
booth::WallLight solveRadiosity(std::vector<booth::WallPatch> patches,
                                const std::vector<double>& directIrradiance,
                                const colour::Spectrum& reflectance,
                                const colour::Spectrum& unitSpd,
                                const colour::Observer& obs,
                                const WallSolveOptions& options = {});

// The walls lit by the lamp's every texel (the reference's texel sums), solved.
booth::WallLight solveWalls(const booth::BoothWalls& walls,
                            const booth::BoothLight& lamp,
                            const colour::Observer& obs,
                            const WallSolveOptions& options = {});

// The walls' light at p: 'irradiance' the spectral irradiance (relative to the lamp's
// unit-luminance SPD, as WallLight::radiance) on the facet nShade from the part of each patch above
// both horizons, each patch shadowed by the relief's horizon along its centre's direction;
// 'geoIrradianceY' the illuminance (lux) on the bare panel (nGeo), for the flare and the white;
// 'specular' the Ward lobe (rho_s = 1) over the patches, each taken at its centre's direction.
struct WallSums {
    colour::Spectrum irradiance{};
    double geoIrradianceY = 0.0;
    colour::Spectrum specular{};
};

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
                        const Vec3& up);

// Whether the unit direction d (cosG = nGeo . d) clears the relief's horizon: the sine table by
// azimuth in (right, up), linear between its entries; true without a table.
bool aboveHorizon(const std::vector<double>* sinHorizonByAzimuth,
                  const Vec3& d,
                  double cosG,
                  const Vec3& right,
                  const Vec3& up);

} // namespace replica::pipeline::reference
