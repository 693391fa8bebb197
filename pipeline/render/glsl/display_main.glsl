// The display pass's main: flare subtracted (the panel's front-surface reflection of the
// booth light, display/display_model.cpp: frontSurfaceFlareXyz, from the illuminance on the panel
// that pass 1 wrote into the texel's alpha), the viewing-angle gain divided out, inverted to
// counts, dithered; false colour marks the out-of-gamut pixels when asked.
// Flare first (the reflection reaches the eye whatever the panel emits), then the viewing-angle
// gain (it scales only what the panel emits): eye = gain * emitted + flare.

const vec3 kFalseColour[4] = vec3[4](vec3(0.0), vec3(1.0, 0.0, 1.0), vec3(0.0, 1.0, 1.0),
                                     vec3(0.0, 0.3, 1.0));
void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 texel = texelFetch(uXyz, px, 0);
    vec3 xyz = texel.xyz;
    vec3 p = uDispPanelOrigin + vUv.x * uDispPanelRight + vUv.y * uDispPanelUp;
    xyz -= texel.w * uDispFlarePerLux; // E (lux) from pass 1, the texel's alpha
    if (uDispViewingOn != 0) {
        vec3 toEye = uDispEye - p;
        float len = length(toEye);
        float c = len > 1e-6 ? dot(toEye, uDispPanelNormal) / len : 1.0;
        float angle = c > 0.0 ? degrees(acos(min(c, 1.0))) : 90.0;
        xyz /= max(viewingGain(angle), vec3(1e-3));
    }
    vec3 drive;
    float cls;
    if (uDispMethod == 1) {
        cls = gamutClass(xyz);
        drive = counts(xyz);
    } else {
        vec4 inv = invert(xyz, uDispGamutMode);
        drive = inv.xyz;
        cls = inv.w;
    }
    vec3 q = quantiseCount(drive, px) / uDispMaxCount;
    if (uDispFalseColour != 0 && cls > 0.0 && ((px.x + px.y) & 4) == 0) {
        q = kFalseColour[int(cls)];
    }
    outRgba = vec4(q, 1.0);
    outClass = cls / 255.0;
}
