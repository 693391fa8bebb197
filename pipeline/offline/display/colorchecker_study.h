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
#include <pipeline/offline/spectral/sensed_light.h>
#include <pipeline/spectral/adaptive_encoding.h>
#include <pipeline/spectral/representation.h>

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
    // The paper's own construction beside the renderer's (spectral/six_channel_model.h 'paper6':
    // light and reflectance each projected onto six channels, multiplied, a fixed [6 x 3] to XYZ),
    // through the same display. Null: not computed.
    const spectral::Representation* paperSix = nullptr;
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
    glm::dvec3 targetXyz{0.0};       // absolute, cd/m^2
    double paperSixDe00 = 0.0;       // paper6 channels vs full spectral (options.paperSix)
    double paperSixMappedDe00 = 0.0; // screen output through paper6, hue-keeping mapping
    GamutClass paperSixGamutClass = GamutClass::InGamut;
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
    ErrorStats paperSix; // options.paperSix only
    ErrorStats paperSixMapped;
    ErrorStats paperSixMappedInGamut;
};

// 'panel' is what a meter reads for integer counts (the ground truth of a synthetic panel, or the
// profile's own forward model). Each patch is quantised over one 16 x 16 dither tile and the
// reading is the tile's mean, as a spot meter would see it.
Expected<std::vector<LightResult>>
colorCheckerStudy(const DisplayInverse& inverse,
                  const std::function<glm::dvec3(const glm::dvec3&)>& panel,
                  const std::filesystem::path& dataDir,
                  const StudyOptions& options);

// ---- End to end from the sensed light ---------------------------------------------------------
//
// The light goes through the simulated spectrometer (offline/spectral/sensed_light.h), then the
// renderer's mode, the render and the display (inverse, dithered counts, the panel); what the panel
// emits is compared with the real surface under the real light. Comparison: absolute (every XYZ
// relative to the perfect diffuser under the real light at the known illuminance, CAT02 from the
// real light's white to D65, CIELAB, CIEDE2000), as the paper's normalisation would hide a sensed
// light's error in the white patch.

enum class SensingMode {
    Direct,     // render under the sensed spectrum itself
    Classifier, // the nearest pre-measured lamp (the study's lights, each measured by the same
                // instrument averaging 50 spectra); an unknown answer falls back to direct
};

struct SensedStudyOptions {
    spectral::InstrumentImpairments impairments;
    double wavelengthErrorMaxNm = 0.5; // each draw is a new instrument: error uniform in +-this
    spectral::SensingCorrections corrections;
    SensingMode mode = SensingMode::Direct;
    int draws = 20; // instruments x noise realisations
    std::uint64_t seed = 1;
    double illuminanceLux = 2000.0;
    FlareHandling flare = FlareHandling::InBoothSubtract;
    // The lights the site calibrates the instrument's wavelength shift under (the booth's
    // fluorescent lamps); empty: the study's own lights.
    std::vector<spectral::FineLight> calibrationLights;
};

struct SensedLightStats {
    std::string light;
    ErrorStats render;       // rendered XYZ vs the real surface, all samples and draws
    ErrorStats panelInGamut; // what the panel emits vs the real surface, in-gamut samples
    ErrorStats panelOutOfGamut;
    int misclassified = 0;        // draws the classifier named another lamp (classifier mode)
    double lightShapeError = 0.0; // mean spectral shape distance, sensed vs real light
};

struct SensedSamples {
    std::vector<std::string> names;
    std::vector<colour::Spectrum> reflectances;
};

// The ColorChecker (24 patches) as SensedSamples.
Expected<SensedSamples> colorCheckerSamples(const std::filesystem::path& dataDir);

// The booth lights as fine lights (offline/spectral/sensed_light.h restoreLines).
Expected<std::vector<spectral::FineLight>> fineBoothLights(const std::filesystem::path& dataDir);

// 'encoder' renders as the appliance does (adaptive_k6, encoded for the light it renders under);
// null renders with 'basis' (a fixed representation).
Expected<std::vector<SensedLightStats>>
sensedStudy(const DisplayInverse& inverse,
            const std::function<glm::dvec3(const glm::dvec3&)>& panel,
            const colour::Observer& observer,
            const std::vector<spectral::FineLight>& lights,
            const SensedSamples& samples,
            const spectral::AdaptiveEncoder* encoder,
            const colour::ChannelBasis& basis,
            const SensedStudyOptions& options);

} // namespace replica::pipeline::display
