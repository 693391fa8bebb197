// A known ground-truth display and a simulated spectroradiometer session on it: the source of the
// shipped synthetic IPS profile and of the fit-recovery tests. Not a real panel's data.
#pragma once

#include <array>
#include <cstdint>
#include <random>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include <pipeline/display/viewing_angle.h>
#include <pipeline/offline/display/measurement_set.h>

namespace replica::pipeline::display {

// How a synthetic channel's tone response is shaped.
enum class SyntheticTone {
    Power, // (x + s x (1 - x)(x - 0.5))^gamma: a power law, S-shaped for s > 0
    Gog,   // (gain x + 1 - gain)^gamma, zero below: Berns's gain-offset-gamma
    Srgb,  // linear toe to 0.04045 then ((x + 0.055) / 1.055)^gamma: the sRGB shape
};

struct SyntheticDisplay {
    int bitDepth = 8;
    SyntheticTone tone = SyntheticTone::Power;
    std::array<double, 3> gogGain{1.0, 1.0, 1.0}; // SyntheticTone::Gog
    std::array<glm::dvec2, 3> primaryXy{};        // chromaticities of R, G, B
    glm::dvec2 whiteXy{0.3127, 0.3290};           // at full drive
    double whiteCdM2 = 900.0;                     // above black
    glm::dvec3 blackXyz{0.0};
    std::array<double, 3> gamma{2.2, 2.2, 2.2};
    std::array<double, 3> sShape{0.0, 0.0, 0.0}; // x + s x (1 - x)(x - 0.5) before the power
    double interaction = 0.0; // white loses this share of luminance to channel crosstalk

    glm::dmat3 matrix() const; // columns: full-drive primaries above black
    double toneResponse(int channel, double counts) const;
    glm::dvec3 forward(const glm::dvec3& counts) const;
};

// The panel the shipped profile describes: sRGB-like primaries (a typical wide-luminance IPS),
// D65 white at 900 cd/m^2 (the paper's EIZO RX220 in its customisable mode), a bluish 0.6 cd/m^2
// black, slightly different S-shaped tone curves per channel and 0.5 % channel interaction.
SyntheticDisplay wideIpsGroundTruth();

// A viewing-angle table for the synthetic panel through the paper's two measured points (90 % of
// on-axis luminance at 15 deg, 75 % at 25 deg), with a small blue shift of white off axis.
ViewingAngleTable wideIpsViewingAngles();

struct MeterNoise {
    double relative = 0.002; // sigma as a share of each tristimulus value (PR-655 class)
    double absoluteCdM2 = 0.005;
};

// Ramps of R, G, B and grey (every 8 counts plus 4 and full drive), black five times, a 5x5x5
// grid and 60 pseudo-random colours, each read once through the meter noise (deterministic in
// seed).
std::vector<Measurement>
syntheticMeasurements(const SyntheticDisplay& display, const MeterNoise& noise, std::uint64_t seed);

// A measurement session of another plan: black 'blackRepeats' times, R, G and B ramps every
// 'rampStep' counts and full drive (read 'fullDriveRepeats' times), white 'whiteRepeats' times, a
// grey ramp when asked, and 'randomColours' pseudo-random colours, each read once through the
// meter noise. The defaults have the ramps of `replica display patches --make-set` (348 patches at
// 8 bits): a reading's error in counts grows with the count (relative noise over a slope that
// grows more slowly), so the ramps are dense and the full drive, which sets each primary's scale
// and with it every count near the top, is read ten times.
struct SessionPlan {
    int rampStep = 3;
    int fullDriveRepeats = 10;
    int blackRepeats = 5;
    int whiteRepeats = 1;
    bool greyRamp = false;
    int randomColours = 60;
};
std::vector<Measurement> syntheticSession(const SyntheticDisplay& display,
                                          const MeterNoise& noise,
                                          const SessionPlan& plan,
                                          std::uint64_t seed);

// Standard normal from two uniform 64-bit draws (Box-Muller): mt19937_64's output is fixed by the
// standard, std::normal_distribution's is not, so simulated meter noise (the shipped data, the
// fit's bootstrap) regenerates identically everywhere.
double standardNormal(std::mt19937_64& rng);

} // namespace replica::pipeline::display
