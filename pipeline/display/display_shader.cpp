// Shader parameters and GLSL of the inverse display model.
#include <algorithm>

#include <glm/matrix.hpp>

#include <pipeline/display/display_shader.h>
#include <pipeline/display/viewing_angle.h>

namespace replica::pipeline::display {

DisplayShaderParams makeDisplayShaderParams(const DisplayInverse& inverse)
{
    const DisplayModel& m = inverse.model();
    const GamutGeometry& g = inverse.geometry();
    DisplayShaderParams p;
    for (int col = 0; col < 3; ++col) {
        for (int row = 0; row < 3; ++row) {
            p.xyzToLinear[static_cast<std::size_t>(col * 3 + row)] =
                    static_cast<float>(g.xyzToLinear[col][row]);
        }
        p.blackXyz[static_cast<std::size_t>(col)] = static_cast<float>(g.blackXyz[col]);
    }
    p.blackY = static_cast<float>(g.blackY);
    p.whiteY = static_cast<float>(g.whiteY);
    p.gamutEdgeTolerance = static_cast<float>(g.edgeTolerance);
    p.gamutEdgeFloor = static_cast<float>(g.edgeFloor);
    p.maxCount = static_cast<float>(m.maxCount());
    p.lutSize = inverse.lutSize();
    p.lut.reserve(static_cast<std::size_t>(p.lutSize - 1) * 3 * 2);
    for (int c = 0; c < 3; ++c) {
        const std::vector<double>& lut = inverse.lut(c);
        for (std::size_t j = 0; j + 1 < lut.size(); ++j) {
            p.lut.push_back(static_cast<float>(lut[j]));
            p.lut.push_back(static_cast<float>(lut[j + 1]));
        }
    }
    p.dither = ditherPattern();
    const glm::dvec3 white = m.whiteXyz();
    p.viewingRows =
            static_cast<int>(std::min<std::size_t>(m.viewing.angleDeg.size(), kMaxViewingRows));
    for (int i = 0; i < p.viewingRows; ++i) {
        const auto row = static_cast<std::size_t>(i);
        const glm::dvec3 gain = viewingGainAtRow(m.viewing, white, row);
        p.viewing[row * 4 + 0] = static_cast<float>(m.viewing.angleDeg[row]);
        p.viewing[row * 4 + 1] = static_cast<float>(gain.x);
        p.viewing[row * 4 + 2] = static_cast<float>(gain.y);
        p.viewing[row * 4 + 3] = static_cast<float>(gain.z);
    }
    if (p.viewingRows >= 2) {
        p.viewingGrid.reserve(4 * kViewingGridNodes);
        for (int k = 0; k < kViewingGridNodes; ++k) {
            const glm::dvec3 gain = viewingGain(m.viewing, white, k * kViewingGridStepDeg);
            p.viewingGrid.insert(p.viewingGrid.end(),
                                 {static_cast<float>(gain.x), static_cast<float>(gain.y),
                                  static_cast<float>(gain.z), 0.0f});
        }
    }
    p.flarePerLux =
            m.condition == MeasurementCondition::LitBooth
                    ? 0.0f
                    : static_cast<float>(m.frontSurfaceReflectance / 3.14159265358979323846);
    return p;
}

const char* const kDisplayInverseGlsl = R"(
uniform mat3 uDispXyzToLinear;
uniform vec3 uDispBlackXyz;
uniform float uDispBlackY;
uniform float uDispWhiteY;
uniform float uDispGamutEdgeTolerance; // the profile's (gamut_map.h); 0 when unset: none
uniform float uDispGamutEdgeFloor;
uniform float uDispMaxCount;
uniform int uDispLutSize;
uniform highp sampler2D uDispToneLut;  // (lutSize - 1) x 3, RG32F, texelFetch only
uniform vec4 uDispViewing[16];         // angle deg, gain X, Y, Z
uniform highp sampler2D uDispViewingGrid; // kViewingGridNodes x 1, RGBA32F, GL_LINEAR

// Linear interpolation in u = cbrt(r), done by hand so no float-filtering extension is needed.
float displayToneLut(int channel, float r) {
    float pos = pow(clamp(r, 0.0, 1.0), 1.0 / 3.0) * float(uDispLutSize - 1);
    int j = clamp(int(floor(pos)), 0, uDispLutSize - 2);
    float f = pos - float(j);
    // Texel j holds entries j and j + 1: one fetch where two were (each a gather on llvmpipe).
    vec2 ab = texelFetch(uDispToneLut, ivec2(j, channel), 0).rg;
    return mix(ab.x, ab.y, f) * uDispMaxCount;
}

// Gamut classes: 0 in gamut, 1 chroma, 2 over peak, 3 below black (see gamut_map.h).
// mode 0: hue-keeping; 1: per-channel clip.
vec4 displayInverse(vec3 xyzIn, int mode) {
    vec3 xyz = xyzIn;
    if (any(isnan(xyz)) || any(isinf(xyz))) {
        return vec4(0.0, 0.0, 0.0, 3.0);
    }
    float cls = 0.0;
    float edge = uDispGamutEdgeTolerance;
    if (xyz.y > uDispWhiteY) {
        cls = 2.0;
        if (mode == 0 && xyz.y > uDispWhiteY * (1.0 + edge)) {
            xyz *= uDispWhiteY / xyz.y;
        }
    }
    vec3 r = uDispXyzToLinear * (xyz - uDispBlackXyz);
    float span = uDispWhiteY - uDispBlackY;
    // Below black: class 3, and the channels clipped (mode 1) or black (mode 0). One tone-curve
    // lookup below serves both cases (llvmpipe runs both sides of a branch, so a second set of
    // lookups here cost every pixel six more texel fetches and cube roots).
    bool below = !(xyz.y - uDispBlackY >= 0.0);
    // float rounding in M^-1 must not flag in-gamut colours: a small tolerance, then clamp.
    const float tol = 1e-5;
    bool inside = all(greaterThanEqual(r, vec3(-tol))) && all(lessThanEqual(r, vec3(1.0 + tol)));
    // Within the profile's edge tolerance (relative to the largest channel below 0): clamped.
    float low = max(tol, edge * max(max(r.x, max(r.y, r.z)), 0.0) + uDispGamutEdgeFloor);
    bool near = all(greaterThanEqual(r, vec3(-low))) &&
                all(lessThanEqual(r, vec3(1.0 + max(tol, edge))));
    if (below) {
        r = mode == 1 ? r : vec3(0.0);
        cls = 3.0;
    } else if (!near && mode == 0) {
        // As mapToGamut: towards the same-luminance neutral until no channel is negative, then
        // scale down until none exceeds 1.
        float s = clamp((xyz.y - uDispBlackY) / span, 0.0, 1.0);
        float t = 1.0;
        for (int c = 0; c < 3; ++c) {
            if (r[c] < 0.0) {
                t = min(t, s / (s - r[c]));
            }
        }
        r = vec3(s) + clamp(t, 0.0, 1.0) * (r - vec3(s));
        float top = max(r.x, max(r.y, r.z));
        if (top > 1.0) {
            r /= top;
        }
    }
    if (!inside && cls == 0.0) {
        cls = 1.0;
    }
    r = clamp(r, 0.0, 1.0);
    return vec4(displayToneLut(0, r.r), displayToneLut(1, r.g), displayToneLut(2, r.b), cls);
}

// The row count is compiled in (DISP_VIEWING_ROWS, from the profile). The segment is the first
// row i whose next angle is above a (what a search up the table returns): with the angles rising,
// i counts the inner rows at or below a. Counting costs a compare a row; only that segment is
// interpolated (llvmpipe ran all eleven divisions and mixes when each row interpolated under its
// own test). At or past the last angle, and for a NaN, the last row's gain.
vec3 displayViewingGain(float angleDeg) {
#if DISP_VIEWING_ROWS <= 0
    return vec3(1.0);
#elif DISP_VIEWING_ROWS == 1
    return uDispViewing[0].yzw;
#elif DISP_VIEWING_FILTERED
    // DisplayPassSetup::viewingFiltered: the gain every half degree, interpolated by the sampler.
    // One filtered read where the row count, two indexed uniform reads (a gather per component
    // on llvmpipe) and a division were: 6 % of the painting's frame. NaN and 90 degrees or more
    // take the last node, the last row's gain.
    float a = angleDeg < 90.0 ? max(angleDeg, 0.0) : 90.0;
    return texture(uDispViewingGrid,
                   vec2((a * float(DISP_VIEWING_GRID_PER_DEG) + 0.5) / float(DISP_VIEWING_GRID_NODES),
                        0.5)).rgb;
#else
    float a = clamp(angleDeg, 0.0, 90.0);
    if (!(a < uDispViewing[DISP_VIEWING_ROWS - 1].x)) {
        return uDispViewing[DISP_VIEWING_ROWS - 1].yzw;
    }
    int i = 0;
    for (int k = 1; k < DISP_VIEWING_ROWS - 1; ++k) {
        i += a >= uDispViewing[k].x ? 1 : 0;
    }
    vec4 lo = uDispViewing[i];
    vec4 hi = uDispViewing[i + 1];
    return mix(lo.yzw, hi.yzw, (a - lo.x) / (hi.x - lo.x));
#endif
}

// The 3-D LUT path (DisplayLut3d::counts): lattice over u = cbrt(XYZ / white), tetrahedral.
uniform highp sampler3D uDispLut3d;    // size^3, RGBA32F, counts in .rgb
uniform int uDispLut3dSize;
uniform vec3 uDispLut3dScale;          // 1 / white XYZ

vec3 displayLut3dCounts(vec3 xyz) {
    float top = float(uDispLut3dSize - 1);
    vec3 pos = clamp(pow(max(xyz * uDispLut3dScale, vec3(0.0)), vec3(1.0 / 3.0)), 0.0, 1.0) * top;
    vec3 fl = min(floor(pos), vec3(top - 1.0));
    vec3 f = pos - fl;
    ivec3 i0 = ivec3(fl);
    ivec3 e1;
    ivec3 e2;
    vec3 w; // fractions in decreasing order
    if (f.x >= f.y) {
        if (f.y >= f.z) {
            e1 = ivec3(1, 0, 0); e2 = ivec3(1, 1, 0); w = f.xyz;
        } else if (f.x >= f.z) {
            e1 = ivec3(1, 0, 0); e2 = ivec3(1, 0, 1); w = f.xzy;
        } else {
            e1 = ivec3(0, 0, 1); e2 = ivec3(1, 0, 1); w = f.zxy;
        }
    } else {
        if (f.z >= f.y) {
            e1 = ivec3(0, 0, 1); e2 = ivec3(0, 1, 1); w = f.zyx;
        } else if (f.z >= f.x) {
            e1 = ivec3(0, 1, 0); e2 = ivec3(0, 1, 1); w = f.yzx;
        } else {
            e1 = ivec3(0, 1, 0); e2 = ivec3(1, 1, 0); w = f.yxz;
        }
    }
    vec3 c0 = texelFetch(uDispLut3d, i0, 0).rgb;
    vec3 c1 = texelFetch(uDispLut3d, i0 + e1, 0).rgb;
    vec3 c2 = texelFetch(uDispLut3d, i0 + e2, 0).rgb;
    vec3 c3 = texelFetch(uDispLut3d, i0 + ivec3(1), 0).rgb;
    return c0 + w.x * (c1 - c0) + w.y * (c2 - c1) + w.z * (c3 - c2);
}

// The gamut class alone (what displayInverse reports in .w), for the LUT path.
float displayGamutClass(vec3 xyz) {
    if (any(isnan(xyz)) || any(isinf(xyz)) || !(xyz.y - uDispBlackY >= 0.0)) {
        return 3.0;
    }
    if (xyz.y > uDispWhiteY) {
        return 2.0;
    }
    vec3 r = uDispXyzToLinear * (xyz - uDispBlackXyz);
    const float tol = 1e-5;
    bool inside = all(greaterThanEqual(r, vec3(-tol))) && all(lessThanEqual(r, vec3(1.0 + tol)));
    return inside ? 0.0 : 1.0;
}

// ditherPattern()'s threshold at the pixel, computed by the same bit interleaving: a dozen
// integer operations where a texel read was a gather per pixel on llvmpipe (3.5 M instructions
// of the painting's frame). The same floats: v + 0.5 and the division by 256 are exact.
float displayDitherThreshold(ivec2 pixel) {
    int y = pixel.y & 15;
    int xy = (pixel.x & 15) ^ y;
    int v = 0;
    for (int bit = 0; bit < 4; ++bit) {
        v = (v << 2) | (((xy >> bit) & 1) << 1) | ((y >> bit) & 1);
    }
    return (float(v) + 0.5) / 256.0;
}

vec3 displayQuantise(vec3 counts, ivec2 pixel) {
    float t = displayDitherThreshold(pixel);
    return clamp(floor(counts + vec3(t)), vec3(0.0), vec3(uDispMaxCount));
}
)";

} // namespace replica::pipeline::display
