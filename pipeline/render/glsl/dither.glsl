// Ordered dither to integer counts (display/dither.cpp: ditherPattern, quantiseCount).

// display/dither.cpp ditherThreshold: ditherPattern()'s threshold at the pixel, computed by the same bit interleaving: a dozen
// integer operations where a texel read was a gather per pixel on llvmpipe (3.5 M instructions
// of the painting's frame). The same floats: v + 0.5 and the division by 256 are exact.
float ditherThreshold(ivec2 pixel) {
    int y = pixel.y & 15;
    int xy = (pixel.x & 15) ^ y;
    int v = 0;
    for (int bit = 0; bit < 4; ++bit) {
        v = (v << 2) | (((xy >> bit) & 1) << 1) | ((y >> bit) & 1);
    }
    return (float(v) + 0.5) / 256.0;
}

// display/dither.cpp quantiseCount, three channels at once.
vec3 quantiseCount(vec3 countsIn, ivec2 pixel) {
    float t = ditherThreshold(pixel);
    return clamp(floor(countsIn + vec3(t)), vec3(0.0), vec3(uDispMaxCount));
}
