// Eq. (1) from areas (BOOTH_AREA_LIGHTS): shading/realtime_model.cpp areaLightIrradiance,
// regionIrradiance, edgeTerm and clipToHorizon.

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
                v = horizonVisibility(vec3(dot(d, uRight), dot(d, uUp), cosG),
                               lightSoftness(i, d, cosG, d2));
            }
            e += es * v;
        }
    }
}
#endif
