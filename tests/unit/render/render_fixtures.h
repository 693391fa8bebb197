// Small lights and scenes built in code for the booth, surface and render tests.
#pragma once

#include <cmath>

#include <pipeline/base/data_dir.h>
#include <pipeline/booth/booth_light.h>
#include <pipeline/colour/xyz.h>
#include <pipeline/surface/surface_scene.h>

namespace replica::test {

inline pipeline::booth::BoothLight ceilingLight(
        int w, int h, double cdM2, double heightM = 0.6, double sizeU = 1.0, double sizeV = 0.5)
{
    pipeline::booth::BoothLight l;
    l.name = "test";
    l.centre = {0.0, heightM, 0.0};
    l.edgeU = {sizeU, 0.0, 0.0};
    l.edgeV = {0.0, 0.0, sizeV}; // cross(u, v) = -y: emits downwards
    l.luminance = pipeline::booth::LuminanceImage::filled(w, h, cdM2);
    l.spd = pipeline::colour::Spectrum::constant(1.0);
    return l;
}

// Stripes like fluorescent tubes on a dimmer diffuser, with fall-off to the edges.
inline pipeline::booth::BoothLight stripedLight(int w, int h, double heightM = 0.6)
{
    auto l = ceilingLight(w, h, 0.0, heightM);
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            const double u = (x + 0.5) / w;
            const double v = (y + 0.5) / h;
            double lum = 800.0;
            for (double c : {0.2, 0.4, 0.6, 0.8}) {
                if (std::abs(v - c) < 0.03) {
                    lum += 3000.0;
                }
            }
            lum *= 0.6 + 0.4 * std::sin(M_PI * u) * std::sin(M_PI * v);
            l.luminance.at(x, y) = lum;
        }
    }
    return l;
}

inline pipeline::surface::SurfaceScene testScene(int w, int h, bool bumpy, bool glossy)
{
    pipeline::surface::SurfaceScene s;
    s.name = "test";
    s.width = w;
    s.height = h;
    s.widthM = 0.2;
    s.heightM = 0.2 * h / w;
    s.paletteNames = {"light", "dark"};
    s.palette = {pipeline::colour::Spectrum::constant(0.6),
                 pipeline::colour::Spectrum::constant(0.1)};
    for (std::size_t b = 0; b < pipeline::colour::kBands; ++b) {
        s.palette[1][b] = 0.05 + 0.5 * static_cast<double>(b) / pipeline::colour::kBands; // reddish
    }
    const std::size_t n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
    s.relief.width = w;
    s.relief.height = h;
    s.relief.pitchM = s.widthM / w;
    s.relief.m.assign(n, 0.0);
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            const std::size_t k = static_cast<std::size_t>(y) * w + x;
            s.pigmentA.push_back(0);
            s.pigmentB.push_back(1);
            s.mix.push_back(x < w / 2 ? 0.0f : 1.0f);
            s.shade.push_back(1.0f);
            if (bumpy) {
                s.relief.m[k] = 0.002 * std::sin(x * 0.7) * std::cos(y * 0.5);
            }
        }
    }
    s.alpha = 0.1;
    if (glossy) {
        s.rhoS = pipeline::colour::Spectrum::constant(0.04);
    }
    return s;
}

inline const pipeline::colour::Observer& observer()
{
    static const pipeline::colour::Observer obs = *pipeline::colour::loadCie1931(dataDir());
    return obs;
}

} // namespace replica::test
