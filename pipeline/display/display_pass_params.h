// What the GPU display pass needs from a profile, as plain data (uniform values and float arrays
// for textures). The renderer owns the GL objects and the GLSL that reads them
// (pipeline/render/glsl/display_inverse.glsl and the pieces after it, each named for the CPU
// function it mirrors: display_inverse.h, viewing_angle.h, dither.h).
#pragma once

#include <array>
#include <vector>

#include <pipeline/display/display_inverse.h>
#include <pipeline/display/dither.h>

namespace replica::pipeline::display {

constexpr int kMaxViewingRows = 16;
// The viewing-angle gain sampled every half degree from 0 to 90 (the display pass filters it
// where the GL filters float textures): the same piecewise-linear function as the rows wherever
// every row's angle is a multiple of the step (the shipped table's are multiples of 5 degrees).
constexpr double kViewingGridStepDeg = 0.5;
constexpr int kViewingGridNodes = 181;

struct DisplayPassParams {
    std::array<float, 9> xyzToLinear{}; // M^-1, column-major (glUniformMatrix3fv, transpose false)
    std::array<float, 3> blackXyz{};
    float blackY = 0.0f;
    float whiteY = 1.0f;
    // DisplayModel::gamutEdgeTolerance (uniform uDispGamutEdgeTolerance; 0, the GL default of an
    // unset uniform, is the mapping without it).
    float gamutEdgeTolerance = 0.0f;
    float gamutEdgeFloor = 0.0f; // uDispGamutEdgeFloor, likewise
    // DisplayModel::crosstalk, column-major (uDispCrosstalk), and the fixed-point steps that undo
    // it (uDispCrosstalkSteps): DisplayModel::kCrosstalkSteps, 0 (no loop, the additive pixels
    // unchanged) without crosstalk.
    std::array<float, 9> crosstalk{};
    int crosstalkSteps = 0;
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

DisplayPassParams makeDisplayPassParams(const DisplayInverse& inverse);

} // namespace replica::pipeline::display
