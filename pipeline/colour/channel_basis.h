// Multispectral rendering channels: a reflectance is stored as kChannels coefficients, and for the
// light in hand each channel maps to an XYZ vector, so a pixel's colour is sum_k c_k * M_k.
#pragma once

#include <array>
#include <cstddef>
#include <filesystem>
#include <string>

#include <pipeline/base/expected.h>
#include <pipeline/colour/spectrum.h>
#include <pipeline/colour/xyz.h>

namespace replica::pipeline::colour {

constexpr std::size_t kChannels = 6; // two RGB float images per surface, as in the paper

// A linear reflectance representation: c_k = sum_l project[k](l) r(l), and r ~ sum_k c_k recon[k].
struct ChannelBasis {
    std::string name;
    std::array<Spectrum, kChannels> project{};
    std::array<Spectrum, kChannels> reconstruct{};
};

using ChannelCoeffs = std::array<double, kChannels>;
using ChannelToXyz = std::array<Xyz, kChannels>;

// Six equal-width box bands over 380-730 nm (6 bands of 60 nm, the last one 50 nm): the simplest
// basis, used until an optimised one is selected.
ChannelBasis boxBasis();

ChannelCoeffs projectReflectance(const ChannelBasis& basis, const Spectrum& reflectance);

// M_k = sum_l recon[k](l) * light(l) * cmf(l) * 10 nm, with the light scaled so that its own Y
// is 1. Then XYZ (cd/m^2) of a Lambertian texel under illuminance E (lux) is E/pi * sum_k c_k M_k:
// exact whenever the reflectance lies in the span of the basis. Returns zeros for a light with Y <=
// 0.
ChannelToXyz channelToXyz(const ChannelBasis& basis, const Observer& obs, const Spectrum& light);

// A basis file: '#' comments, header 'wavelength_nm,project_1,...,project_6,reconstruct_1,...,
// reconstruct_6', then exactly the 36 rows of the working grid. The basis takes the file's stem as
// its name. Errors name the file, the line and the problem.
Expected<ChannelBasis> loadChannelBasis(const std::filesystem::path& path);
// Writes a basis in that format, with 'provenance' as the comment line.
Expected<void> saveChannelBasis(const ChannelBasis& basis,
                                const std::filesystem::path& path,
                                const std::string& provenance);

// The basis the appliance renders with: data/channels/replica_k6.csv, written by 'replica spectral
// fit' (see docs/accuracy.md for how it was derived and how accurate it is).
constexpr const char* kDefaultChannelBasisFile = "replica_k6.csv";
Expected<ChannelBasis> loadDefaultChannelBasis(const std::filesystem::path& dataDir);

} // namespace replica::pipeline::colour
