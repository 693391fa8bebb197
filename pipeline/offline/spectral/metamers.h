// Metameric pairs for the paper's Figure 7 target: two reflectances with the same XYZ under one
// light (tungsten) and clearly different colours under another (D65), built inside a channel basis'
// span so that the K = 6 rendering reproduces both the match and the mismatch exactly.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <pipeline/base/expected.h>
#include <pipeline/colour/channel_basis.h>
#include <pipeline/spectral/reference_sets.h>
#include <pipeline/spectral/representation.h>

namespace replica::pipeline::spectral {

struct MetamerPair {
    std::string name; // "pairNN", from the seed it grew out of
    std::string seed;
    Spectrum a;
    Spectrum b;
    double de00Match = 0.0;    // under the matching light
    double de00Mismatch = 0.0; // under the other light
};

// CIEDE2000 between two reflectances under one light, CIELAB against that light's perfect white.
double reflectancePairDifference(const Observer& obs,
                                 const Spectrum& light,
                                 const Spectrum& a,
                                 const Spectrum& b);

// For each seed: a = the seed projected into the basis span; b = a + W d with d in the null space
// of the matching light's 3 x 6 channel matrix (so XYZ under it is unchanged), d chosen over a
// dense set of directions to maximise the mismatch while every band of b stays in [0.02, 0.98].
// Returns up to 'count' pairs with mismatch >= minMismatch, greedily chosen for spread hues under
// the mismatch light. With targetMismatch > 0, b is then moved back towards a along the chosen
// direction until the mismatch is targetMismatch: the gentlest spectral change that shows it.
std::vector<MetamerPair> findMetamerPairs(const Observer& obs,
                                          const colour::ChannelBasis& basis,
                                          const Spectrum& matchLight,
                                          const Spectrum& mismatchLight,
                                          const NamedSpectra& seeds,
                                          std::size_t count,
                                          double minMismatch,
                                          double targetMismatch = 0.0);

// CSV on the working grid: wavelength_nm, pairNN_a, pairNN_b, ...; comment lines give each pair's
// differences.
Expected<void> saveMetamerPairs(const std::vector<MetamerPair>& pairs,
                                const std::filesystem::path& path,
                                const std::string& provenance);

} // namespace replica::pipeline::spectral
