// The booth's walls in the real-time renderer: their light on the panel baked, each time the
// panel moves, into a few numbers the diffuse term adds. The walls' radiosity is solved once per
// lamp at start-up (reference::solveWalls, booth::WallLight); here only the panel's share of it:
// the illuminance on the macro normal at a few nodes over the surface (biquadratic between
// them) and the walls' vector irradiance at the surface's centre for the relief's facets
// (E(n) ~ E(nGeo) + Phi . (n - nGeo)). No horizon shadowing and no specular reflection of the
// walls (docs/rendering.md, "The booth's walls", measures what that costs).
#pragma once

#include <array>

#include <pipeline/booth/booth_walls.h>
#include <pipeline/shading/view.h>
#include <pipeline/surface/surface_scene.h>

namespace replica::pipeline::shading {

struct WallField {
    std::array<double, 9> nodes{}; // lux at (u, v) in {0, 1/2, 1}^2, row by row (v down)
    Vec3 vector{0.0};              // the walls' vector irradiance at the surface's centre (lux)
    double whiteLux = 0.0;         // on the macro normal at the panel's centre (the white)
};

// The walls' illuminance at p on a surface of normal n (each patch clipped to n's horizon, at
// its Y luminance), and with 'vector' their vector irradiance there.
double wallIrradiance(const booth::WallLight& walls, const Vec3& p, const Vec3& n, Vec3* vector);

// The field for the surface of 'scene' on the panel at 'panel'.
WallField wallField(const booth::WallLight& walls,
                    const PanelPose& panel,
                    const surface::SurfaceScene& scene);

// What the walls add to a frame's white (XyzFrame::whiteY, Y of a perfect diffuser at the panel's
// centre): 0 unless the settings light with walls and the light carries them.
double wallsWhiteY(const booth::WallLight* walls, const PanelPose& panel, bool on);

// The walls' illuminance at surface (u, v) on a facet of normal nShade (nGeo the macro normal).
double wallFieldAt(const WallField& f, double u, double v, const Vec3& nGeo, const Vec3& nShade);

} // namespace replica::pipeline::shading
