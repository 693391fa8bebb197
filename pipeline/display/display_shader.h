// What the GPU display pass needs from a profile, as plain data (uniform values and float arrays
// for textures), and the GLSL of the inverse model that reads them. The renderer owns the GL
// objects; this file owns the maths, so the shader and the CPU reference (display_inverse.h) are
// written side by side.
#pragma once

#include <array>
#include <vector>

#include <pipeline/display/display_inverse.h>
#include <pipeline/display/dither.h>

namespace replica::pipeline::display {

constexpr int kMaxViewingRows = 16;
// The viewing-angle gain sampled every half degree from 0 to 90 (DisplayPassSetup::
// viewingFiltered): the same piecewise-linear function as the rows wherever every row's angle is
// a multiple of the step (the shipped table's are multiples of 5 degrees).
constexpr double kViewingGridStepDeg = 0.5;
constexpr int kViewingGridNodes = 181;

struct DisplayShaderParams {
    std::array<float, 9> xyzToLinear{}; // M^-1, column-major (glUniformMatrix3fv, transpose false)
    std::array<float, 3> blackXyz{};
    float blackY = 0.0f;
    float whiteY = 1.0f;
    // DisplayModel::gamutEdgeTolerance (uniform uDispGamutEdgeTolerance; 0, the GL default of an
    // unset uniform, is the mapping without it).
    float gamutEdgeTolerance = 0.0f;
    float gamutEdgeFloor = 0.0f; // uDispGamutEdgeFloor, likewise
    float maxCount = 255.0f;
    // Inverse tone LUTs: entry j = counts / maxCount at r = (j / (lutSize - 1))^3 (the cube-root
    // domain keeps near-black precision), as a (lutSize - 1) x 3 RG32F texture: row c = channel c,
    // texel j = entries j and j + 1 (the pair one interpolation reads).
    int lutSize = 0;
    std::vector<float> lut;
    // Ordered-dither thresholds in (0, 1), indexed by pixel modulo 16 (the CPU's checks of the
    // surround; the shader computes the same thresholds).
    std::array<float, kDitherSize * kDitherSize> dither{};
    // Viewing-angle gains at the table rows: (angle deg, gain X, gain Y, gain Z); rows beyond
    // kMaxViewingRows are dropped (the shipped table has 12).
    int viewingRows = 0;
    std::array<float, 4 * kMaxViewingRows> viewing{};
    // The gain at each of kViewingGridNodes angles, RGBA (gain X, Y, Z, 0); empty for fewer than
    // two rows (no interpolation to do).
    std::vector<float> viewingGrid;
    // Front-surface flare per lux of illuminance, before the light's colour: rho_d / pi; 0 when the
    // profile was measured in the lit booth (its black already holds the reflection).
    float flarePerLux = 0.0f;
};

DisplayShaderParams makeDisplayShaderParams(const DisplayInverse& inverse);

// GLSL ES 3.10 declarations and functions (no #version, no main; the includer defines
// DISP_VIEWING_ROWS as viewingRows, DISP_VIEWING_FILTERED 0 or 1, DISP_VIEWING_GRID_PER_DEG and
// DISP_VIEWING_GRID_NODES from the constants above): uniforms uDisp*, samplers uDispToneLut and
// uDispViewingGrid (read only when filtered), and
//   vec4 displayInverse(vec3 xyz, int mode)  // counts (real) in .xyz, gamut class in .w
//   vec3 displayViewingGain(float angleDeg)
//   vec3 displayQuantise(vec3 counts, ivec2 pixel) // integer counts as floats
// mirroring mapToGamut, DisplayInverse::countsFromLinear (Lut), viewingGain and quantiseCount.
extern const char* const kDisplayInverseGlsl;

} // namespace replica::pipeline::display
