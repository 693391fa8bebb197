// The booth as the box it is: its floor, back and side walls, a diffuse reflectance spectrum, cut
// into patches; and the light they pass on to the surface once solved (reference::solveWalls).
#pragma once

#include <array>
#include <vector>

#include <pipeline/booth/booth_light.h>
#include <pipeline/colour/spectrum.h>

namespace replica::pipeline::booth {

// Munsell N7's luminous reflectance (CIE Y 43.06 %, ASTM D1535's value 7), the neutral grey booth
// walls are painted: taken as spectrally flat.
inline constexpr double kMunsellN7Reflectance = 0.4306;

// The box in the booth frame (scene/booth.h: origin on the floor at the booth's centre, y up, z
// towards the viewer): floor y = boxMin.y, back wall z = boxMin.z, side walls x = boxMin.x and
// boxMax.x. The front (z = boxMax.z) is open towards the viewer and the ceiling (y = boxMax.y) is
// the emitter, taken as black (its diffuser's reflectance is not in the booth data).
struct BoothWalls {
    Vec3 boxMin{0.0};
    Vec3 boxMax{0.0};
    colour::Spectrum reflectance{};
};

// The walls of the booth whose ceiling is 'ceiling': the box under the ceiling's rectangle down to
// the floor (y = 0), painted N7, its back wall at the ceiling's back edge or at backZ, whichever
// is further back (the booth data give the ceiling, not the booth's depth: the appliance puts the
// back wall behind the furthest its panel reaches, scene::defaultBoothWalls).
BoothWalls defaultWalls(const BoothLight& ceiling, double backZ = 1e300);

// One rectangle of a wall: origin + s u + t v for s, t in [0, 1]; normal = cross(u, v), unit,
// into the booth.
struct WallPatch {
    Vec3 origin{0.0};
    Vec3 u{0.0};
    Vec3 v{0.0};
    Vec3 normal{0.0};
    double areaM2 = 0.0;
    Vec3 centre() const { return origin + 0.5 * (u + v); }
    std::array<Vec3, 4> corners() const { return {origin, origin + u, origin + u + v, origin + v}; }
};

// The four walls (floor, back, left, right) cut into patches of at most patchM on a side.
std::vector<WallPatch> wallPatches(const BoothWalls& walls, double patchM);

// The walls lit by one lamp, solved: each patch's radiance relative to the lamp's unit-luminance
// SPD (unitLuminanceSpd): the patch's spectral radiance is radiance[k] * unitSpd, band by band,
// so that for spectrally flat walls every band holds the patch's luminance (cd/m^2).
struct WallLight {
    std::vector<WallPatch> patches;
    std::vector<colour::Spectrum> radiance;
    std::vector<double> luminance; // cd/m^2: radiance[k] * unitSpd weighted by ybar
    int iterations = 0;            // of the radiosity solve
    double residual = 0.0;         // its last update, relative to the largest radiance
    bool empty() const { return patches.empty(); }
};

} // namespace replica::pipeline::booth
