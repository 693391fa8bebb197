// A surface scene on disk: scene.json (size, palette of reflectance spectra, Ward gloss) beside
// material.exr (per-texel pigment mix), height.exr (metres) and channels.exr (renderer channels).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <pipeline/base/expected.h>
#include <pipeline/brdf/ward.h>
#include <pipeline/colour/channel_basis.h>
#include <pipeline/colour/spectrum.h>
#include <pipeline/surface/relief.h>

namespace replica::pipeline::surface {

// Per texel: reflectance = shade * ((1 - mix) * palette[a] + mix * palette[b]). Exact spectra for
// the reference, and (by linearity) exact channel coefficients for the renderer.
struct SurfaceScene {
    std::string name;
    double widthM = 0.0; // physical size of the surface on the panel
    double heightM = 0.0;
    int width = 0; // texels
    int height = 0;
    std::vector<std::string> paletteNames;
    std::vector<colour::Spectrum> palette;
    std::vector<int> pigmentA, pigmentB;
    std::vector<float> mix, shade;
    HeightField relief;
    double alpha = 0.1;    // Ward roughness
    colour::Spectrum rhoS; // spectral specular reflectance (all zero: matte)
    brdf::WardModel model = brdf::WardModel::WardDurGuarded;

    colour::Spectrum reflectance(int x, int y) const;
    colour::ChannelCoeffs
    channels(const std::vector<colour::ChannelCoeffs>& paletteCoeffs, int x, int y) const;
    bool glossy() const { return rhoS.max() > 0.0; }
    bool flat() const { return relief.flat(); }
};

Expected<SurfaceScene> loadScene(const std::filesystem::path& dir);
// Writes every file; channels.exr holds the box6 coefficients (c0..c5) for GL upload.
Expected<void> saveScene(const std::filesystem::path& dir, const SurfaceScene& scene);

} // namespace replica::pipeline::surface
