// The four modes of the pass (booth_shading_pass.cpp says when each runs), as the pixel loop of
// shading/realtime_model.cpp renderRealtime: eq. (1)'s cache, eq. (2)'s channel sum
// (colour::ChannelCoeffs times the light's per-channel XYZ), the specular grid, and the compose
// minus the screen's front-surface flare.

// The surface coordinates (u, v) this fragment shades: a node of the specular or the diffuse grid
// (modes 2 and 3; row j = v, down the surface, like the textures' rows), or the pixel's point.
vec2 surfaceUv() {
    if (uMode == 2 || uMode == 3) {
        vec2 node = floor(gl_FragCoord.xy);
        ivec2 nodes = uMode == 2 ? uGridNodes : uDiffNodes;
        return vec2(node.x / float(nodes.x - 1), node.y / float(nodes.y - 1));
    }
    vec2 frag = gl_FragCoord.xy / uViewport;
    return vec2(uSurfOffset.x + uSurfScale.x * frag.x, uSurfOffset.y + uSurfScale.y * (1.0 - frag.y));
}

// The texel position of (u, v). In the pixel modes view.cpp shadingPoint's rule: the pixel's texel
// position from its offset into the surface's pixels times the texels, divided last. For the
// whole-pixel rectangles the CPU model renders the product is exact, and a correctly rounded
// division (llvmpipe's) of it lands exactly on a texel edge where the pixel centre does, so float
// takes the texel after the edge as double does. u * texels rounded such a centre either way: at
// 48x30 a pixel row in thirty read the texel row before the CPU model's.
vec2 texelPosition(vec2 uv) {
    if (uMode == 0 || uMode == 1) {
        vec2 along = vec2(gl_FragCoord.x - uSurfPixels.x, uSurfPixels.y - gl_FragCoord.y) *
                     vec2(uTexels);
        return vec2(along.x / uSurfPixels.z, along.y / uSurfPixels.w);
    }
    return vec2(uv.x * float(uTexels.x), uv.y * float(uTexels.y));
}

// The facet normal at the texel position (world frame), and its horizons into hz: eq. (1)'s
// bilinear horizons in the cache, the texel's in the compose's lobe.
vec3 facetNormal(vec2 tex, ivec2 tc) {
#if BOOTH_FACET_CACHE && BOOTH_MODE == 1
    vec3 nl = texelFetch(uFacetCache, ivec2(gl_FragCoord.xy), 0).xyz;
#else
    vec3 nl = sampleNormal(tex.x, tex.y);
#endif
#if BOOTH_FACET_CACHE && BOOTH_MODE == 0
    outFacet = vec4(nl, 0.0);
#endif
#if BOOTH_MODE == 0 || BOOTH_MODE == 3
    bilinearHorizons(tex.x, tex.y);
#else
    for (int j = 0; j < (uHorizonDirs + 7) / 8; ++j) {
        uvec4 b = texelFetch(uHorizon, ivec3(tc, j), 0);
        for (int w = 0; w < 4; ++w) {
            vec2 pair = unpackHalf2x16(b[w]);
            hz[8 * j + 2 * w] = pair.x;
            hz[8 * j + 2 * w + 1] = pair.y;
        }
    }
#endif
    return normalize(uRight * nl.x + uUp * nl.y + uNormal * nl.z);
}

float finiteOrZero(float x) {
    return (isnan(x) || isinf(x)) ? 0.0 : x;
}

// Mode 2: a node of the specular grid.
void specularNode(vec3 p, vec3 nShade) {
    float spec = 0.0;
    vec3 toEye = uEye - p;
    float eyeDist = length(toEye);
    toEye = eyeDist > 0.0 ? toEye / eyeDist : uNormal;
    if (dot(toEye, uNormal) > 0.0) {
        spec = filteredSpecular(p, uNormal, nShade, toEye);
    }
    outXyz = vec4(finiteOrZero(spec), 0.0, 0.0, 0.0);
}

// Mode 3: realtime_model.cpp's diffuse grid: eq. (1) with the macro normal at this node, and on
// relief with the node's facet and horizons too (green; the texture is RG32F there).
void diffuseNode(vec3 p, vec3 nShade) {
    float eg = 0.0;
    float e = 0.0;
    bool relief = uRelief;
#define LIGHT_AT(k) if (k < uLightCount) { diffuseLight(k, p, nShade, relief, eg, e); }
    BOOTH_LIGHT_CALLS
#undef LIGHT_AT
    for (int i = BOOTH_UNROLLED_LIGHTS; i < uLightCount; ++i) {
        diffuseLight(i, p, nShade, relief, eg, e);
    }
    outXyz = vec4(finiteOrZero(eg), finiteOrZero(e), 0.0, 0.0);
}

