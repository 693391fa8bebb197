// Representation (2), the paper's six optimised channels (Darling & Ferwerda; after Drew &
// Finlayson 2003 and Darling et al. 2011): light and reflectance are each projected onto six
// channels, multiplied channel by channel, and a fixed [6 x 3] matrix takes the product to XYZ.
#pragma once

#include <array>
#include <filesystem>
#include <memory>
#include <string>

#include <pipeline/base/expected.h>
#include <pipeline/colour/channel_basis.h>
#include <pipeline/spectral/reference_sets.h>
#include <pipeline/spectral/representation.h>

namespace replica::pipeline::spectral {

struct SixChannelModel {
    std::string name;
    std::array<Spectrum, colour::kChannels> lightProject{}; // s_k = lightProject[k] . light(Y = 1)
    std::array<Spectrum, colour::kChannels> reflectProject{}; // c_k = reflectProject[k] . r
    std::array<Xyz, colour::kChannels> toXyz{};               // XYZ = sum_k s_k c_k toXyz[k]
};

// The per-light vectors in the renderer's form: M_k = s_k toXyz[k].
colour::ChannelToXyz
sixChannelToXyz(const SixChannelModel& model, const Observer& obs, const Spectrum& light);

std::unique_ptr<Representation> makeSixChannelRepresentation(const Observer& obs,
                                                             SixChannelModel model);

struct SixChannelFitReport {
    std::vector<double> objective; // weighted squared error after each round, for the docs
};

// Alternating least squares over the training lights and reflectances, minimising the same
// CIELAB-weighted error as fitChannelBasis (fit_metric.h). Each of the three steps (toXyz with the
// projections fixed; reflectProject with the rest fixed; lightProject likewise) is a linear least-
// squares problem whose normal equations reduce to 36 x 36 moments of the training set, so a round
// costs milliseconds. Starts from 'initial' projections (both set to its rows).
Expected<SixChannelModel> fitSixChannelModel(const Observer& obs,
                                             const Spectrum& d65,
                                             const NamedSpectra& reflectances,
                                             const NamedSpectra& lights,
                                             const colour::ChannelBasis& initial,
                                             int rounds,
                                             const std::string& name,
                                             SixChannelFitReport* report = nullptr);

// Files: '<stem>.csv' (wavelength_nm, light_1..6, reflectance_1..6 on the working grid) and
// '<stem>_to_xyz.csv' (header 'channel,X,Y,Z', six rows).
Expected<SixChannelModel> loadSixChannelModel(const std::filesystem::path& csvPath);
Expected<void> saveSixChannelModel(const SixChannelModel& model,
                                   const std::filesystem::path& csvPath,
                                   const std::string& provenance);

} // namespace replica::pipeline::spectral
