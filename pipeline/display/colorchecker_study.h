// The paper's Table 1 (right half) as a computation: the ColorChecker under a booth light, through
// spectral -> six channels -> XYZ -> inverse display -> quantised counts -> the panel, compared
// with the full-spectral XYZ in the paper's relative, CAT02-to-D65, CIEDE2000 terms.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <pipeline/colour/channel_basis.h>
#include <pipeline/display/display_inverse.h>

namespace replica::pipeline::display {

struct StudyLight {
    std::string name; // for the table
    std::string file; // under data/spectra
    std::string column;
};

// A (tungsten), the D50 fluorescent simulator (CIE F8) and the D65 simulator (CIE F7).
std::vector<StudyLight> boothLights();

// Whether the panel sits in the lit booth and what the pipeline does about its reflection.
enum class FlareHandling {
    Dark,            // no booth light on the screen (measured in the dark)
    InBoothSubtract, // the meter sees panel + rho_d E / pi; the estimate is subtracted (the paper)
    InBoothIgnore,   // the meter sees panel + reflection; nothing subtracted
};

struct StudyOptions {
    // The renderer's six-channel representation (the appliance's default is
    // colour::loadDefaultChannelBasis; the box basis needs no file).
    colour::ChannelBasis basis = colour::boxBasis();
    double illuminanceLux = 2000.0; // on the screen plane
    FlareHandling flare = FlareHandling::InBoothSubtract;
};

struct ErrorStats {
    int count = 0;
    double mean = 0.0;
    double std = 0.0; // population standard deviation
    double p90 = 0.0;
    double max = 0.0;
};
ErrorStats errorStats(const std::vector<double>& de);

struct PatchResult {
    std::string name;
    GamutClass gamutClass = GamutClass::InGamut; // of the six-channel XYZ target
    double sixChannelDe00 = 0.0;                 // channels vs full spectral
    double mappedDe00 = 0.0;                     // screen output, hue-keeping mapping
    double clippedDe00 = 0.0;                    // screen output, per-channel clipping
    // The same two without the paper's white-patch normalisation: every XYZ relative to the
    // perfect diffuser under the light, so a white patch that had to be dimmed counts as dimmed
    // instead of brightening every other patch.
    double mappedAbsoluteDe00 = 0.0;
    double clippedAbsoluteDe00 = 0.0;
    glm::dvec3 targetXyz{0.0}; // absolute, cd/m^2
};

struct LightResult {
    std::string light;
    std::vector<PatchResult> patches;
    ErrorStats sixChannel;
    ErrorStats mapped;
    ErrorStats clipped;
    ErrorStats mappedInGamut; // in-gamut patches only
    ErrorStats mappedAbsolute;
    ErrorStats clippedAbsolute;
    std::vector<std::string> outOfGamut;
};

// 'panel' is what a meter reads for integer counts (the ground truth of a synthetic panel, or the
// profile's own forward model). Each patch is quantised over one 16 x 16 dither tile and the
// reading is the tile's mean, as a spot meter would see it.
Expected<std::vector<LightResult>>
colorCheckerStudy(const DisplayInverse& inverse,
                  const std::function<glm::dvec3(const glm::dvec3&)>& panel,
                  const std::filesystem::path& dataDir,
                  const StudyOptions& options);

} // namespace replica::pipeline::display
