// GLSL ES 3.10 sources of the booth shading pass (surface radiance in absolute XYZ).
#pragma once

namespace replica::pipeline::render {

// Drawn with gl_program.h's kFullscreenVertexShader.
// The real-time algorithm of shading/realtime_model.cpp, line for line in float: eq. (1) over the
// median-cut point lights with normal-mapped facets and horizon shadows, eq. (2) with K = 6
// channel coefficients, Ward specular by filtered importance sampling of the luminance mip chain,
// minus the screen's front-surface flare. Writes XYZ (cd/m^2) and 1.
extern const char* const kBoothXyzShader;

constexpr int kBoothMaxLights = 256;           // std140 uniform block of vec4: 4 KiB
constexpr int kBoothMaxHorizonDirections = 32; // local array in the shader

} // namespace replica::pipeline::render
