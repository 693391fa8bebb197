// Where the surface lies in a booth frame: the layout that maps framebuffer pixels to surface
// (u, v), and the pixel rectangle that can show the surface.
#pragma once

#include <glm/vec2.hpp>

#include <pipeline/render/pixel_rect.h>
#include <pipeline/scene/stand.h>
#include <pipeline/surface/surface_scene.h>

namespace replica::pipeline::render {

// Which part of the surface a framebuffer pixel shows: surface (u, v) = offset + scale * pixel
// (u, v), v down the image; pixels that land outside [0, 1]^2 are black. {0, 0}, {1, 1}: the frame
// covers the surface exactly, as shading::View does.
struct SurfaceLayout {
    glm::dvec2 offset{0.0, 0.0};
    glm::dvec2 scale{1.0, 1.0};
};

// The pixels of a width x height frame that can show the surface, widened by one pixel so that
// the shader's own bounds test decides every edge pixel: outside it the booth pass writes XYZ
// (0, 0, 0), the black panel around the surface. The whole frame for a layout that does not scale.
PixelRect surfaceRect(const SurfaceLayout& layout, int width, int height);

// The pixels of a width x height frame that show the surface for certain: every pixel wholly
// inside its edges (where the shader's bounds test, in float, cannot decide otherwise).
// surfaceRect less its edge pixels: what lies between the two is decided pixel by pixel. Empty for
// a layout that does not scale.
PixelRect surfaceInterior(const SurfaceLayout& layout, int width, int height);

// The surface at its physical size, centred on the panel's active area (the appliance's frame
// covers the whole panel). The matching View's panel centre is the active area's centre.
SurfaceLayout layoutOnPanel(const surface::SurfaceScene& scene, const scene::StandModel& stand);

} // namespace replica::pipeline::render
