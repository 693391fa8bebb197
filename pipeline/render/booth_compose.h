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

// Draws the frame into framebuffer 'target' (width x height): the cache copied whole (around the
// surface (0, 0, 0) and E_geo) and, when 'shadeSurface' (a specular term or flare to add), the
// surface's rectangle 'rect' composed by mode 1 at 'panel': the cached part, the specular term
// (per pixel or from the grid), minus the flare. Leaves 'target' bound.
void composeBoothFrame(const BoothPrograms& programs,
                       const BoothDiffuseCache& cache,
                       const BoothSpecular& specular,
                       GLuint target,
                       const PixelRect& rect,
                       int width,
                       int height,
                       const shading::PanelPose& panel,
                       bool shadeSurface);

} // namespace replica::pipeline::render
