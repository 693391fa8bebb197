// The inverse display model (Day et al.): XYZ -> linear drive by M^-1, the gamut mapped as
// display/gamut_map.cpp's mapToGamut does, the crosstalk undone (DisplayModel::deinteracted; no
// steps without it), then counts by the inverse tone-curve LUT
// (display/display_inverse.cpp: DisplayInverse::countsFromLinear).

uniform mat3 uDispXyzToLinear;
uniform vec3 uDispBlackXyz;
uniform float uDispBlackY;
uniform float uDispWhiteY;
uniform float uDispGamutEdgeTolerance; // the profile's (gamut_map.h); 0 when unset: none
uniform float uDispGamutEdgeFloor;
uniform mat3 uDispCrosstalk;     // DisplayModel::crosstalk
uniform int uDispCrosstalkSteps; // 0 without crosstalk: r is then the mapping's, untouched
uniform float uDispMaxCount;
uniform int uDispLutSize;
uniform highp sampler2D uDispToneLut;  // (lutSize - 1) x 3, RG32F, texelFetch only
uniform vec4 uDispViewing[16];         // angle deg, gain X, Y, Z
uniform highp sampler2D uDispViewingGrid; // kViewingGridNodes x 1, RGBA32F, GL_LINEAR

// Linear interpolation in u = cbrt(r), done by hand so no float-filtering extension is needed.
// DisplayInverse::countsFromLinear with ToneInverse::Lut.
float countsFromLinear(int channel, float r) {
    float pos = pow(clamp(r, 0.0, 1.0), 1.0 / 3.0) * float(uDispLutSize - 1);
    int j = clamp(int(floor(pos)), 0, uDispLutSize - 2);
    float f = pos - float(j);
    // Texel j holds entries j and j + 1: one fetch where two were (each a gather on llvmpipe).
    vec2 ab = texelFetch(uDispToneLut, ivec2(j, channel), 0).rg;
    return mix(ab.x, ab.y, f) * uDispMaxCount;
}

// Gamut classes: 0 in gamut, 1 chroma, 2 over peak, 3 below black (see gamut_map.h).
// mode 0: hue-keeping; 1: per-channel clip.
// DisplayInverse::invert (mapToGamut, then countsFromLinear per channel).
vec4 invert(vec3 xyzIn, int mode) {
    vec3 xyz = xyzIn;
    if (any(isnan(xyz)) || any(isinf(xyz))) {
        return vec4(0.0, 0.0, 0.0, 3.0);
    }
    // DisplayInverse::invert with crosstalk: r with the crosstalk undone (unclamped steps) in
    // the cube is in gamut as it is. No steps, and this is skipped, without crosstalk.
    if (uDispCrosstalkSteps > 0) {
        vec3 y0 = uDispXyzToLinear * (xyz - uDispBlackXyz);
        vec3 q = y0;
        for (int i = 0; i < uDispCrosstalkSteps; ++i) {
            q = y0 - uDispCrosstalk * vec3(q.x * q.y, q.y * q.z, q.z * q.x);
        }
        const float tolX = 1e-5;
        if (all(greaterThanEqual(q, vec3(-tolX))) && all(lessThanEqual(q, vec3(1.0 + tolX))) &&
            xyz.y >= uDispBlackY) {
            q = clamp(q, 0.0, 1.0);
            return vec4(countsFromLinear(0, q.r), countsFromLinear(1, q.g),
                        countsFromLinear(2, q.b), 0.0);
        }
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
    // DisplayModel::deinteracted: r + C p(r) = y by fixed-point steps from r = y.
    vec3 y = r;
    for (int i = 0; i < uDispCrosstalkSteps; ++i) {
        r = clamp(y - uDispCrosstalk * vec3(r.x * r.y, r.y * r.z, r.z * r.x), 0.0, 1.0);
    }
    return vec4(countsFromLinear(0, r.r), countsFromLinear(1, r.g), countsFromLinear(2, r.b), cls);
}

