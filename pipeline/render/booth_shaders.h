// GLSL ES 3.10 sources of the booth shading pass (surface radiance in absolute XYZ): the files
// under glsl/, joined at build time (pipeline/CMakeLists.txt, glsl/embed_glsl.cmake).
#pragma once

namespace replica::pipeline::render {

// Drawn with gl_program.h's kFullscreenVertexShader.
// The real-time algorithm of shading/realtime_model.cpp, line for line in float: eq. (1) over the
// median-cut point lights with normal-mapped facets and horizon shadows, eq. (2) with K = 6
// channel coefficients, Ward specular by filtered importance sampling of the luminance mip chain,
// minus the screen's front-surface flare. Up to four modes, each linked as its own program from
// "#version 310 es", "#define BOOTH_MODE n", the pass's other BOOTH_* defines (booth_shading_
// pass.cpp: relief, grids, filter, counts) and this source (no #version line of its own): mode 3
// sums E_geo at the nodes of the diffuse grid (flat surfaces); mode 0 writes the eye-independent
// part (diffuse XYZ, and E_geo, the illuminance on the panel plane, in alpha) into a cache; mode 2
// the specular term at the nodes of the specular grid; mode 1 reads them and writes XYZ (cd/m^2)
// and E_geo.
extern const char* const kBoothXyzShader;

constexpr int kBoothMaxLights = 256;           // std140 uniform block of vec4: 4 KiB
constexpr int kBoothUnrolledLights = 64;       // eq. (1) written out light by light up to here
constexpr int kBoothMaxHorizonDirections = 32; // local array in the shader
constexpr int kBoothMaxSpecularSamples = 256;  // std140 uniform block of vec4: 4 KiB
constexpr int kBoothUnrolledSpecSamples = 32;  // the specular loop written out up to here

} // namespace replica::pipeline::render
