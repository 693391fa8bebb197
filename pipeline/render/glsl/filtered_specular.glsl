// Eq. (3): the Ward(-Duer) specular term by filtered importance sampling:
// shading/realtime_model.cpp filteredSpecular with brdf::sampleWard (brdf/ward.cpp) inlined.

// Sample k of filteredSpecular's loop (brdf::sampleWard inlined, rho_s = 1): its weighted
// luminance, 0 where the sample leaves the lobe, the surface or the ceiling. Every pixel computes
// the sample and keeps it or 0 at the end, without early returns: llvmpipe runs each early return
// as a masked branch with masked stores after it, and a lane that fails a test only ever yields 0.
float specSample(int k, vec3 n, vec3 o, float co, vec3 ft, vec3 fbt, vec3 nGeo, float planeDist,
                 vec3 eu, vec3 ev, float lu0, float lv0, float visFrom, float visScale) {
    vec4 sk = uSpecSample[k];
    vec3 hl = sk.xyz;
    vec3 h = ft * hl.x + fbt * hl.y + n * hl.z;
    float oh = dot(o, h);
    vec3 i = 2.0 * oh * h - o;
    float ci = dot(n, i);
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
    float t = planeDist / denom;
    float lu = lu0 + t * dot(i, eu);
    float lv = lv0 + t * dot(i, ev);
    bool onCeiling = lu >= 0.0 && lu <= 1.0 && lv >= 0.0 && lv <= 1.0;
    float ratio = solidAngle * t * t / (uTexelArea * -denom);
    // sampleNearestLevel's level d = ceil(l + 0.5) - 1 for
    // l = 0.5 log2(r) + bias > 0.5, else 0, is ceil(log2(r 4^bias)) halved and rounded down, and
    // for a normal float r ceil(log2 r) is its exponent plus one unless the mantissa is zero:
    // adding the largest mantissa carries into the exponent exactly then. (llvmpipe's log2 is a
    // polynomial.) The ratio is kept within normal floats; d < 0 clamps to level 0 below.
    float r = clamp(ratio, 1e-20, 1e30) * uLodScale;
    float lod = float((((floatBitsToInt(r) + 0x7fffff) >> 23) - 127) >> 1);
    float vis = clamp((cosG - visFrom) * visScale, 0.0, 1.0);
    float value = lumSample(lu, lv, lod) * w * (vis * vis * (3.0 - 2.0 * vis));
    // The early returns' tests: a half vector facing the eye and a mirror direction above the
    // facet; above the macro surface and towards the ceiling's plane; ahead of the point and
    // finite; inside the ceiling.
    bool inLobe = oh > 0.0 && ci > 0.0;
    bool towardsCeiling = cosG > 0.0 && denom < 0.0 && t > 0.0 && !isinf(t);
    return inLobe && towardsCeiling && onCeiling ? value : 0.0;
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
        lobeSinB = sinHorizon(vec3(dot(mirror, uRight), dot(mirror, uUp), 0.0));
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
    // SPEC_AT(1) ..., written out by the pass, as the lights are), then any beyond in a loop to
    // the lamp's count (a pass that several lamps share writes out the fewest of them: llvmpipe
    // runs an `if` under a mask, so a sample kept to the count would cost every lamp the most).
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
