// The characterised display (Day, Taplin & Berns 2004): per-channel tone curves, a 3x3 primaries
// matrix and a black/flare offset, XYZ = M r(d) + XYZ_k, in absolute cd/m^2; with channel
// interaction (crosstalk) XYZ = XYZ_k + M (r + C p(r)), p = (r_R r_G, r_G r_B, r_B r_R): each pair
// of driven channels changes each channel's light in proportion to the two drives' product (zero
// on the single-channel ramps, largest at white). C = 0 is the additive model.
#pragma once

#include <array>
#include <string>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include <pipeline/display/tone_curve.h>
#include <pipeline/display/viewing_angle.h>

namespace replica::pipeline::display {

// Where the characterisation was measured: in the dark, or in the lit booth (then the black
// already holds the screen's own reflection of the booth light and it must not be subtracted
// again: the flare double-count trap).
enum class MeasurementCondition { Dark, LitBooth };

// Fit diagnostics kept with the profile, so a field check can compare against them.
struct FitReport {
    int trainingColours = 0;
    int heldOutColours = 0;
    double heldOutMeanDe00 = 0.0;
    double heldOutP90De00 = 0.0;
    double heldOutMaxDe00 = 0.0;
    double trainingMeanDe00 = 0.0;
    double directPrimariesHeldOutMeanDe00 = 0.0; // before optimising the matrix
    double additivityDe00 = -1.0;                // measured white vs R+G+B; -1 when not measured
    double additivityLuminancePercent = 0.0;     // (Y_white - Y_sum) / Y_sum * 100
    std::array<double, 3> chromaticityDrift{};   // max |dxy| of each primary along its ramp
    int monotonicCorrections = 0;                // ramp points moved by pool-adjacent-violators
    int optimiserEvaluations = 0;
    // The noise-robust fit (absent, -1 / empty, for the interpolating fit of format 1 profiles):
    double noisePercent =
            -1.0; // meter noise per XYZ component, % of the reading, from ramp residuals
    std::array<std::string, 3> toneShape{};   // per channel: gog, gogo or gogo+spline
    std::array<double, 3> toneSmoothing{};    // the spline's cross-validated penalty (relative)
    std::array<double, 3> inverseCountsRms{}; // expected inverse error (1 sigma) in counts, rms
                                              // over the counts where r >= 0.1 % of full
    std::array<double, 3> inverseCountsMax{}; // and its maximum (where r >= 0.1 % of full)
    double heldOutNoiseMeanDe00 = -1.0;       // mean dE00 the held-out readings' noise alone gives
    double additivityLuminanceSigmaPercent = -1.0; // 1 sigma of the luminance check from the noise
    double additivityNoiseDe00 = -1.0; // 99.9th percentile of the dE00 the noise alone gives
    bool additiveWithinNoise = false;
    double gamutEdgeSigma = -1.0; // 1 sigma of r at the gamut's corners (the fit's uncertainty)
    // The crosstalk family cross-validation chose ("none", "uniform" or "full"; empty before it)
    // and its held-out mean dE00 gain over the additive model.
    std::string crosstalkModel;
    double crosstalkGainDe00 = 0.0;
    double crosstalkZ = 0.0; // the uniform coefficient over its standard error
    // Non-zero ramp levels per channel, and whether the tone curves were limited to GOG because
    // a ramp had fewer than FitOptions::minRampLevels (not stored in the profile).
    std::array<int, 3> rampLevels{};
    bool gogOnlyForShortRamps = false;
};

struct DisplayModel {
    std::string name;
    std::string description;
    bool synthetic = false;
    int bitDepth = 8;
    // Columns: XYZ (cd/m^2) of each channel at full drive above black, so white = black + M
    // (1,1,1).
    glm::dmat3 matrix{1.0};
    glm::dvec3 blackXyz{0.0};
    // r_c(count), 0 at count 0 and 1 at full drive.
    std::array<ToneCurve, 3> tone;
    MeasurementCondition condition = MeasurementCondition::Dark;
    double frontSurfaceReflectance = 0.002; // rho_d of the panel's front surface (paper)
    ViewingAngleTable viewing;
    FitReport fit;
    // How far outside [0, 1] a channel's r may lie and still be shown per channel (clamped, counted
    // in gamut) rather than gamut-mapped: the fit's own uncertainty at the gamut's corners (4
    // sigma), so that a colour the panel makes, which the noisy fit puts a hair outside its gamut,
    // is not moved along the hue-keeping line (that costs a bright primary up to 13 times the
    // excursion). 0 (profiles without "gamut_edge_tolerance"): the mapping's rounding tolerance.
    double gamutEdgeTolerance = 0.0;
    // And its part that does not scale with the colour (black's uncertainty, in r): below 0 a
    // channel may reach -(gamutEdgeTolerance max r + gamutEdgeFloor).
    double gamutEdgeFloor = 0.0;
    // Crosstalk C (columns: the r-space change per unit of r_R r_G, r_G r_B, r_B r_R); zero, the
    // additive model, for profiles without "crosstalk". Each row's absolute sum is at most
    // kMaxCrosstalk (validate), so the inverse's fixed point contracts.
    glm::dmat3 crosstalk{0.0};
    static constexpr double kMaxCrosstalk = 0.2;

    double maxCount() const;
    // The additive white, black + M (1, 1, 1): the gamut mapping's peak (without crosstalk the
    // panel's white; with it the white the panel would show without the interaction).
    glm::dvec3 whiteXyz() const { return blackXyz + matrix * glm::dvec3(1.0); }
    bool hasCrosstalk() const { return crosstalk != glm::dmat3(0.0); }
    // r for real-valued counts.
    glm::dvec3 linearFromCounts(const glm::dvec3& counts) const;
    // The channel drives with the interaction, r + C p(r): XYZ = black + M interacted(r).
    glm::dvec3 interacted(const glm::dvec3& r) const;
    // Its inverse: the r with interacted(r) = y, by kCrosstalkSteps fixed-point steps
    // r <- y - C p(r) from r = y (the GLSL runs the same), each clamped to [0, 1] when 'clamp'
    // (a mapped colour), unclamped otherwise (the in-gamut test); y itself when C = 0.
    glm::dvec3 deinteracted(const glm::dvec3& y, bool clamp = true) const;
    static constexpr int kCrosstalkSteps = 12;
    // Absolute XYZ on the panel normal for real-valued counts.
    glm::dvec3 forward(const glm::dvec3& counts) const;
    // Checks the invariants a loaded or fitted model must hold; fails with the reason.
    Expected<void> validate() const;
};

// (r_R r_G, r_G r_B, r_B r_R): the products the crosstalk matrix multiplies.
glm::dvec3 crosstalkProducts(const glm::dvec3& r);

// The screen's own diffuse reflection of the booth light reaching the eye: rho_d E / pi in the
// light's colour (lightXyz scaled so that its Y is 1), zero when the profile was measured in the
// lit booth (its black already holds it).
glm::dvec3 frontSurfaceFlareXyz(const DisplayModel& model,
                                double illuminanceLux,
                                const glm::dvec3& lightXyzUnitY);

} // namespace replica::pipeline::display
