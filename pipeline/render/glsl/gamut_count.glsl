// The gamut-count compute shader (DisplayPass::countClasses): the pixels of each gamut class in
// a rectangle of the class target, summed into four counters. Compiled after "#version 310 es"
// and "#define COUNT_RUN n".
// One invocation per COUNT_RUN x 2 pixels of the rectangle [uOrigin, uEnd): it reads the class
// of a 2x2 block at a time with textureGather (one read where four texelFetch were), counts in
// registers and adds each nonzero sum to the buffer once. The painting's highlights put 40 % of
// its pixels over peak, and an atomic add per pixel (60 000 a frame on three words of one buffer)
// cost llvmpipe's two threads about 3 ms of cache-line traffic. (Counting a workgroup's pixels in
// shared memory instead was slower still: llvmpipe runs barrier() as a coroutine switch.)

layout(local_size_x = 8, local_size_y = 8) in;
uniform highp sampler2D uClass;
uniform ivec2 uOrigin;
uniform ivec2 uEnd;
layout(std430, binding = 0) buffer Counts { uint counts[4]; };
uvec4 classCounts(vec4 cls, bvec4 in4) {
    ivec4 c = ivec4(cls * 255.0 + 0.5);
    uvec4 n = uvec4(0u);
    for (int k = 0; k < 4; ++k) {
        n += in4[k] ? uvec4(equal(ivec4(c[k]), ivec4(0, 1, 2, 3))) : uvec4(0u);
    }
    return n;
}
void main() {
    ivec2 p = uOrigin + ivec2(gl_GlobalInvocationID.xy) * ivec2(COUNT_RUN, 2);
    if (p.y >= uEnd.y) {
        return;
    }
    vec2 size = vec2(textureSize(uClass, 0));
    uvec4 n = uvec4(0u);
    bool row1 = p.y + 1 < uEnd.y;
    for (int k = 0; k < COUNT_RUN; k += 2) {
        int x = p.x + k;
        if (x < uEnd.x) {
            // The block's shared corner: the gather takes texels x, x + 1 and y, y + 1 (the
            // corner is half a texel from each texel centre, so rounding cannot move it).
            vec4 cls = textureGather(uClass, vec2(float(x + 1), float(p.y + 1)) / size, 0);
            // textureGather's order: (x, y + 1), (x + 1, y + 1), (x + 1, y), (x, y).
            bool col1 = x + 1 < uEnd.x;
            n += classCounts(cls, bvec4(row1, row1 && col1, col1, true));
        }
    }
    for (int c = 1; c < 4; ++c) {
        if (n[c] > 0u) {
            atomicAdd(counts[c], n[c]);
        }
    }
}
