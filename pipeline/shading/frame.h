// An absolute-XYZ frame (cd/m^2) and the counters every renderer fills in.
#pragma once

#include <vector>

#include <pipeline/colour/xyz.h>

namespace replica::pipeline::shading {

constexpr double kScreenFlareRho = 0.002; // diffuse reflectance of the panel's front surface

struct XyzFrame {
    int width = 0;
    int height = 0;
    std::vector<colour::Xyz> xyz; // what the panel must emit: surface radiance minus screen flare
    double whiteY = 0.0;          // Y of a perfect white diffuser at the panel centre (Lab white)
    colour::Xyz whiteXyz{0.0};
    long flareClamped = 0;    // pixel components where flare exceeded the surface (set to 0)
    long eyeBehindPixels = 0; // eye at or behind the surface plane: specular forced to 0
    long nonFinite = 0;       // must stay 0: counted, then replaced by 0 (never reaches a pixel)
};

// Flare subtraction for one pixel: never below zero, clamps counted.
colour::Xyz subtractFlare(const colour::Xyz& surface, const colour::Xyz& flare, long& clamped);

} // namespace replica::pipeline::shading
