// GLSL sources of the booth shading pass; each block names the function of realtime_model.cpp,
// brdf/ward.cpp or booth/luminance_image.cpp it mirrors, so the two stay in step.
#include <pipeline/render/booth_shaders.h>

namespace replica::pipeline::render {

const char* const kBoothXyzShader = R"(
precision highp float;
precision highp int;
precision highp sampler2D;
precision highp sampler2DArray;
out vec4 outXyz;

// Pixel -> surface: su, sv (sv down the image) = offset + scale * (pixel centre / viewport).
uniform vec2 uViewport;
uniform vec2 uSurfOffset;
uniform vec2 uSurfScale;
// The surface's pixel rectangle in window coordinates (BOOTH_EXACT_TIES): left edge x, top edge y
// (window y runs up), width and height in pixels; from uSurfOffset, uSurfScale and uViewport.
uniform vec4 uSurfPixels;
// The surface in the booth frame (metres): centre, unit axes, physical size; texels.
uniform vec3 uCentre;
uniform vec3 uRight;
uniform vec3 uUp;
uniform vec3 uNormal;
uniform vec2 uSizeM;
uniform ivec2 uTexels;
uniform vec3 uEye;

uniform sampler2D uCoeffA;      // channels 0..2 per texel (row 0 = top row of the scene)
uniform sampler2D uCoeffB;      // channels 3..5
uniform sampler2D uNormals;     // tangent-space normal per texel
// sin(horizon elevation): 4 directions a layer, or with BOOTH_HORIZON_HALF 8 a layer as half
// floats, two a word (booth_shading_pass.cpp horizonTexture; RenderSettings::horizonHalf).
#if BOOTH_HORIZON_HALF
uniform highp usampler2DArray uHorizon;
#else
uniform sampler2DArray uHorizon;
#endif
const bool uRelief = BOOTH_RELIEF != 0; // normal map and horizons (fixed for the pass's life)
// Horizon directions (0: no horizon shadowing), specular samples (0: no specular pass) and the
// Ward model (0 Ward 1992, 1 Ward-Duer, 2 Ward-Duer guarded, 3 GMD) are fixed for the pass's life
// and compiled in: the loops over them get constant bounds, the horizon sines constant indices
// and the Ward weight one branch (llvmpipe paid for the dynamic array indexing and the untaken
// branches on every sample).
const int uHorizonDirs = BOOTH_HORIZON_DIRS;
uniform float uSoftness;

layout(std140) uniform BoothLights {
    vec4 uLight[256];           // xyz: position (m); w: summed luminance * texel area (cd)
    vec4 uLightSpreadU[256];    // xyz: booth::PointLight::spreadU (m); w: its meanCdM2
    vec4 uLightSpreadV[256];    // xyz: booth::PointLight::spreadV (m)
    // The region's rectangle on the ceiling (BOOTH_AREA_LIGHTS): (s0, t0, s1, t1), the corners
    // uLightCentre + (s - 1/2) uEdgeU + (t - 1/2) uEdgeV (booth::PointLight::regionOrigin/U/V).
    vec4 uLightRect[256];
};
uniform int uLightCount;
uniform vec3 uLightNormal;      // emitting side of the ceiling
uniform float uTexelArea;       // m^2: floor of d^2 (a light never nearer than one texel)
uniform bool uDiffuse;
uniform vec3 uChannelXyz[6];    // M_k of the light (Y = 1 light)
uniform vec3 uWhite;            // XYZ of the light scaled to Y = 1
uniform float uFlareRho;
// 0: the eye-independent part into the cache (diffuse XYZ, E_geo in alpha); 1: compose the frame
// from the cache plus the eye-dependent specular term; 2: the specular term (rho_s = 1) at the
// nodes of the specular grid, one fragment per node; 3: E_geo at the nodes of the diffuse grid,
// for mode 0 to interpolate (booth_shading_pass.cpp says when each runs).
// A constant: each mode is its own program, so that it carries none of the others' code (llvmpipe
// runs both sides of a branch under a mask; a mode that only composes would pay for the rest).
const int uMode = BOOTH_MODE;
uniform sampler2D uCache;       // RGBA32F, the viewport's size: what mode 0 wrote
// The specular grid (shading::gridNodes): node (i, j) at surface (u, v) =
// (i / (nodes.x - 1), j / (nodes.y - 1)); (0, 0): the specular term per pixel.
uniform ivec2 uGridNodes;
const bool kGrid = BOOTH_GRID != 0;     // whether the compose reads the grid (fixed likewise)
uniform sampler2D uSpecGrid;    // R32F, uGridNodes: what mode 2 wrote this frame
// The diffuse grid (RenderSettings::diffuseGrid, flat surfaces only), laid out like the specular
// one: mode 0 interpolates E_geo between its nodes instead of summing eq. (1) per pixel.
// BOOTH_DIFFUSE_GRID says whether mode 0 reads it (fixed for the pass's life like the rest).
uniform ivec2 uDiffNodes;
uniform sampler2D uDiffGrid;    // R32F, uDiffNodes: what mode 3 wrote with the cache
// BOOTH_FACET_CACHE (relief with a per-pixel specular term): mode 0 also writes each pixel's
// facet normal (tangent frame, bilinearNormal's) beside the cache, and the compose reads it there:
// one texel a frame instead of four and a normalisation.
#if BOOTH_FACET_CACHE && BOOTH_MODE == 0
layout(location = 1) out vec4 outFacet;
#endif
uniform sampler2D uFacetCache;  // RGBA32F, the viewport's size: what mode 0 wrote

const int uSpecSamples = BOOTH_SPEC_SAMPLES;
// brdf::sampleWardHalfVectorLocal for sample k (u1 = (k + 1/2) / N, u2 = radicalInverse2(k)),
// computed once on the CPU in double: xyz the half vector in the local frame, w the sample's
// solid angle without its o.h factor, 4 pi alpha^2 cos^3 / (N u1).
layout(std140) uniform BoothSpecSamples {
    vec4 uSpecSample[256];
};
const int uWardModel = BOOTH_WARD_MODEL;
uniform vec3 uSpecXyz;          // XYZ of rho_s times the unit-luminance light
uniform vec3 uLightCentre;
uniform vec3 uEdgeU;
uniform vec3 uEdgeV;
uniform vec2 uInvEdge2;         // 1 / |edgeU|^2, 1 / |edgeV|^2
uniform sampler2D uLum;         // luminance mip chain (cd/m^2), padded to powers of two with 0
uniform int uLumMaxLevel;
uniform ivec2 uLumSize;         // level 0
uniform vec2 uLumUsed;          // the light's share of the padded texture
uniform float uLodBias;         // RenderSettings::specularLodBias
uniform float uLodScale;        // 4^uLodBias, exact (BOOTH_EXACT_LEVEL only)

const float kPi = 3.14159265358979;
const float kMinCosView = 1e-3;

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

#if BOOTH_HORIZON_BILINEAR && BOOTH_MODE == 0
// Adds w times texel t's horizon sines to hz (horizonTexture's layout).
void addHorizons(ivec2 t, float w) {
#if BOOTH_HORIZON_HALF
    for (int j = 0; j < (uHorizonDirs + 7) / 8; ++j) {
        uvec4 b = texelFetch(uHorizon, ivec3(t, j), 0);
        for (int q = 0; q < 4; ++q) {
            vec2 pair = unpackHalf2x16(b[q]);
            hz[8 * j + 2 * q] += w * pair.x;
            hz[8 * j + 2 * q + 1] += w * pair.y;
        }
    }
#else
    for (int j = 0; j < (uHorizonDirs + 3) / 4; ++j) {
        vec4 b = texelFetch(uHorizon, ivec3(t, j), 0);
        hz[4 * j] += w * b.x;
        hz[4 * j + 1] += w * b.y;
        hz[4 * j + 2] += w * b.z;
        hz[4 * j + 3] += w * b.w;
    }
#endif
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
float horizonSine(vec3 l) {
    float phi = (abs(l.x) > 0.0 || abs(l.y) > 0.0) ? atan(l.y, l.x) : 0.0;
    if (phi < 0.0) {
        phi += 2.0 * kPi;
    }
    float f = phi / (2.0 * kPi) * float(uHorizonDirs);
#if BOOTH_HORIZON_PICK
    // RenderSettings::horizonPick: the two directions around phi picked by comparisons, each
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
#else
    // Linear between the two directions around phi (wrapping): written as a tent weight over
    // all k so that every index is a constant (the same sum as indexing hz[k0] and hz[k1]).
    float sinB = 0.0;
    for (int k = 0; k < uHorizonDirs; ++k) {
        float d = abs(f - float(k));
        d = min(d, float(uHorizonDirs) - d);
        sinB += max(1.0 - d, 0.0) * hz[k];
    }
#endif
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
float visibility(vec3 l, float softness) {
    if (uHorizonDirs <= 0) {
        return 1.0;
    }
    return elevationVisibility(horizonSine(l), l.z, softness);
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

#if BOOTH_HW_FILTER
// booth::MipChain::sample (or sampleNearestLevel: GL_LINEAR_MIPMAP_NEAREST, set by the pass) by
// the sampler itself: GL_LINEAR_MIPMAP_LINEAR is its rule (bilinear
// within a level with texel centres at (x + 0.5) / w, linear between levels, the level clamped to
// the chain) and GL_CLAMP_TO_BORDER with border 0 its dark booth outside the image. One textureLod
// instead of eight texelFetch and their bounds tests: about 1.7x faster per specular sample on
// llvmpipe, and the same value to float rounding (booth_shading_pass_test).
float lumSample(float u, float v, float level) {
    return textureLod(uLum, vec2(u * uLumUsed.x, v * uLumUsed.y),
                      clamp(level, 0.0, float(uLumMaxLevel))).r;
}
#else
// booth/luminance_image.cpp bilinear(): texel centres at (x + 0.5) / w, border 0.
float lumTexel(ivec2 c, int level, ivec2 size) {
    if (c.x < 0 || c.y < 0 || c.x >= size.x || c.y >= size.y) {
        return 0.0;
    }
    return texelFetch(uLum, c, level).r;
}
float lumBilinear(float u, float v, int level) {
    // Level size from the base size: textureSize() with a per-pixel level is not reliable on
    // every driver (llvmpipe answers one level for a whole quad).
    ivec2 size = max(uLumSize >> level, ivec2(1));
    float fx = u * float(size.x) - 0.5;
    float fy = v * float(size.y) - 0.5;
    float x0 = floor(fx);
    float y0 = floor(fy);
    float ax = fx - x0;
    float ay = fy - y0;
    ivec2 c = ivec2(int(x0), int(y0));
    return (1.0 - ay) * ((1.0 - ax) * lumTexel(c, level, size) + ax * lumTexel(c + ivec2(1, 0), level, size))
         + ay * ((1.0 - ax) * lumTexel(c + ivec2(0, 1), level, size) + ax * lumTexel(c + ivec2(1, 1), level, size));
}
#if BOOTH_NEAREST_LEVEL
// booth::MipChain::sampleNearestLevel.
float lumSample(float u, float v, float level) {
    float l = clamp(level, 0.0, float(uLumMaxLevel));
    int d = l <= 0.5 ? 0 : min(int(ceil(l + 0.5)) - 1, uLumMaxLevel);
    return lumBilinear(u * uLumUsed.x, v * uLumUsed.y, d);
}
#else
// booth::MipChain::sample.
float lumSample(float u, float v, float level) {
    float l = clamp(level, 0.0, float(uLumMaxLevel));
    int l0 = int(floor(l));
    int l1 = min(l0 + 1, uLumMaxLevel);
    float t = l - float(l0);
    float a = lumBilinear(u * uLumUsed.x, v * uLumUsed.y, l0);
    if (t <= 0.0 || l1 == l0) {
        return a;
    }
    return (1.0 - t) * a + t * lumBilinear(u * uLumUsed.x, v * uLumUsed.y, l1);
}
#endif
#endif

// Sample k of filteredSpecular's loop (brdf::sampleWard inlined, rho_s = 1): its weighted
// luminance, 0 where the sample leaves the lobe, the surface or the ceiling. With
// BOOTH_SPEC_BRANCH_FREE (RenderSettings::specularBranchFree) every pixel computes the sample
// and keeps it or 0 at the end: llvmpipe runs each early return as a masked branch with masked
// stores after it, and a lane that fails a test only ever yields 0. Without it, the early returns
// of the frames recorded before.
float specSample(int k, vec3 n, vec3 o, float co, vec3 ft, vec3 fbt, vec3 nGeo, float planeDist,
                 vec3 eu, vec3 ev, float lu0, float lv0, float visFrom, float visScale) {
    vec4 sk = uSpecSample[k];
    vec3 hl = sk.xyz;
    vec3 h = ft * hl.x + fbt * hl.y + n * hl.z;
    float oh = dot(o, h);
#if !BOOTH_SPEC_BRANCH_FREE
    if (!(oh > 0.0)) {
        return 0.0;
    }
#endif
    vec3 i = 2.0 * oh * h - o;
    float ci = dot(n, i);
#if !BOOTH_SPEC_BRANCH_FREE
    if (!(ci > 0.0)) {
        return 0.0;
    }
#endif
    float hz3 = hl.z * hl.z * hl.z;
    float w;
    if (uWardModel == 0) {
        w = ci * oh * hz3 / sqrt(max(ci, kMinCosView) * max(co, kMinCosView));
    } else if (uWardModel == 1) {
        w = (ci / max(ci, kMinCosView)) * oh * hz3 / max(co, kMinCosView);
    } else if (uWardModel == 2) {
        w = ci * oh * hz3 / max(ci * co, oh * oh * hz3 * hl.z);
    } else {
        w = ci / (oh * hl.z);
    }
    float solidAngle = sk.w * oh;
    float cosG = dot(nGeo, i);
    float denom = dot(i, uLightNormal);
#if !BOOTH_SPEC_BRANCH_FREE
    if (!(cosG > 0.0) || !(denom < 0.0)) {
        return 0.0;
    }
#endif
    float t = planeDist / denom;
#if !BOOTH_SPEC_BRANCH_FREE
    if (!(t > 0.0) || isinf(t)) {
        return 0.0;
    }
#endif
    float lu = lu0 + t * dot(i, eu);
    float lv = lv0 + t * dot(i, ev);
    bool onCeiling = lu >= 0.0 && lu <= 1.0 && lv >= 0.0 && lv <= 1.0;
#if !BOOTH_SPEC_BRANCH_FREE
    if (!onCeiling) {
        return 0.0;
    }
#endif
    float ratio = solidAngle * t * t / (uTexelArea * -denom);
#if BOOTH_EXACT_LEVEL
    // RenderSettings::specularExactLevel: sampleNearestLevel's level d = ceil(l + 0.5) - 1 for
    // l = 0.5 log2(r) + bias > 0.5, else 0, is ceil(log2(r 4^bias)) halved and rounded down, and
    // for a normal float r ceil(log2 r) is its exponent plus one unless the mantissa is zero:
    // adding the largest mantissa carries into the exponent exactly then. (llvmpipe's log2 is a
    // polynomial.) The ratio is kept within normal floats; d < 0 clamps to level 0 below.
    float r = clamp(ratio, 1e-20, 1e30) * uLodScale;
    float lod = float((((floatBitsToInt(r) + 0x7fffff) >> 23) - 127) >> 1);
#else
    float lod = 0.5 * log2(max(ratio, 1e-20)) + uLodBias;
#endif
    float vis = clamp((cosG - visFrom) * visScale, 0.0, 1.0);
    float value = lumSample(lu, lv, lod) * w * (vis * vis * (3.0 - 2.0 * vis));
#if BOOTH_SPEC_BRANCH_FREE
    // The early returns' tests: a half vector facing the eye and a mirror direction above the
    // facet; above the macro surface and towards the ceiling's plane; ahead of the point and
    // finite; inside the ceiling.
    bool inLobe = oh > 0.0 && ci > 0.0;
    bool towardsCeiling = cosG > 0.0 && denom < 0.0 && t > 0.0 && !isinf(t);
    return inLobe && towardsCeiling && onCeiling ? value : 0.0;
#else
    return value;
#endif
}

// realtime_model.cpp filteredSpecular with brdf::sampleWard inlined (rho_s = 1).
float filteredSpecular(vec3 p, vec3 nGeo, vec3 n, vec3 o) {
    float co = dot(n, o);
    if (!(co > 0.0)) {
        return 0.0;
    }
    // brdf::Frame::fromNormal (Duff et al. 2017).
    float sgn = n.z >= 0.0 ? 1.0 : -1.0;
    float fa = -1.0 / (sgn + n.z);
    float fb = n.x * n.y * fa;
    vec3 ft = vec3(1.0 + sgn * n.x * n.x * fa, sgn * fb, -sgn * n.x);
    vec3 fbt = vec3(fb, sgn + n.y * n.y * fa, -n.y);
    // The lobe's horizon sine, at the mirror direction's azimuth (realtime_model.cpp).
    float lobeSinB = 0.0;
    if (uHorizonDirs > 0) {
        vec3 mirror = 2.0 * co * n - o;
        lobeSinB = horizonSine(vec3(dot(mirror, uRight), dot(mirror, uUp), 0.0));
    }
    // What the loop below needs of the pixel alone, once (the compiler does not hoist it): the
    // ceiling's plane and axes from p, and the horizon's smoothstep (an open horizon: always 1).
    vec3 pc = p - uLightCentre;
    float planeDist = -dot(pc, uLightNormal);
    vec3 eu = uEdgeU * uInvEdge2.x;
    vec3 ev = uEdgeV * uInvEdge2.y;
    float lu0 = dot(pc, eu) + 0.5;
    float lv0 = dot(pc, ev) + 0.5;
    float visFrom = -2.0;
    float visScale = 1.0;
    if (lobeSinB > 0.0) {
        visFrom = lobeSinB - uSoftness;
        visScale = 1.0 / max(2.0 * uSoftness, 1e-12);
    }
    float sum = 0.0;
    float nf = float(uSpecSamples);
    // The first BOOTH_UNROLLED_SPEC samples at constant indices (BOOTH_SPEC_CALLS: SPEC_AT(0)
    // SPEC_AT(1) ..., written out by the pass, as the lights are), then any beyond in a loop.
    // The same samples summed in the same order.
#define SPEC_AT(k)                                                                             \
    sum += specSample(k, n, o, co, ft, fbt, nGeo, planeDist, eu, ev, lu0, lv0, visFrom, visScale);
    BOOTH_SPEC_CALLS
#undef SPEC_AT
    for (int k = BOOTH_UNROLLED_SPEC; k < uSpecSamples; ++k) {
        sum += specSample(k, n, o, co, ft, fbt, nGeo, planeDist, eu, ev, lu0, lv0, visFrom,
                          visScale);
    }
    return sum / nf;
}

#if BOOTH_AREA_LIGHTS
// RenderSettings::areaLights: each region the uniform rectangle of its power, centroid and spread
// (booth::PointLight::region*), its irradiance by
// Lambert's contour integral over the part above the horizon. realtime_model.cpp clips the
// polygon whole (clipToHorizon, Sutherland-Hodgman) and sums its edges; here each edge is clipped
// on its own, with constant indices (llvmpipe spills a local array indexed by a counter), and the
// edge the clip adds along the horizon is the one from where the boundary leaves the half-space to
// where it comes back: the same polygon, its edges summed in another order.

// realtime_model.cpp edgeTerm without the normal: the angle a -> b subtends times
// normalize(a x b) (the edge's share of the polygon's vector irradiance, to be dotted with a
// normal); 0 for an edge of zero length or in line with the point.
vec3 edgeVector(vec3 a, vec3 b) {
    vec3 c = cross(a, b);
    float len = length(c);
    return len > 0.0 ? c * (atan(len, dot(a, b)) / len) : vec3(0.0);
}

// Edge a -> b (keep: whether it is part of the polygon) clipped to the horizon n . v >= 0: keep
// false where all of it is below; exitP or entryP set where it leaves or enters the half-space.
void clipEdge(inout vec3 a, inout vec3 b, inout bool keep, vec3 n, inout vec3 exitP,
              inout vec3 entryP, inout bool crossed) {
    float da = dot(n, a);
    float db = dot(n, b);
    bool aIn = da >= 0.0;
    bool bIn = db >= 0.0;
    // Only used where one end is above and one below: da - db is then nonzero.
    vec3 x = a + (b - a) * (da / (aIn != bIn ? da - db : 1.0));
    bool leaves = keep && aIn && !bIn;
    bool enters = keep && !aIn && bIn;
    exitP = leaves ? x : exitP;
    entryP = enters ? x : entryP;
    crossed = crossed || leaves;
    a = aIn ? a : x;
    b = bIn ? b : x;
    keep = keep && (aIn || bIn);
}

// realtime_model.cpp regionIrradiance for region i at p: its irradiance with the macro normal
// into eGeo, and on relief with the facet normal (the polygon clipped again to the facet's
// horizon) times the horizon's visibility along the region's centroid into e.
void diffuseLight(int i, vec3 p, vec3 nShade, bool relief, inout float eGeo, inout float e) {
    vec4 r = uLightRect[i];
    float lum = uLightSpreadU[i].w;
    vec3 base = uLightCentre - 0.5 * (uEdgeU + uEdgeV) - p;
    vec3 q0 = base + r.x * uEdgeU + r.y * uEdgeV;
    vec3 q1 = base + r.z * uEdgeU + r.y * uEdgeV;
    vec3 q2 = base + r.z * uEdgeU + r.w * uEdgeV;
    vec3 q3 = base + r.x * uEdgeU + r.w * uEdgeV;
    if (!(lum > 0.0) || !(-dot(q0, uLightNormal) > 0.0)) {
        return; // behind the emitting side or in its plane
    }
    // The quadrilateral's four edges and the horizon's edge (e4: exit -> entry) above the macro
    // surface.
    vec3 a0 = q0, b0 = q1, a1 = q1, b1 = q2, a2 = q2, b2 = q3, a3 = q3, b3 = q0;
    bool k0 = true, k1 = true, k2 = true, k3 = true;
    vec3 a4 = vec3(0.0), b4 = vec3(0.0);
    bool k4 = false;
    clipEdge(a0, b0, k0, uNormal, a4, b4, k4);
    clipEdge(a1, b1, k1, uNormal, a4, b4, k4);
    clipEdge(a2, b2, k2, uNormal, a4, b4, k4);
    clipEdge(a3, b3, k3, uNormal, a4, b4, k4);
    vec3 phi = (k0 ? edgeVector(a0, b0) : vec3(0.0)) + (k1 ? edgeVector(a1, b1) : vec3(0.0))
             + (k2 ? edgeVector(a2, b2) : vec3(0.0)) + (k3 ? edgeVector(a3, b3) : vec3(0.0))
             + (k4 ? edgeVector(a4, b4) : vec3(0.0));
    float eg = 0.5 * lum * abs(dot(uNormal, phi));
    eGeo += eg;
    if (relief && eg > 0.0) {
        // With every corner of that polygon above the facet's horizon too, its vector irradiance
        // serves the facet as it is (the edges' angles once, not twice); otherwise the five
        // edges are clipped to the facet's horizon and the edge that adds (e5) summed anew.
        bool below = (k0 && (dot(nShade, a0) < 0.0 || dot(nShade, b0) < 0.0))
                  || (k1 && (dot(nShade, a1) < 0.0 || dot(nShade, b1) < 0.0))
                  || (k2 && (dot(nShade, a2) < 0.0 || dot(nShade, b2) < 0.0))
                  || (k3 && (dot(nShade, a3) < 0.0 || dot(nShade, b3) < 0.0))
                  || (k4 && (dot(nShade, a4) < 0.0 || dot(nShade, b4) < 0.0));
        float es;
        if (below) {
            vec3 a5 = vec3(0.0), b5 = vec3(0.0);
            bool k5 = false;
            clipEdge(a0, b0, k0, nShade, a5, b5, k5);
            clipEdge(a1, b1, k1, nShade, a5, b5, k5);
            clipEdge(a2, b2, k2, nShade, a5, b5, k5);
            clipEdge(a3, b3, k3, nShade, a5, b5, k5);
            clipEdge(a4, b4, k4, nShade, a5, b5, k5);
            vec3 phiS = (k0 ? edgeVector(a0, b0) : vec3(0.0))
                      + (k1 ? edgeVector(a1, b1) : vec3(0.0))
                      + (k2 ? edgeVector(a2, b2) : vec3(0.0))
                      + (k3 ? edgeVector(a3, b3) : vec3(0.0))
                      + (k4 ? edgeVector(a4, b4) : vec3(0.0))
                      + (k5 ? edgeVector(a5, b5) : vec3(0.0));
            es = 0.5 * lum * abs(dot(nShade, phiS));
        } else {
            es = 0.5 * lum * abs(dot(nShade, phi));
        }
        if (es > 0.0) {
            // One horizon test, along the region's centroid (areaLightIrradiance).
            vec3 d = uLight[i].xyz - p;
            float d2 = dot(d, d);
            float v = 1.0;
            if (d2 > 0.0) {
                d *= inversesqrt(d2);
                float cosG = dot(uNormal, d);
                v = visibility(vec3(dot(d, uRight), dot(d, uUp), cosG),
                               lightSoftness(i, d, cosG, d2));
            }
            e += es * v;
        }
    }
}
#else
// Light i's share of eq. (1): to eGeo with the macro normal, to e with the facet normal and the
// horizon (relief only).
void diffuseLight(int i, vec3 p, vec3 nShade, bool relief, inout float eGeo, inout float e) {
    vec4 l = uLight[i];
    vec3 d = l.xyz - p;
    float d2 = dot(d, d);
    if (!(d2 > 0.0) || !(l.w > 0.0)) {
        return;
    }
    d *= inversesqrt(d2);
    float cosL = -dot(uLightNormal, d);
    float cosG = dot(uNormal, d);
    if (!(cosL > 0.0) || !(cosG > 0.0)) {
        return;
    }
    float g = l.w * cosL / max(d2, uTexelArea);
    eGeo += g * cosG;
    if (relief) {
        float cosS = dot(nShade, d);
        if (cosS > 0.0) {
            e += g * cosS *
                 visibility(vec3(dot(d, uRight), dot(d, uUp), cosG),
                            lightSoftness(i, d, cosG, d2));
        }
    }
}
#endif

vec3 bilinearNormal(float x, float y) {
    ivec2 c;
    vec2 a = bilinearTexel(x, y, c);
    float ax = a.x;
    float ay = a.y;
    ivec2 hi = uTexels - 1;
    vec3 n00 = texelFetch(uNormals, clamp(c, ivec2(0), hi), 0).xyz;
    vec3 n10 = texelFetch(uNormals, clamp(c + ivec2(1, 0), ivec2(0), hi), 0).xyz;
    vec3 n01 = texelFetch(uNormals, clamp(c + ivec2(0, 1), ivec2(0), hi), 0).xyz;
    vec3 n11 = texelFetch(uNormals, clamp(c + ivec2(1, 1), ivec2(0), hi), 0).xyz;
    vec3 n = (1.0 - ay) * ((1.0 - ax) * n00 + ax * n10) + ay * ((1.0 - ax) * n01 + ax * n11);
    float len = length(n);
    return len > 1e-12 ? n / len : vec3(0.0, 0.0, 1.0);
}

// realtime_model.cpp gridValue: bilinear between the four nodes around (u, v).
float gridValue(sampler2D grid, ivec2 nodes, float u, float v) {
    vec2 last = vec2(nodes - 1);
    vec2 f = clamp(vec2(u, v), 0.0, 1.0) * last;
    vec2 f0 = min(floor(f), last - 1.0);
    vec2 a = f - f0;
    ivec2 c = ivec2(f0);
    float s00 = texelFetch(grid, c, 0).r;
    float s10 = texelFetch(grid, c + ivec2(1, 0), 0).r;
    float s01 = texelFetch(grid, c + ivec2(0, 1), 0).r;
    float s11 = texelFetch(grid, c + ivec2(1, 1), 0).r;
    return (1.0 - a.y) * ((1.0 - a.x) * s00 + a.x * s10) + a.y * ((1.0 - a.x) * s01 + a.x * s11);
}

void main() {
    float u;
    float v;
    if (uMode == 2 || uMode == 3) {
        // A node of the specular or the diffuse grid (row j = v, down the surface, like the
        // textures' rows).
        vec2 node = floor(gl_FragCoord.xy);
        ivec2 nodes = uMode == 2 ? uGridNodes : uDiffNodes;
        u = node.x / float(nodes.x - 1);
        v = node.y / float(nodes.y - 1);
    } else {
        vec2 frag = gl_FragCoord.xy / uViewport;
        u = uSurfOffset.x + uSurfScale.x * frag.x;
        v = uSurfOffset.y + uSurfScale.y * (1.0 - frag.y);
    }
    bool inside = u >= 0.0 && u <= 1.0 && v >= 0.0 && v <= 1.0;
    // On the panel plane also around the surface: the flare term needs E_geo on every pixel.
    vec3 p = uCentre + uRight * ((u - 0.5) * uSizeM.x) + uUp * ((0.5 - v) * uSizeM.y);
    float texX = u * float(uTexels.x);
    float texY = v * float(uTexels.y);
#if BOOTH_EXACT_TIES
    // RenderSettings::texelExactTies (view.cpp shadingPoint's rule): the pixel's texel position
    // from its offset into the surface's pixels times the texels, divided last. For the
    // whole-pixel rectangles the CPU model renders the product is exact, and a correctly rounded
    // division (llvmpipe's) of it lands exactly on a texel edge where the pixel centre does, so
    // float takes the texel after the edge as double does. u * texels rounded such a centre
    // either way: at 48x30 a pixel row in thirty read the texel row before the CPU model's.
    if (uMode == 0 || uMode == 1) {
        vec2 along = vec2(gl_FragCoord.x - uSurfPixels.x, uSurfPixels.y - gl_FragCoord.y) *
                     vec2(uTexels);
        texX = along.x / uSurfPixels.z;
        texY = along.y / uSurfPixels.w;
    }
    ivec2 tc = clamp(ivec2(floor(vec2(texX, texY))), ivec2(0), uTexels - 1);
#else
    ivec2 tc = clamp(ivec2(int(texX), int(texY)), ivec2(0), uTexels - 1);
#endif
    vec3 nShade = uNormal;
    // Facets and horizons where this mode shades with them (the compose reads a grid's specular).
    bool facets = uMode == 0 || (uSpecSamples > 0 && (uMode == 2 || !kGrid));
    if (inside && uRelief && facets) {
#if BOOTH_FACET_CACHE && BOOTH_MODE == 1
        vec3 nl = texelFetch(uFacetCache, ivec2(gl_FragCoord.xy), 0).xyz;
#else
        vec3 nl = bilinearNormal(texX, texY);
#endif
#if BOOTH_FACET_CACHE && BOOTH_MODE == 0
        outFacet = vec4(nl, 0.0);
#endif
        nShade = normalize(uRight * nl.x + uUp * nl.y + uNormal * nl.z);
#if BOOTH_HORIZON_BILINEAR && BOOTH_MODE == 0
        // Eq. (1)'s horizons at this point (RenderSettings::horizonBilinear); the compose's lobe
        // reads the texel's below.
        bilinearHorizons(texX, texY);
#elif BOOTH_HORIZON_HALF
        for (int j = 0; j < (uHorizonDirs + 7) / 8; ++j) {
            uvec4 b = texelFetch(uHorizon, ivec3(tc, j), 0);
            for (int w = 0; w < 4; ++w) {
                vec2 pair = unpackHalf2x16(b[w]);
                hz[8 * j + 2 * w] = pair.x;
                hz[8 * j + 2 * w + 1] = pair.y;
            }
        }
#else
        for (int j = 0; j < (uHorizonDirs + 3) / 4; ++j) {
            vec4 b = texelFetch(uHorizon, ivec3(tc, j), 0);
            hz[4 * j] = b.x;
            hz[4 * j + 1] = b.y;
            hz[4 * j + 2] = b.z;
            hz[4 * j + 3] = b.w;
        }
#endif
    }

    if (uMode == 2) {
        float spec = 0.0;
        vec3 toEye = uEye - p;
        float eyeDist = length(toEye);
        toEye = eyeDist > 0.0 ? toEye / eyeDist : uNormal;
        if (dot(toEye, uNormal) > 0.0) {
            spec = filteredSpecular(p, uNormal, nShade, toEye);
        }
        outXyz = vec4((isnan(spec) || isinf(spec)) ? 0.0 : spec, 0.0, 0.0, 0.0);
        return;
    }
    if (uMode == 3) {
        // realtime_model.cpp's diffuse grid: eq. (1) with the macro normal at this node.
        float eg = 0.0;
        float unused = 0.0;
#define LIGHT_AT(k) if (k < uLightCount) { diffuseLight(k, p, uNormal, false, eg, unused); }
        BOOTH_LIGHT_CALLS
#undef LIGHT_AT
        for (int i = BOOTH_UNROLLED_LIGHTS; i < uLightCount; ++i) {
            diffuseLight(i, p, uNormal, false, eg, unused);
        }
        outXyz = vec4((isnan(eg) || isinf(eg)) ? 0.0 : eg, 0.0, 0.0, 0.0);
        return;
    }
    if (uMode == 0 && !inside) {
        // Around the surface only E_geo (pass 2's flare): eq. (1) with the macro normal, the
        // cosines clamped instead of tested: the same sum, and on llvmpipe about half the cost of
        // the full loop below, which ran here on every pixel of the panel (measured: a metamer
        // frame that recomputes the cache, 393 -> 217 ms on the loaded 2-core machine).
        float eg = 0.0;
#if BOOTH_AREA_LIGHTS
        float unused = 0.0;
        for (int i = 0; i < uLightCount; ++i) {
            diffuseLight(i, p, uNormal, false, eg, unused);
        }
#else
        for (int i = 0; i < uLightCount; ++i) {
            vec4 l = uLight[i];
            vec3 d = l.xyz - p;
            float d2 = max(dot(d, d), 1e-30);
            d *= inversesqrt(d2);
            eg += l.w * max(-dot(uLightNormal, d), 0.0) * max(dot(uNormal, d), 0.0)
                  / max(d2, uTexelArea);
        }
#endif
        outXyz = vec4(0.0, 0.0, 0.0, (isnan(eg) || isinf(eg)) ? 0.0 : eg);
        return;
    }
    if (uMode == 0) {
        // Eq. (1): eGeo with the macro normal (flare, flat scenes), e with facets and horizons.
        bool relief = inside && uRelief;
        float eGeo = 0.0;
        float e = 0.0;
        // The first BOOTH_UNROLLED_LIGHTS lights one after another at constant indices
        // (BOOTH_LIGHT_CALLS, written out by the pass: LIGHT_AT(0) LIGHT_AT(1) ...; llvmpipe
        // reads a uniform array at a loop counter as a gather per pixel, at a constant index as
        // one load), then any beyond them in a loop. Same lights in the same order.
#if BOOTH_DIFFUSE_GRID
        // Flat, and inside the surface here: E_geo between the diffuse grid's nodes.
        eGeo = gridValue(uDiffGrid, uDiffNodes, u, v);
#else
#define LIGHT_AT(k) if (k < uLightCount) { diffuseLight(k, p, nShade, relief, eGeo, e); }
        BOOTH_LIGHT_CALLS
#undef LIGHT_AT
        for (int i = BOOTH_UNROLLED_LIGHTS; i < uLightCount; ++i) {
            diffuseLight(i, p, nShade, relief, eGeo, e);
        }
#endif
        if (!relief) {
            e = eGeo;
        }
        if (!uDiffuse) {
            e = 0.0;
        }
        vec3 xyz = vec3(0.0); // the panel around the surface stays black
        if (inside) {
            // Eq. (2): channel coefficients times the light's per-channel XYZ.
            vec3 a = texelFetch(uCoeffA, tc, 0).rgb;
            vec3 b = texelFetch(uCoeffB, tc, 0).rgb;
            xyz = a.r * uChannelXyz[0] + a.g * uChannelXyz[1] + a.b * uChannelXyz[2]
                + b.r * uChannelXyz[3] + b.g * uChannelXyz[4] + b.b * uChannelXyz[5];
            xyz *= e / kPi;
        }
        if (isnan(eGeo) || isinf(eGeo)) {
            eGeo = 0.0;
        }
        if (uSpecSamples == 0 && uFlareRho == 0.0) {
            // Nothing left for the compose: the cache is the frame (clamped as mode 1 would).
            xyz = max(xyz, vec3(0.0));
            if (any(isnan(xyz)) || any(isinf(xyz))) {
                xyz = vec3(0.0);
            }
        }
        outXyz = vec4(xyz, eGeo);
        return;
    }

    // Compose (drawn over the surface's rectangle only; around it the frame is the cache): the
    // cached diffuse term and E_geo, plus this eye's specular, minus the flare.
    vec4 cached = texelFetch(uCache, ivec2(gl_FragCoord.xy), 0);
    vec3 xyz = cached.rgb;
    float eGeo = cached.a;
    if (kGrid) {
        if (inside) {
            xyz += uSpecXyz * gridValue(uSpecGrid, uGridNodes, u, v);
        }
    } else if (inside && uSpecSamples > 0) {
        vec3 toEye = uEye - p;
        float eyeDist = length(toEye);
        toEye = eyeDist > 0.0 ? toEye / eyeDist : uNormal;
        bool behind = !(dot(toEye, uNormal) > 0.0);
        if (!behind) {
            xyz += uSpecXyz * filteredSpecular(p, uNormal, nShade, toEye);
        }
    }
    vec3 outv = max(xyz - uWhite * (uFlareRho * eGeo / kPi), vec3(0.0));
    if (any(isnan(outv)) || any(isinf(outv))) {
        outv = vec3(0.0); // never reaches a pixel; the read-back check counts none
    }
    if (isnan(eGeo) || isinf(eGeo)) {
        eGeo = 0.0;
    }
    outXyz = vec4(outv, eGeo);
}
)";

} // namespace replica::pipeline::render
