// Eq. (1) from the median-cut point lights: shading/realtime_model.cpp pointLightIrradiance.

#if !BOOTH_AREA_LIGHTS
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
                 horizonVisibility(vec3(dot(d, uRight), dot(d, uUp), cosG),
                            lightSoftness(i, d, cosG, d2));
        }
    }
}
#endif
