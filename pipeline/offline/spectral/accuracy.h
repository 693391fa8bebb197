// Colour accuracy of a representation against the full-spectral calculation, with the normalisation
// of docs/accuracy.md (our reading of the paper's section "Color accuracy"):
//   1. each workflow's XYZ is scaled so that its own white sample has Y = 1/1.13;
//   2. the source white is the light's own XYZ (full spectral, 36 bands) scaled to Y = 1;
//   3. both are adapted with CAT02 (D = 1) to D65 (summed on the same grid, Y = 1);
//   4. CIELAB against that D65 white, CIEDE2000 between reference and approximation.
#pragma once

#include <string>
#include <vector>

#include <pipeline/base/expected.h>
#include <pipeline/colour/cat02.h>
#include <pipeline/colour/cielab.h>
#include <pipeline/spectral/reference_sets.h>
#include <pipeline/spectral/representation.h>

namespace replica::pipeline::spectral {

struct ErrorStats {
    double mean = 0.0;
    double std = 0.0; // population standard deviation (divides by n)
    double p90 = 0.0; // 90th percentile, linear between order statistics (rank 0.9 (n - 1))
    double max = 0.0;
};

// Statistics of a non-empty list of values.
ErrorStats errorStats(std::vector<double> values);

struct SampleAccuracy {
    std::string name;
    colour::Lab labReference;
    colour::Lab labApprox;
    double de00 = 0.0;
};

struct AccuracyReport {
    std::string representation;
    std::vector<SampleAccuracy> samples;
    ErrorStats stats;
    std::size_t whiteIndex = 0; // the sample used as white (named "white", else the highest Y)
    // How the light's colours were adapted to D65 (colour::adaptationBetween): CAT02; for a light
    // whose white CAT02 cannot adapt (a narrow-band light), von Kries scaling in XYZ; for a light
    // with no Z at all (650-730 nm alone), not at all.
    colour::Adaptation adaptation = colour::Adaptation::Cat02;
};

// Index of the white sample: the one named exactly "white", else the one with the highest Y under
// 'light' (full spectral).
std::size_t
whiteSampleIndex(const Observer& obs, const Spectrum& light, const NamedSpectra& samples);

// Lab (against D65) of each reference XYZ after the normalisation above. 'whiteIndex' picks the
// white sample; 'lightXyz' is the source white (any scale).
Expected<std::vector<colour::Lab>> normalisedLab(const std::vector<Xyz>& xyz,
                                                 std::size_t whiteIndex,
                                                 const Xyz& lightXyz,
                                                 const Xyz& d65Xyz);

// Evaluates 'approx' against the full-spectral reference under 'light' for every sample. An
// adaptive representation is evaluated as encoded for 'light' (its adaptedTo(light)); to see it
// encoded for another light, pass that light's adaptedTo() result instead. Fails for a light
// without luminance, an empty set, or a white sample with Y <= 0.
Expected<AccuracyReport> evaluateRepresentation(const Observer& obs,
                                                const Spectrum& d65,
                                                const Representation& approx,
                                                const Spectrum& light,
                                                const NamedSpectra& samples);

} // namespace replica::pipeline::spectral
