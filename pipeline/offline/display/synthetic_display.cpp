// Synthetic ground-truth display and measurement session.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include <glm/matrix.hpp>

#include <pipeline/offline/display/synthetic_display.h>

namespace replica::pipeline::display {
namespace {

glm::dvec3 xyFull(const glm::dvec2& xy)
{
    return {xy.x / xy.y, 1.0, (1.0 - xy.x - xy.y) / xy.y};
}

// The R, G, B (and, for channels 4, grey) ramps at 'levels', in that order.
void appendRamps(std::vector<glm::dvec3>& patches, const std::vector<double>& levels, int channels)
{
    for (int c = 0; c < channels; ++c) {
        for (double v : levels) {
            glm::dvec3 p(0.0);
            if (c == 3) {
                p = glm::dvec3(v);
            } else {
                p[c] = v;
            }
            patches.push_back(p);
        }
    }
}

// 'n' colours with every channel uniform over the counts 0..maxCount.
void appendRandomColours(std::vector<glm::dvec3>& patches,
                         int n,
                         double maxCount,
                         std::mt19937_64& rng)
{
    for (int i = 0; i < n; ++i) {
        glm::dvec3 p;
        for (int c = 0; c < 3; ++c) {
            p[c] = std::floor(static_cast<double>(rng() >> 11) * 0x1.0p-53 * (maxCount + 1.0));
        }
        patches.push_back(p);
    }
}

// Each patch read once: the panel's XYZ plus the meter's noise per component (sigma = relative
// times the reading plus the absolute floor), drawn from 'rng' in patch order.
std::vector<Measurement> readThroughMeter(const SyntheticDisplay& display,
                                          const MeterNoise& noise,
                                          const std::vector<glm::dvec3>& patches,
                                          std::mt19937_64& rng)
{
    std::vector<Measurement> out;
    out.reserve(patches.size());
    for (const auto& p : patches) {
        Measurement m;
        m.counts = p;
        const glm::dvec3 truth = display.forward(p);
        for (int c = 0; c < 3; ++c) {
            const double sigma = noise.relative * std::abs(truth[c]) + noise.absoluteCdM2;
            m.xyz[c] = truth[c] + sigma * standardNormal(rng);
        }
        out.push_back(m);
    }
    return out;
}

} // namespace

double standardNormal(std::mt19937_64& rng)
{
    const double u1 = (static_cast<double>(rng() >> 11) + 0.5) * 0x1.0p-53;
    const double u2 = static_cast<double>(rng() >> 11) * 0x1.0p-53;
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

glm::dmat3 SyntheticDisplay::matrix() const
{
    // Scale each primary so that their sum is the white point at whiteCdM2.
    const glm::dmat3 p(xyFull(primaryXy[0]), xyFull(primaryXy[1]), xyFull(primaryXy[2]));
    const glm::dvec3 w = xyFull(whiteXy) * whiteCdM2;
    const glm::dvec3 s = glm::inverse(p) * w;
    return glm::dmat3(p[0] * s.x, p[1] * s.y, p[2] * s.z);
}

double SyntheticDisplay::toneResponse(int channel, double counts) const
{
    const auto c = static_cast<std::size_t>(channel);
    const double maxCount = std::ldexp(1.0, bitDepth) - 1.0;
    const double x = std::clamp(counts / maxCount, 0.0, 1.0);
    if (tone == SyntheticTone::Gog) {
        const double u = gogGain[c] * x + (1.0 - gogGain[c]);
        return u > 0.0 ? std::pow(u, gamma[c]) : 0.0;
    }
    if (tone == SyntheticTone::Srgb) {
        // Continuous at the break: the toe's slope matches the power segment's value there.
        const double knee = std::pow((0.04045 + 0.055) / 1.055, gamma[c]);
        return x <= 0.04045 ? x * knee / 0.04045 : std::pow((x + 0.055) / 1.055, gamma[c]);
    }
    const double shaped = x + sShape[c] * x * (1.0 - x) * (x - 0.5);
    return std::pow(std::max(shaped, 0.0), gamma[c]);
}

glm::dvec3 SyntheticDisplay::forward(const glm::dvec3& counts) const
{
    const glm::dvec3 r{toneResponse(0, counts.x), toneResponse(1, counts.y),
                       toneResponse(2, counts.z)};
    const glm::dmat3 m = matrix();
    // Crosstalk: the product terms take light away in the white's colour, most at full white.
    const double cross = (r.x * r.y + r.y * r.z + r.x * r.z) / 3.0;
    return blackXyz + m * r - interaction * cross * (m * glm::dvec3(1.0));
}

SyntheticDisplay wideIpsGroundTruth()
{
    SyntheticDisplay d;
    d.bitDepth = 8;
    d.primaryXy = {glm::dvec2{0.6450, 0.3320}, glm::dvec2{0.3050, 0.6150},
                   glm::dvec2{0.1500, 0.0580}};
    d.whiteXy = {0.3127, 0.3290};
    d.whiteCdM2 = 900.0;
    d.blackXyz = glm::dvec3{0.55, 0.60, 0.82};
    d.gamma = {2.25, 2.20, 2.10};
    d.sShape = {0.35, 0.30, 0.45};
    d.interaction = 0.005;
    return d;
}

ViewingAngleTable wideIpsViewingAngles()
{
    ViewingAngleTable t;
    t.angleDeg = {0, 5, 10, 15, 20, 25, 30, 40, 50, 60, 70, 80};
    t.luminanceRatio = {1.0,   0.988, 0.953, 0.900, 0.830, 0.750,
                        0.670, 0.525, 0.405, 0.305, 0.220, 0.150};
    for (double a : t.angleDeg) {
        const double q = (a / 30.0) * (a / 30.0);
        t.dx.push_back(-0.0030 * q);
        t.dy.push_back(-0.0045 * q);
    }
    return t;
}

std::vector<Measurement>
syntheticMeasurements(const SyntheticDisplay& display, const MeterNoise& noise, std::uint64_t seed)
{
    std::mt19937_64 rng(seed);
    const double maxCount = std::ldexp(1.0, display.bitDepth) - 1.0;
    std::vector<glm::dvec3> patches(5, glm::dvec3(0.0));
    std::vector<double> levels{4.0};
    for (double v = 8.0; v < maxCount; v += 8.0) {
        levels.push_back(v);
    }
    levels.push_back(maxCount);
    appendRamps(patches, levels, 4);
    // The fit alternates off-ramp colours between training and held-out, so both halves sample
    // the grid and the random colours.
    for (int r = 0; r < 5; ++r) {
        for (int g = 0; g < 5; ++g) {
            for (int b = 0; b < 5; ++b) {
                patches.push_back(glm::round(glm::dvec3(r, g, b) * (maxCount / 4.0)));
            }
        }
    }
    appendRandomColours(patches, 60, maxCount, rng);
    return readThroughMeter(display, noise, patches, rng);
}

std::vector<Measurement> syntheticSession(const SyntheticDisplay& display,
                                          const MeterNoise& noise,
                                          const SessionPlan& plan,
                                          std::uint64_t seed)
{
    std::mt19937_64 rng(seed);
    const double maxCount = std::ldexp(1.0, display.bitDepth) - 1.0;
    std::vector<glm::dvec3> patches(static_cast<std::size_t>(std::max(plan.blackRepeats, 0)),
                                    glm::dvec3(0.0));
    std::vector<double> levels;
    for (double v = plan.rampStep; v < maxCount; v += plan.rampStep) {
        levels.push_back(v);
    }
    for (int i = 0; i < std::max(plan.fullDriveRepeats, 1); ++i) {
        levels.push_back(maxCount);
    }
    appendRamps(patches, levels, plan.greyRamp ? 4 : 3);
    for (int i = plan.greyRamp ? 1 : 0; i < plan.whiteRepeats; ++i) {
        patches.emplace_back(maxCount);
    }
    appendRandomColours(patches, plan.randomColours, maxCount, rng);
    return readThroughMeter(display, noise, patches, rng);
}

} // namespace replica::pipeline::display
