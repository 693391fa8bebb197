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

// realtime_model.cpp gridValue: bilinear between the four nodes around (u, v).
float gridValue(sampler2D grid, ivec2 nodes, float u, float v) {
    vec2 last = vec2(nodes - 1);
    vec2 f = clamp(vec2(u, v), 0.0, 1.0) * last;
    vec2 f0 = min(floor(f), last - 1.0);
    vec2 a = f - f0;
    ivec2 c = ivec2(f0);
    float s00 = texelFetch(grid, c, 0).r;
    float s10 = texelFetch(grid, c + ivec2(1, 0), 0).r;
    float s01 = texelFetch(grid, c + ivec2(0, 1), 0).r;
    float s11 = texelFetch(grid, c + ivec2(1, 1), 0).r;
    return (1.0 - a.y) * ((1.0 - a.x) * s00 + a.x * s10) + a.y * ((1.0 - a.x) * s01 + a.x * s11);
}
