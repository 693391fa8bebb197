// Per-pixel lookups: the facet normal (surface::NormalMap's bilinear rule) and
// shading/realtime_model.cpp gridValue (the diffuse and specular grids).

// shading/view.cpp sampleNormal: the facet normal bilinear at texel position (x, y), normalised.
vec3 sampleNormal(float x, float y) {
    ivec2 c;
    vec2 a = bilinearTexel(x, y, c);
    float ax = a.x;
    float ay = a.y;
    ivec2 hi = uTexels - 1;
    vec3 n00 = texelFetch(uNormals, clamp(c, ivec2(0), hi), 0).xyz;
    vec3 n10 = texelFetch(uNormals, clamp(c + ivec2(1, 0), ivec2(0), hi), 0).xyz;
    vec3 n01 = texelFetch(uNormals, clamp(c + ivec2(0, 1), ivec2(0), hi), 0).xyz;
    vec3 n11 = texelFetch(uNormals, clamp(c + ivec2(1, 1), ivec2(0), hi), 0).xyz;
    vec3 n = (1.0 - ay) * ((1.0 - ax) * n00 + ax * n10) + ay * ((1.0 - ax) * n01 + ax * n11);
    float len = length(n);
    return len > 1e-12 ? n / len : vec3(0.0, 0.0, 1.0);
}

// realtime_model.cpp gridValue: bilinear between the four nodes around (u, v). gridCell finds
// them (c the one below and left) and the weights towards the others.
ivec2 gridCell(ivec2 nodes, float u, float v, out vec2 a) {
    vec2 last = vec2(nodes - 1);
    vec2 f = clamp(vec2(u, v), 0.0, 1.0) * last;
    vec2 f0 = min(floor(f), last - 1.0);
    a = f - f0;
    return ivec2(f0);
}

float gridBilinear(float s00, float s10, float s01, float s11, vec2 a) {
    return (1.0 - a.y) * ((1.0 - a.x) * s00 + a.x * s10) + a.y * ((1.0 - a.x) * s01 + a.x * s11);
}

// Channel 'k' of the grid (0 for both grids; 1: the diffuse grid's eq. (1) on relief); every
// caller passes a constant, which the compiler folds into a plain component read.
float gridChannel(sampler2D grid, ivec2 nodes, float u, float v, int k) {
    vec2 a;
    ivec2 c = gridCell(nodes, u, v, a);
    return gridBilinear(texelFetch(grid, c, 0)[k], texelFetch(grid, c + ivec2(1, 0), 0)[k],
                        texelFetch(grid, c + ivec2(0, 1), 0)[k],
                        texelFetch(grid, c + ivec2(1, 1), 0)[k], a);
}

float gridValue(sampler2D grid, ivec2 nodes, float u, float v) {
    return gridChannel(grid, nodes, u, v, 0);
}
