// The booth's walls (BOOTH_WALLS, RenderSettings::walls): shading/wall_field.cpp wallFieldAt.
// Their illuminance on the macro normal at 3 x 3 nodes over the surface, biquadratic between
// them, plus the vector irradiance's share for a facet; set for each pose the cache is drawn at
// (BoothPrograms::usePose).
#if defined(BOOTH_WALLS)
uniform float uWallE[9]; // lux at (u, v) in {0, 1/2, 1}^2, row by row (v down)
uniform vec3 uWallVec;   // the walls' vector irradiance at the surface's centre (lux)

vec3 quadraticWeights(float t) {
    return vec3(2.0 * (t - 0.5) * (t - 1.0), -4.0 * t * (t - 1.0), 2.0 * t * (t - 0.5));
}

float wallLight(vec2 uv, vec3 n) {
    vec2 t = clamp(uv, 0.0, 1.0);
    vec3 wu = quadraticWeights(t.x);
    vec3 wv = quadraticWeights(t.y);
    vec3 rows = vec3(dot(wu, vec3(uWallE[0], uWallE[1], uWallE[2])),
                     dot(wu, vec3(uWallE[3], uWallE[4], uWallE[5])),
                     dot(wu, vec3(uWallE[6], uWallE[7], uWallE[8])));
    return max(dot(wv, rows) + dot(uWallVec, n - uNormal), 0.0);
}
#endif
