// The booth shading pass's compose: a frame from the cached eye-independent part and this eye's
// specular term, minus the screen's front-surface flare.
#pragma once

#include <GLES3/gl31.h>

#include <pipeline/render/booth_diffuse_cache.h>
#include <pipeline/render/booth_programs.h>
#include <pipeline/render/booth_specular.h>
#include <pipeline/render/pixel_rect.h>
#include <pipeline/shading/view.h>

namespace replica::pipeline::render {

// Where a frame goes: a framebuffer of width x height pixels, 'rect' the surface's part of it.
struct BoothFrameTarget {
    GLuint framebuffer = 0;
    PixelRect rect;
    int width = 0;
    int height = 0;
};

// Draws the frame into 'target': the cache copied whole (around the surface (0, 0, 0) and E_geo)
// and, when 'shadeSurface' (a specular term or flare to add), the surface's rectangle composed by
// mode 1 at 'panel': the cached part, the specular term (per pixel or from the grid), minus the
// flare. Leaves the target's framebuffer bound.
void composeBoothFrame(const BoothPrograms& programs,
                       const BoothDiffuseCache& cache,
                       const BoothSpecular& specular,
                       const BoothFrameTarget& target,
                       const shading::PanelPose& panel,
                       bool shadeSurface);

} // namespace replica::pipeline::render
