// The display pass (pass 2): XYZ (cd/m^2) in, panel counts and each pixel's gamut class out.
// What every piece after this file reads: the pass-1 frame, the DISP_* switches compiled in
// (DisplayPass::init), the pose and eye of the frame. Compiled after "#version 310 es" and
// the DISP_* defines; the pieces follow in the order pipeline/CMakeLists.txt lists them.

precision highp float;
precision highp int;
precision highp sampler3D;
in vec2 vUv;
layout(location = 0) out vec4 outRgba;
layout(location = 1) out float outClass;
uniform highp sampler2D uXyz;
// Fixed for the pass's life and compiled in (DisplayPass::init), so that the program carries
// only the inverse, gamut mode and overlays it runs: llvmpipe executes an untaken branch under a
// mask, and the 3-D LUT path cost every analytic frame its tetrahedral fetches.
const int uDispMethod = DISP_METHOD;         // 0 analytic, 1 3-D LUT
const int uDispGamutMode = DISP_GAMUT_MODE;  // 0 hue-keeping, 1 per-channel clip
const int uDispViewingOn = DISP_VIEWING;
const int uDispFalseColour = DISP_FALSE_COLOUR;
uniform vec3 uDispEye;
uniform vec3 uDispPanelOrigin;
uniform vec3 uDispPanelRight;
uniform vec3 uDispPanelUp;
uniform vec3 uDispPanelNormal;
uniform vec3 uDispFlarePerLux;  // rho_d / pi times the light's XYZ with Y = 1; 0 when off
