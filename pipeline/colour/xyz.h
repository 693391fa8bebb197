// CIE 1931 2-degree tristimulus values from working-grid spectra.
#pragma once

#include <filesystem>

#include <glm/vec3.hpp>

#include <pipeline/base/expected.h>
#include <pipeline/colour/spectrum.h>

namespace replica::pipeline::colour {

using Xyz = glm::dvec3; // X, Y, Z

// The CIE 1931 2-degree colour-matching functions on the working grid.
struct Observer {
    Spectrum xbar, ybar, zbar;
};

// Loads data/spectra/cie1931_2deg_cmf_10nm_380_730.csv (point-sampled from the 1 nm CIE table).
Expected<Observer> loadCie1931(const std::filesystem::path& dataDir);

// Sum of s * cmf over the bands (times the 10 nm band width): absolute when s is absolute.
Xyz spectrumToXyz(const Observer& obs, const Spectrum& s);

// Tristimulus values of a reflectance under a light, scaled so that the perfect white has Y = 100.
Xyz reflectanceToXyz(const Observer& obs, const Spectrum& light, const Spectrum& reflectance);

} // namespace replica::pipeline::colour
