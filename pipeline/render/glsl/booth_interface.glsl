// The booth shading pass's interface: precisions, outputs, uniforms and the constants every
// piece below reads. Compiled after "#version 310 es" and the pass's BOOTH_* defines
// (booth_shading_pass.cpp); the pieces follow in the order pipeline/CMakeLists.txt lists them.

precision highp float;
precision highp int;
precision highp sampler2D;
precision highp sampler2DArray;
out vec4 outXyz;

// Pixel -> surface: su, sv (sv down the image) = offset + scale * (pixel centre / viewport).
uniform vec2 uViewport;
uniform vec2 uSurfOffset;
uniform vec2 uSurfScale;
// The surface's pixel rectangle in window coordinates (for view.cpp shadingPoint's texel rule):
// left edge x, top edge y (window y runs up), width and height in pixels; from uSurfOffset,
// uSurfScale and uViewport.
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
// sin(horizon elevation): 8 directions a layer as half floats, two a word (booth_upload.cpp
// horizonTexture; the CPU model reads the same rounded sines, PreparedScene::horizonHalf).
uniform highp usampler2DArray uHorizon;
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
// facet normal (tangent frame, sampleNormal's) beside the cache, and the compose reads it there:
// one texel a frame instead of four and a normalisation.
#if BOOTH_FACET_CACHE && BOOTH_MODE == 0
layout(location = 1) out vec4 outFacet;
#endif
uniform sampler2D uFacetCache;  // RGBA32F, the viewport's size: what mode 0 wrote

// Whether the pass has a specular term (fixed for its life, like the modes); how many samples it
// takes is a uniform: each lamp of a plan may take its own count, and lamps that share everything
// else share one program, so that a lamp switch compiles nothing (booth_scene_pass.h).
const bool kSpecular = BOOTH_SPECULAR != 0;
uniform int uSpecSamples;
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
uniform float uLodScale;        // 4^RenderSettings::specularLodBias, exact (a whole half level)

const float kPi = 3.14159265358979;
const float kMinCosView = 1e-3;
