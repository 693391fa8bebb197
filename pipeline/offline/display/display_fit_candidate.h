// The display fit's model candidates (pipeline/offline/display/display_fit.h): what the
// measurements give before any candidate (black, the single-channel ramps, the off-ramp colours
// split into training and held-out halves), one candidate per primaries matrix with its tone curves
// re-derived from the ramps, and the choice between the direct primaries and the matrix refined
// against the training colours.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include <pipeline/offline/display/display_fit.h>
#include <pipeline/offline/display/tone_fit.h>

namespace replica::pipeline::display {

constexpr std::array<char, 3> kChannelNames{'R', 'G', 'B'};

struct RampPoint {
    double count = 0.0;
    glm::dvec3 xyz{0.0};
    int line = 0;
    int repeats = 1; // readings averaged into xyz
};

// What the measurements give, before any candidate matrix.
struct FitData {
    std::string source;
    double maxCount = 255.0;
    glm::dvec3 black{0.0};
    std::array<std::vector<RampPoint>, 3> ramps; // sorted by count, full drive last
    glm::dmat3 primaries{1.0};                   // each ramp's full-drive reading above black
    std::vector<Measurement> colours;            // off the ramps, in file order
    std::vector<Measurement> training;           // alternate colours: the even ones
    std::vector<Measurement> heldOut;            // and the odd ones
    std::optional<glm::dvec3> white;             // the (mean) full-drive white reading
    glm::dvec3 refWhite{0.0};                    // the white dE00 is judged against
};

double mean(const std::vector<double>& v);
double percentile(std::vector<double> v, double p);

// The model for one candidate matrix: tone curves re-derived from the ramps.
struct Candidate {
    glm::dmat3 matrix{1.0};
    bool robust = false;
    std::array<ToneCurve, 3> tone; // interpolating fit
    std::array<ToneFit, 3> fits;   // robust fit
    std::array<std::vector<ToneSample>, 3> samples;
    int corrections = 0;

    double value(std::size_t c, double count) const
    {
        return robust ? fits[c](count) : tone[c](count);
    }
};

// The interpolating candidate: each ramp projected through M^-1 and made monotone.
Candidate deriveCandidate(const glm::dmat3& m,
                          const glm::dvec3& black,
                          const std::array<std::vector<RampPoint>, 3>& ramps);

// The robust candidate: each ramp projected onto its channel and fitted through its noise.
// 'options' per channel (cross-validated the first time, then the shapes kept fixed).
Candidate deriveRobust(const glm::dmat3& m,
                       const glm::dvec3& black,
                       const std::array<std::vector<RampPoint>, 3>& ramps,
                       double maxCount,
                       double noiseFloor,
                       const std::array<ToneFitOptions, 3>& options);

glm::dvec3
candidateForward(const Candidate& cand, const glm::dvec3& black, const glm::dvec3& counts);

// dE00 of each of 'colours' against the candidate's prediction.
std::vector<double> candidateErrors(const Candidate& cand,
                                    const FitData& data,
                                    const std::vector<Measurement>& colours);

// The direct primaries' candidate and the one the fit keeps (the refined matrix where that
// predicts the training colours better, and, for the robust fit, where it passes the
// cross-validated test).
struct MatrixChoice {
    Candidate direct;
    Candidate best;
    double directHeldOutMeanDe00 = 0.0;
    int optimiserEvaluations = 0;
};

MatrixChoice chooseMatrix(const FitData& data, const FitOptions& options);

} // namespace replica::pipeline::display
