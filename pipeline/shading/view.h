// The viewing set-up in the booth frame: panel pose from the stand's tilt, eye position, and the
// per-pixel shading point (position, geometric and normal-mapped normals) on the virtual surface.
#pragma once

#include <optional>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <pipeline/brdf/ward.h>
#include <pipeline/scene/stand.h>
#include <pipeline/surface/surface_scene.h>

namespace replica::pipeline::shading {

using Vec3 = glm::dvec3;

// The panel's pose (scene::PanelPose, from the stand's hinge model by scene::panelPose): the
// surface is shown at its physical size, centred on the panel's active area.
using scene::PanelPose;

struct View {
    PanelPose panel;
    Vec3 eye{0.0, 0.45, 0.60}; // scene::SceneState's default eye
    int pixelsX = 96;
    int pixelsY = 60;
};

// What one pixel sees: the point on the surface and its frame.
struct ShadingPoint {
    Vec3 p{0.0};
    Vec3 nGeo{0.0, 0.0, 1.0};
    Vec3 nShade{0.0, 0.0, 1.0};
    Vec3 right{1.0, 0.0, 0.0}; // macro tangent frame (for horizon azimuths)
    Vec3 up{0.0, 1.0, 0.0};
    double texX = 0.0; // fractional texel coordinates in the scene
    double texY = 0.0;
    int tx = 0;
    int ty = 0;
};

// The pixel grid covers the whole surface. normals: the scene's normal map (bilinear,
// renormalised); empty means flat.
ShadingPoint shadingPoint(const View& view,
                          const surface::SurfaceScene& scene,
                          const std::vector<Vec3>& normals,
                          int px,
                          int py);
// The same at surface coordinates (u, v) in [0, 1]^2 (v down the surface): what a pixel centre
// maps to, or a node of the specular grid. The texel position is 'texel' when given, else
// (u, v) times the texels.
ShadingPoint shadingPointAt(const View& view,
                            const surface::SurfaceScene& scene,
                            const std::vector<Vec3>& normals,
                            double u,
                            double v,
                            const std::optional<glm::dvec2>& texel = std::nullopt);

// sp with its facet normal set to the macro normal: eq. (1) without the relief.
inline ShadingPoint withMacroNormal(ShadingPoint sp)
{
    sp.nShade = sp.nGeo;
    return sp;
}

// Whether the eye is at or behind the surface's plane at sp, as renderRealtime decides it (its
// specular term is then 0 and the pixel counted in XyzFrame::eyeBehindPixels).
bool eyeBehind(const View& view, const ShadingPoint& sp);

// Bilinear interpolation of a normal map at fractional texel coordinates, renormalised (never zero:
// every stored normal has z > 0).
Vec3 sampleNormal(const std::vector<Vec3>& normals, int w, int h, double x, double y);

} // namespace replica::pipeline::shading
