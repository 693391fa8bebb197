// The robust display fit's report of its own uncertainty.
#include <algorithm>
#include <cmath>
#include <random>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include <pipeline/display/xyz_difference.h>
#include <pipeline/offline/display/display_fit_uncertainty.h>
#include <pipeline/offline/display/synthetic_display.h>

namespace replica::pipeline::display {
namespace {

// The meter's noise per XYZ component (relative) from the ramps: each reading against the fit, and
// against the fit with its fold left out; the product of the two is unbiased for the noise
// variance where the plain residual is too small and the left-out one too large.
double meterNoise(const FitData& data, const Candidate& direct)
{
    double acc = 0.0;
    int n = 0;
    for (std::size_t c = 0; c < 3; ++c) {
        const auto& ramp = data.ramps[c];
        const glm::dvec3 full = ramp.back().xyz - data.black;
        for (std::size_t i = 0; i < ramp.size(); ++i) {
            const auto& p = ramp[i];
            const glm::dvec3 above = p.xyz - data.black;
            if (!(above.x + above.y + above.z > 0.1 * (full.x + full.y + full.z))) {
                continue;
            }
            glm::dvec3 counts(0.0);
            counts[static_cast<int>(c)] = p.count;
            const glm::dvec3 e = p.xyz - candidateForward(direct, data.black, counts);
            const glm::dvec3 ecv =
                    e + direct.matrix[static_cast<int>(c)] *
                                (direct.fits[c].cvResidual[i + 1] - direct.fits[c].residual[i + 1]);
            const double top = std::max({p.xyz.x, p.xyz.y, p.xyz.z});
            for (int k = 0; k < 3; ++k) {
                if (p.xyz[k] > 0.1 * top) {
                    // A mean of n readings has 1/n of a reading's variance.
                    acc += p.repeats * e[k] * ecv[k] / (p.xyz[k] * p.xyz[k]);
                    ++n;
                }
            }
        }
    }
    return n > 0 ? std::sqrt(std::max(0.0, acc / n)) : 0.0;
}

// The inverse's expected error in counts: a parametric bootstrap of each channel's fit under the
// noise its own residuals show. Sets the report's tone and inverse figures; returns each channel's
// spread of its full-drive value.
std::array<double, 3>
inverseSpread(const Candidate& best, double rho, double maxCount, int replicates, FitReport& report)
{
    std::array<double, 3> topSpread{};
    for (std::size_t c = 0; c < 3; ++c) {
        const auto& smp = best.samples[c];
        const auto& tf = best.fits[c];
        // The weights are 1 / variance in units of the relative noise per XYZ component
        // (deriveRobust), so a sample's sigma is rho / sqrt(weight). (Each curve's own
        // residuals, rather than rho from all three ramps, read near 0 where the
        // cross-validated smoothing is light.)
        std::vector<double> sigma;
        for (const auto& sm : smp) {
            sigma.push_back(rho / std::sqrt(std::max(sm.weight, 1e-300)));
        }
        const auto spread = toneCountSpread(smp, tf, sigma, replicates, 0x5eed + c, &topSpread[c]);
        // Over the counts whose light above black is at least 0.1 % of full drive: below
        // that the curve is flat (a GOG toe) and no count is better than another.
        const double r0 = tf(0.0);
        const double rSpan = tf(maxCount) - r0;
        double sum2 = 0.0;
        double worst = 0.0;
        int used = 0;
        for (std::size_t g = 0; g < spread.size(); ++g) {
            const double count =
                    maxCount * static_cast<double>(g + 1) / static_cast<double>(spread.size());
            if (tf(count) - r0 >= 1e-3 * rSpan) {
                sum2 += spread[g] * spread[g];
                worst = std::max(worst, spread[g]);
                ++used;
            }
        }
        report.toneShape[c] = toneShapeName(tf.shape);
        report.toneSmoothing[c] = tf.lambda;
        report.inverseCountsRms[c] = used > 0 ? std::sqrt(sum2 / used) : 0.0;
        report.inverseCountsMax[c] = worst;
    }
    return topSpread;
}

struct GamutEdge {
    double sigma = 0.0;                      // of r, the largest over the corners and channels
    std::array<glm::dvec3, 3> columnSigma{}; // per XYZ component of each fitted column
};

// The fit's uncertainty of r at the gamut's corners (each primary and white at full drive): each
// channel's full-drive value (the bootstrap's spread, relative) and each primary's direction
// (rampPrimary's sum of readings, each with relative noise rho per XYZ component), carried through
// M^-1 into every channel.
GamutEdge gamutEdge(const FitData& data,
                    const Candidate& best,
                    double rho,
                    const std::array<double, 3>& topSpread)
{
    const glm::dmat3 mInv = glm::inverse(best.matrix);
    GamutEdge edge;
    for (std::size_t c = 0; c < 3; ++c) {
        const double topValue = best.fits[c](data.maxCount);
        const double topRel = topValue > 0.0 ? topSpread[c] / topValue : 0.0;
        const glm::dvec3 full = data.ramps[c].back().xyz - data.black;
        const double fullSum = full.x + full.y + full.z;
        glm::dvec3 sum(0.0);
        glm::dvec3 sumSq(0.0);
        for (const auto& p : data.ramps[c]) {
            const glm::dvec3 above = p.xyz - data.black;
            if (above.x + above.y + above.z > 0.2 * fullSum) {
                // A mean of n readings, weighted n in the sum: variance n rho^2 above^2.
                sum += static_cast<double>(p.repeats) * above;
                sumSq += static_cast<double>(p.repeats) * above * above;
            }
        }
        const double len = glm::length(sum);
        glm::dvec3 colSigma(0.0); // per XYZ component of the fitted column
        if (len > 0.0) {
            colSigma = glm::length(full) / len * rho * glm::sqrt(sumSq);
        }
        edge.columnSigma[c] = colSigma;
        for (int k = 0; k < 3; ++k) {
            double var = 0.0;
            for (int j = 0; j < 3; ++j) {
                // Column c's error in r_k, relative to column c's length in r_c (1).
                const double e = mInv[j][k] * colSigma[j] *
                                 (glm::length(best.matrix[static_cast<int>(c)]) /
                                  std::max(glm::length(full), 1e-300));
                var += e * e;
            }
            if (k == static_cast<int>(c)) {
                var += topRel * topRel;
            }
            edge.sigma = std::max(edge.sigma, std::sqrt(var));
        }
    }
    return edge;
}

// Black's uncertainty in r, which does not scale with the colour: the spread of the black
// readings over their count (or rho of black for a single reading), through M^-1.
double blackSigma(const std::vector<Measurement>& rows,
                  const glm::dvec3& black,
                  const glm::dmat3& matrix,
                  double rho)
{
    const glm::dmat3 mInv = glm::inverse(matrix);
    std::vector<glm::dvec3> blacks;
    for (const auto& m : rows) {
        if (m.counts == glm::dvec3(0.0)) {
            blacks.push_back(m.xyz);
        }
    }
    glm::dvec3 sigma = rho * glm::abs(black);
    if (blacks.size() >= 2) {
        glm::dvec3 var(0.0);
        for (const auto& b : blacks) {
            var += (b - black) * (b - black);
        }
        const double nb = static_cast<double>(blacks.size());
        sigma = glm::sqrt(var / (nb - 1.0) / nb);
    }
    double floorSigma = 0.0;
    for (int k = 0; k < 3; ++k) {
        double var = 0.0;
        for (int j = 0; j < 3; ++j) {
            var += mInv[j][k] * mInv[j][k] * sigma[j] * sigma[j];
        }
        floorSigma = std::max(floorSigma, std::sqrt(var));
    }
    return floorSigma;
}

// What the held-out readings' own noise gives against a perfect model.
double
heldOutNoiseDe(const DisplayModel& model, const FitData& data, double rho, std::mt19937_64& rng)
{
    double noiseDe = 0.0;
    int draws = 0;
    for (const auto& m : data.heldOut) {
        const glm::dvec3 xyz = model.forward(m.counts);
        for (int k = 0; k < 16; ++k) {
            glm::dvec3 noisy = xyz;
            for (int q = 0; q < 3; ++q) {
                noisy[q] *= 1.0 + rho * standardNormal(rng);
            }
            noiseDe += deltaE2000Xyz(noisy, xyz, data.refWhite);
            ++draws;
        }
    }
    return draws > 0 ? noiseDe / draws : 0.0;
}

// Additivity: the white readings against what the ramps predict for full drive (black once, plus
// each primary above black at its fitted full-drive value), judged against what the noise of both
// sides gives.
void additivity(const FitData& data,
                const Candidate& direct,
                const std::vector<Measurement>& rows,
                double rho,
                const std::array<double, 3>& topSpread,
                const GamutEdge& edge,
                std::mt19937_64& rng,
                FitReport& report)
{
    const double maxCount = data.maxCount;
    const glm::dvec3 white = *data.white;
    const glm::dvec3 predicted = candidateForward(direct, data.black, glm::dvec3(maxCount));
    const auto whiteReadings = std::count_if(rows.begin(), rows.end(), [&](const Measurement& m) {
        return m.counts == glm::dvec3(maxCount);
    });
    const double nWhite = static_cast<double>(std::max<long>(whiteReadings, 1));
    report.additivityDe00 = deltaE2000Xyz(white, predicted, data.refWhite);
    report.additivityLuminancePercent =
            predicted.y > 0.0 ? 100.0 * (white.y - predicted.y) / predicted.y : 0.0;
    // 2000 draws; the 99.9th percentile: a one-in-a-thousand false alarm, like the luminance's
    // three sigma (the 99th let one fit in 20 of an additive panel through).
    std::vector<double> noiseDes;
    double sumY2 = 0.0;
    constexpr int kDraws = 2000;
    for (int k = 0; k < kDraws; ++k) {
        glm::dvec3 meas = predicted;
        for (int q = 0; q < 3; ++q) {
            meas[q] *= 1.0 + rho / std::sqrt(nWhite) * standardNormal(rng);
        }
        glm::dvec3 pred = predicted;
        // Each channel's full-drive value and its primary's direction.
        for (int c = 0; c < 3; ++c) {
            const auto cs = static_cast<std::size_t>(c);
            pred += direct.matrix[c] * (topSpread[cs] * standardNormal(rng));
            for (int q = 0; q < 3; ++q) {
                pred[q] +=
                        edge.columnSigma[cs][q] * direct.fits[cs](maxCount) * standardNormal(rng);
            }
        }
        noiseDes.push_back(deltaE2000Xyz(meas, pred, data.refWhite));
        const double dy = 100.0 * (meas.y - pred.y) / predicted.y;
        sumY2 += dy * dy;
    }
    report.additivityNoiseDe00 = percentile(noiseDes, 0.999);
    report.additivityLuminanceSigmaPercent = std::sqrt(sumY2 / kDraws);
    report.additiveWithinNoise = report.additivityDe00 <= report.additivityNoiseDe00 &&
                                 std::abs(report.additivityLuminancePercent) <=
                                         3.0 * report.additivityLuminanceSigmaPercent;
}

} // namespace

void reportUncertainty(DisplayModel& model,
                       const FitData& data,
                       const MatrixChoice& choice,
                       const std::vector<Measurement>& rows,
                       int bootstrapReplicates,
                       FitReport& report)
{
    const double rho = meterNoise(data, choice.direct);
    report.noisePercent = 100.0 * rho;
    const auto topSpread =
            inverseSpread(choice.best, rho, data.maxCount, bootstrapReplicates, report);
    // Four sigma of the largest corner's uncertainty is the mapping's edge tolerance: a colour
    // the panel makes may lie that far outside the fitted gamut, and is then clamped per channel
    // instead of gamut-mapped. (Three let one fit in 24 put the panel's white outside: the
    // estimate leaves out the variance of the tone shape's choice.)
    const GamutEdge edge = gamutEdge(data, choice.best, rho, topSpread);
    report.gamutEdgeSigma = edge.sigma;
    model.gamutEdgeTolerance = std::min(4.0 * edge.sigma, 0.05);
    model.gamutEdgeFloor =
            std::min(4.0 * blackSigma(rows, data.black, choice.best.matrix, rho), 0.05);
    std::mt19937_64 rng(0xde00);
    report.heldOutNoiseMeanDe00 = heldOutNoiseDe(model, data, rho, rng);
    if (data.white) {
        additivity(data, choice.direct, rows, rho, topSpread, edge, rng, report);
    }
}

} // namespace replica::pipeline::display
