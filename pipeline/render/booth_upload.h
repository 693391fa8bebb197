// The booth shading pass's upload helpers (booth_shading_pass.cpp uses them; tests may too):
// textures for the scene, the grids' render targets, and the source of each mode's program.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <GLES3/gl31.h>
#include <glm/vec3.hpp>

#include <pipeline/base/expected.h>
#include <pipeline/brdf/ward.h>
#include <pipeline/render/gl_handles.h>
#include <pipeline/shading/realtime_model.h>

namespace replica::pipeline::render::booth_upload {

// Nearest sampling, clamped to the edge, on the texture bound to 'target'.
void nearest(GLenum target);

// A grid's target: one R32F texel per node, RG32F with 'twoValues' (made on 'unit', so that
// creating it binds over no other input) and a framebuffer that draws into it; an error naming
// 'grid' if not renderable.
Expected<void> nodeTarget(shading::GridNodes nodes,
                          GLint unit,
                          const char* grid,
                          GlTexture& texture,
                          GlFramebuffer& fbo,
                          bool twoValues = false);

// The horizon map as a 2-D array texture: directions [8j, 8j + 8) as half floats in layer j of
// an RGBA32UI array (packHalf2x16's layout). 'dirs' 0: one empty texel.
GlTexture horizonTexture(const surface::HorizonMap& map, int dirs);

glm::vec3 f3(const glm::dvec3& v);

// 2 x the specular mip level bias where the GL pass renders it (the nearest level, a bias of
// whole half levels), else nothing.
std::optional<int> exactLevelTwiceBias(const shading::RenderSettings& s);

// BOOTH_WARD_MODEL's number for a Ward model.
int wardModelIndex(brdf::WardModel m);

// An error naming 'what' if the GL has one pending.
Expected<void> glCheck(const char* what);

// Channel coefficients per texel, exactly as the CPU model forms them (then rounded to float):
// channels 0-2 in 'a', 3-5 in 'b'.
void channelPlanes(const shading::PreparedScene& ps, std::vector<float>& a, std::vector<float>& b);

// What one mode's program is compiled for: the BOOTH_* defines (glsl/booth_interface.glsl and
// the files after it say what each does).
struct BoothShaderConfig {
    int mode = 0; // 0 cache, 1 compose, 2 specular grid, 3 diffuse grid
    // Mode 0's two programs: the surface's pixels (false), and those around it (true), drawn
    // after it and discarding the surface's pixels, so that neither carries the other's code
    // (llvmpipe runs both sides of a branch under a mask: the surface's pixels paid for the
    // surround's light loop).
    bool surround = false;
    bool relief = false;
    bool specularGrid = false;
    bool diffuseGrid = false;
    bool hardwareFilter = false;
    int horizonDirections = 0;
    int horizonSlots = 4;
    bool specular = false; // a specular term (its sample count is a uniform, uSpecSamples)
    brdf::WardModel wardModel = brdf::WardModel::WardDurGuarded;
    bool facetCache = false;
    int unrolledLights = 0;
    int unrolledSpecularSamples = 0;
};

// "#version 310 es", the defines for 'c' and the settings' switches, then kBoothXyzShader.
std::string boothShaderSource(const BoothShaderConfig& c, const shading::RenderSettings& s);

} // namespace replica::pipeline::render::booth_upload
