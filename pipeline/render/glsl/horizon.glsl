// Horizon shadowing: surface::HorizonMap::sinHorizon / sinHorizonBilinear and
// shading/realtime_model.cpp elevationVisibility, horizonVisibility, lightSoftness.

float hz[BOOTH_HORIZON_SLOTS];  // a whole number of layers, at least one

// bilinearAtTexel's rule (pipeline/base/bilinear.h) at texel position (x, y) (texel centres at
// + 0.5): the texel below and left of it in c (not clamped) and the weights of the texels after
// it in x and y.
vec2 bilinearTexel(float x, float y, out ivec2 c) {
    float fx = x - 0.5;
    float fy = y - 0.5;
    float x0 = floor(fx);
    float y0 = floor(fy);
    c = ivec2(int(x0), int(y0));
    return vec2(fx - x0, fy - y0);
}

#if BOOTH_MODE == 0 || BOOTH_MODE == 3
// Adds w times texel t's horizon sines to hz (horizonTexture's layout).
void addHorizons(ivec2 t, float w) {
    for (int j = 0; j < (uHorizonDirs + 7) / 8; ++j) {
        uvec4 b = texelFetch(uHorizon, ivec3(t, j), 0);
        for (int q = 0; q < 4; ++q) {
            vec2 pair = unpackHalf2x16(b[q]);
            hz[8 * j + 2 * q] += w * pair.x;
            hz[8 * j + 2 * q + 1] += w * pair.y;
        }
    }
}

// surface::HorizonMap::sinHorizonBilinear's four texels and weights at texel position (x, y),
// summed into hz (the azimuth interpolation after it is linear too: the same sine).
void bilinearHorizons(float x, float y) {
    for (int k = 0; k < BOOTH_HORIZON_SLOTS; ++k) {
        hz[k] = 0.0;
    }
    ivec2 c;
    vec2 a = bilinearTexel(x, y, c);
    float ax = a.x;
    float ay = a.y;
    ivec2 hi = uTexels - 1;
    addHorizons(clamp(c, ivec2(0), hi), (1.0 - ax) * (1.0 - ay));
    addHorizons(clamp(c + ivec2(1, 0), ivec2(0), hi), ax * (1.0 - ay));
    addHorizons(clamp(c + ivec2(0, 1), ivec2(0), hi), (1.0 - ax) * ay);
    addHorizons(clamp(c + ivec2(1, 1), ivec2(0), hi), ax * ay);
}
#endif

// surface::HorizonMap::sinHorizon: the horizon sine at the azimuth of l (tangent frame).
float sinHorizon(vec3 l) {
    float phi = (abs(l.x) > 0.0 || abs(l.y) > 0.0) ? atan(l.y, l.x) : 0.0;
    if (phi < 0.0) {
        phi += 2.0 * kPi;
    }
    float f = phi / (2.0 * kPi) * float(uHorizonDirs);
    // The two directions around phi picked by comparisons, each
    // direction past the first replacing the pair when f has reached it (every index a
    // constant: a compare and two selects a direction, where the tent weights below take seven
    // operations), then sinHorizon's (1 - t) lo + t hi. f = K (phi rounded up to 2 pi) is
    // direction 0 again, as on the CPU.
    f = f >= float(uHorizonDirs) ? f - float(uHorizonDirs) : f;
    float lo = hz[0];
    float hi = hz[uHorizonDirs > 1 ? 1 : 0];
    for (int k = 1; k < uHorizonDirs; ++k) {
        bool past = f >= float(k);
        lo = past ? hz[k] : lo;
        hi = past ? hz[(k + 1) % uHorizonDirs] : hi;
    }
    float t = f - floor(f);
    float sinB = (1.0 - t) * lo + t * hi;
    return sinB;
}

// realtime_model.cpp elevationVisibility: a direction at elevation sin = lz against sinB.
float elevationVisibility(float sinB, float lz, float softness) {
    if (sinB <= 0.0) {
        return 1.0;
    }
    float e0 = sinB - softness;
    float e1 = sinB + softness;
    float s = clamp((lz - e0) / max(e1 - e0, 1e-12), 0.0, 1.0);
    return s * s * (3.0 - 2.0 * s);
}

// realtime_model.cpp horizonVisibility.
float horizonVisibility(vec3 l, float softness) {
    if (uHorizonDirs <= 0) {
        return 1.0;
    }
    return elevationVisibility(sinHorizon(l), l.z, softness);
}

// realtime_model.cpp lightSoftness: the horizon's softness for light i seen along the unit
// direction d, cosG = d.n, d2 its squared distance: at least uSoftness, and sqrt(3) times the
// spread of the light's elevation sine over the ceiling region it stands for (the distance
// floored at a texel, as in eq. 1).
float lightSoftness(int i, vec3 d, float cosG, float d2) {
    float invDist = inversesqrt(max(d2, uTexelArea));
    vec3 su3 = uLightSpreadU[i].xyz;
    vec3 sv3 = uLightSpreadV[i].xyz;
    float su = (dot(su3, uNormal) - cosG * dot(d, su3)) * invDist;
    float sv = (dot(sv3, uNormal) - cosG * dot(d, sv3)) * invDist;
    return max(uSoftness, sqrt(3.0 * (su * su + sv * sv)));
}
