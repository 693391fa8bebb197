// The 3-D LUT inverse and the gamut class alone, for that path.

// The 3-D LUT path (display_inverse.cpp DisplayLut3d::counts): lattice over u = cbrt(XYZ / white), tetrahedral.
uniform highp sampler3D uDispLut3d;    // size^3, RGBA32F, counts in .rgb
uniform int uDispLut3dSize;
uniform vec3 uDispLut3dScale;          // 1 / white XYZ

vec3 counts(vec3 xyz) {
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

// The gamut class alone (what invert reports in .w; on the CPU InverseResult::gamutClass), for
// the LUT path.
float gamutClass(vec3 xyz) {
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

