// The ceiling's luminance mip chain: booth::MipChain::sample / sampleNearestLevel
// (booth/luminance_image.cpp), by the sampler or by texelFetch.

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
// booth::MipChain::sampleNearestLevel.
float lumSample(float u, float v, float level) {
    float l = clamp(level, 0.0, float(uLumMaxLevel));
    int d = l <= 0.5 ? 0 : min(int(ceil(l + 0.5)) - 1, uLumMaxLevel);
    return lumBilinear(u * uLumUsed.x, v * uLumUsed.y, d);
}
#endif
