// GLSL ES 3.10 sources of the display pass (pass 2: XYZ to panel counts): the files under glsl/,
// joined at build time (pipeline/CMakeLists.txt, glsl/embed_glsl.cmake).
#pragma once

namespace replica::pipeline::render {

// The display pass's fragment shader, drawn with gl_program.h's kFullscreenVertexShader after
// "#version 310 es" and the DISP_* defines (DisplayPass::init): glsl/display_interface.glsl,
// display_inverse (mapToGamut, DisplayInverse::countsFromLinear), viewing_angle (viewingGain),
// display_lut3d (DisplayLut3d::counts), dither (quantiseCount), display_main.
extern const char* const kDisplayFragmentShader;

// The gamut-count compute shader (glsl/gamut_count.glsl), after "#version 310 es" and
// "#define COUNT_RUN n".
extern const char* const kGamutCountShader;

} // namespace replica::pipeline::render
