// The panel's off-axis gain (display/viewing_angle.cpp: viewingGain), divided out of what the
// panel must emit.

// The row count is compiled in (DISP_VIEWING_ROWS, from the profile). The segment is the first
// row i whose next angle is above a (what a search up the table returns): with the angles rising,
// i counts the inner rows at or below a. Counting costs a compare a row; only that segment is
// interpolated (llvmpipe ran all eleven divisions and mixes when each row interpolated under its
// own test). At or past the last angle, and for a NaN, the last row's gain.
// display/viewing_angle.cpp viewingGain at angleDeg.
vec3 viewingGain(float angleDeg) {
#if DISP_VIEWING_ROWS <= 0
    return vec3(1.0);
#elif DISP_VIEWING_ROWS == 1
    return uDispViewing[0].yzw;
#elif DISP_VIEWING_FILTERED
    // Where the GL filters float textures: the gain every half degree, interpolated by the sampler.
    // One filtered read where the row count, two indexed uniform reads (a gather per component
    // on llvmpipe) and a division were: 6 % of the painting's frame. NaN and 90 degrees or more
    // take the last node, the last row's gain.
    float a = angleDeg < 90.0 ? max(angleDeg, 0.0) : 90.0;
    return texture(uDispViewingGrid,
                   vec2((a * float(DISP_VIEWING_GRID_PER_DEG) + 0.5) / float(DISP_VIEWING_GRID_NODES),
                        0.5)).rgb;
#else
    // Without GL_OES_texture_float_linear: the rows themselves.
    float a = clamp(angleDeg, 0.0, 90.0);
    if (!(a < uDispViewing[DISP_VIEWING_ROWS - 1].x)) {
        return uDispViewing[DISP_VIEWING_ROWS - 1].yzw;
    }
    int i = 0;
    for (int k = 1; k < DISP_VIEWING_ROWS - 1; ++k) {
        i += a >= uDispViewing[k].x ? 1 : 0;
    }
    vec4 lo = uDispViewing[i];
    vec4 hi = uDispViewing[i + 1];
    return mix(lo.yzw, hi.yzw, (a - lo.x) / (hi.x - lo.x));
#endif
}