// Mode 0 around the surface: only E_geo (pass 2's flare): eq. (1) with the macro normal, the
// cosines clamped instead of tested: the same sum, and on llvmpipe about half the cost of the full
// loop of the cache, which ran here on every pixel of the panel (measured: a metamer frame that
// recomputes the cache, 393 -> 217 ms on the loaded 2-core machine).
void flareOnly(vec3 p, vec2 uv) {
    float eg = 0.0;
#if defined(BOOTH_WALLS)
    eg += wallLight(uv, uNormal); // the nearest edge's, around the surface
#endif
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
    outXyz = vec4(0.0, 0.0, 0.0, finiteOrZero(eg));
}

// Mode 0 on the surface: the cache. Eq. (1): eGeo with the macro normal (flare, flat scenes), e
// with facets and horizons; eq. (2) the colour.
void diffuseCache(vec3 p, vec3 nShade, vec2 uv, ivec2 tc, bool inside) {
    bool relief = inside && uRelief;
    float eGeo = 0.0;
    float e = 0.0;
    // The first BOOTH_UNROLLED_LIGHTS lights one after another at constant indices
    // (BOOTH_LIGHT_CALLS, written out by the pass: LIGHT_AT(0) LIGHT_AT(1) ...; llvmpipe reads a
    // uniform array at a loop counter as a gather per pixel, at a constant index as one load), then
    // any beyond them in a loop. Same lights in the same order.
#if BOOTH_DIFFUSE_GRID
    // Inside the surface here: E_geo between the diffuse grid's nodes, and on relief eq. (1) with
    // facets and horizons too, taken at each node.
    eGeo = gridValue(uDiffGrid, uDiffNodes, uv.x, uv.y);
    if (relief) {
        e = gridChannel(uDiffGrid, uDiffNodes, uv.x, uv.y, 1);
    }
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
#if defined(BOOTH_WALLS)
    {
        float wallGeo = wallLight(uv, uNormal);
        e += relief ? wallLight(uv, nShade) : wallGeo;
        eGeo += wallGeo;
    }
#endif
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
    eGeo = finiteOrZero(eGeo);
    if (!kSpecular && uFlareRho == 0.0) {
        // Nothing left for the compose: the cache is the frame (clamped as mode 1 would).
        xyz = max(xyz, vec3(0.0));
        if (any(isnan(xyz)) || any(isinf(xyz))) {
            xyz = vec3(0.0);
        }
    }
    outXyz = vec4(xyz, eGeo);
}

// Mode 1, the compose (drawn over the surface's rectangle only; around it the frame is the cache):
// the cached diffuse term and E_geo, plus this eye's specular, minus the flare.
void compose(vec3 p, vec3 nShade, vec2 uv, bool inside) {
    vec4 cached = texelFetch(uCache, ivec2(gl_FragCoord.xy), 0);
    vec3 xyz = cached.rgb;
    float eGeo = cached.a;
    if (kGrid) {
        if (inside) {
            xyz += uSpecXyz * gridValue(uSpecGrid, uGridNodes, uv.x, uv.y);
        }
    } else if (inside && kSpecular) {
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
    outXyz = vec4(outv, finiteOrZero(eGeo));
}

void main() {
    vec2 uv = surfaceUv();
    bool inside = uv.x >= 0.0 && uv.x <= 1.0 && uv.y >= 0.0 && uv.y <= 1.0;
#if BOOTH_MODE == 0 && BOOTH_SURROUND
    // Mode 0 is two programs, each without the other's code, which llvmpipe would run for every
    // pixel under a mask: this one, drawn after the surface's over the pixels that may lie around
    // the surface (booth_diffuse_cache.cpp), leaves the surface's pixels as that one drew them.
    if (inside) {
        discard;
    }
#endif
    // On the panel plane also around the surface: the flare term needs E_geo on every pixel.
    vec3 p = uCentre + uRight * ((uv.x - 0.5) * uSizeM.x) + uUp * ((0.5 - uv.y) * uSizeM.y);
    vec2 tex = texelPosition(uv);
    ivec2 tc = clamp(ivec2(floor(tex)), ivec2(0), uTexels - 1);
    vec3 nShade = uNormal;
    // Facets and horizons where this mode shades with them (the compose reads a grid's specular).
    bool facets = uMode == 0 || uMode == 3 || (kSpecular && (uMode == 2 || !kGrid));
#if !(BOOTH_MODE == 0 && BOOTH_SURROUND)
    if (inside && uRelief && facets) {
        nShade = facetNormal(tex, tc);
    }
#endif
    if (uMode == 2) {
        specularNode(p, nShade);
    } else if (uMode == 3) {
        diffuseNode(p, nShade);
    } else if (uMode == 0) {
#if BOOTH_SURROUND
        flareOnly(p, uv); // around the surface: only E_geo
#else
        diffuseCache(p, nShade, uv, tc, inside);
#endif
    } else {
        compose(p, nShade, uv, inside);
    }
}
