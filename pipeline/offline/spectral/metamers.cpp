// Metamer pairs in the null space of a light's channel matrix.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>

#include <pipeline/base/output_file.h>
#include <pipeline/colour/ciede2000.h>
#include <pipeline/colour/cielab.h>
#include <pipeline/offline/spectral/metamers.h>
#include <pipeline/spectral/dense_matrix.h>

namespace replica::pipeline::spectral {
namespace {

using colour::kBands;
using colour::kChannels;

constexpr double kLow = 0.02;
constexpr double kHigh = 0.98;

Spectrum reconstruct(const colour::ChannelBasis& basis, const std::array<double, kChannels>& c)
{
    Spectrum s;
    for (std::size_t k = 0; k < kChannels; ++k) {
        s = s + basis.reconstruct[k] * c[k];
    }
    return s;
}

bool inRange(const Spectrum& s)
{
    return std::all_of(s.v.begin(), s.v.end(), [](double v) { return v >= kLow && v <= kHigh; });
}

colour::Lab labUnder(const Observer& obs, const Spectrum& light, const Spectrum& r)
{
    const Xyz white = colour::reflectanceToXyz(obs, light, Spectrum::constant(1.0));
    return colour::xyzToLab(colour::reflectanceToXyz(obs, light, r), white);
}

} // namespace

double reflectancePairDifference(const Observer& obs,
                                 const Spectrum& light,
                                 const Spectrum& a,
                                 const Spectrum& b)
{
    return colour::ciede2000(labUnder(obs, light, a), labUnder(obs, light, b));
}

namespace {

// The channel-weight directions that leave the colour under the matching light unchanged: 600
// directions on the unit sphere of the null space of the 3 x 6 matrix M (XYZ of each
// reconstruction spectrum under that light).
std::vector<std::array<double, kChannels>> nullSpaceDirections(const Observer& obs,
                                                               const colour::ChannelBasis& basis,
                                                               const Spectrum& matchLight)
{
    // Null space of the 3 x 6 matrix M (XYZ of each reconstruction spectrum under the matching
    // light): the eigenvectors of M^T M with the three smallest eigenvalues (which are ~0).
    const auto m = colour::channelToXyz(basis, obs, matchLight);
    DenseMatrix mtm(kChannels, kChannels);
    for (std::size_t i = 0; i < kChannels; ++i) {
        for (std::size_t j = 0; j < kChannels; ++j) {
            mtm(i, j) = m[i].x * m[j].x + m[i].y * m[j].y + m[i].z * m[j].z;
        }
    }
    const SymmetricEigen eig = symmetricEigen(mtm);
    std::array<std::array<double, kChannels>, 3> nullBasis{};
    for (std::size_t n = 0; n < 3; ++n) {
        for (std::size_t k = 0; k < kChannels; ++k) {
            nullBasis[n][k] = eig.vectors(k, kChannels - 1 - n);
        }
    }
    // Directions on the unit sphere of the null space (Fibonacci lattice).
    constexpr int kDirections = 600;
    std::vector<std::array<double, kChannels>> directions;
    for (int i = 0; i < kDirections; ++i) {
        const double z = 1.0 - 2.0 * (i + 0.5) / kDirections;
        const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
        const double phi = i * std::numbers::pi * (3.0 - std::sqrt(5.0));
        const double u[3] = {r * std::cos(phi), r * std::sin(phi), z};
        std::array<double, kChannels> d{};
        for (std::size_t n = 0; n < 3; ++n) {
            for (std::size_t k = 0; k < kChannels; ++k) {
                d[k] += u[n] * nullBasis[n][k];
            }
        }
        directions.push_back(d);
    }
    return directions;
}

// Greedily the largest mismatches whose hue (of a, under the mismatch light) is at least 30
// degrees from every pair taken so far, at most 'count', named pair01, pair02, ...
std::vector<MetamerPair> spreadHues(std::vector<MetamerPair> candidates,
                                    const Observer& obs,
                                    const Spectrum& mismatchLight,
                                    std::size_t count)
{
    std::sort(candidates.begin(), candidates.end(), [](const MetamerPair& x, const MetamerPair& y) {
        return x.de00Mismatch > y.de00Mismatch;
    });
    std::vector<MetamerPair> chosen;
    std::vector<double> hues;
    for (const auto& c : candidates) {
        if (chosen.size() >= count) {
            break;
        }
        const colour::Lab lab = labUnder(obs, mismatchLight, c.a);
        const double hue = std::atan2(lab.b, lab.a) * 180.0 / std::numbers::pi;
        const bool spread = std::all_of(hues.begin(), hues.end(), [hue](double h) {
            const double diff = std::abs(std::remainder(hue - h, 360.0));
            return diff >= 30.0;
        });
        if (!spread) {
            continue;
        }
        hues.push_back(hue);
        chosen.push_back(c);
        chosen.back().name = fmt::format("pair{:02}", chosen.size());
    }
    return chosen;
}

} // namespace

std::vector<MetamerPair> findMetamerPairs(const Observer& obs,
                                          const colour::ChannelBasis& basis,
                                          const Spectrum& matchLight,
                                          const Spectrum& mismatchLight,
                                          const NamedSpectra& seeds,
                                          std::size_t count,
                                          double minMismatch,
                                          double targetMismatch)
{
    const auto directions = nullSpaceDirections(obs, basis, matchLight);
    std::vector<MetamerPair> candidates;
    for (std::size_t s = 0; s < seeds.size(); ++s) {
        const auto c0 = colour::projectReflectance(basis, seeds.spectra[s]);
        const Spectrum a = reconstruct(basis, c0);
        if (!inRange(a)) {
            continue;
        }
        MetamerPair best;
        Spectrum bestStep;
        double bestT = 0.0;
        for (const auto& d : directions) {
            const Spectrum wd = reconstruct(basis, d);
            // Largest step t with kLow <= a + t wd <= kHigh in every band.
            double t = std::numeric_limits<double>::infinity();
            for (std::size_t l = 0; l < kBands; ++l) {
                if (wd[l] > 1e-12) {
                    t = std::min(t, (kHigh - a[l]) / wd[l]);
                } else if (wd[l] < -1e-12) {
                    t = std::min(t, (kLow - a[l]) / wd[l]);
                }
            }
            if (!std::isfinite(t) || t <= 0.0) {
                continue;
            }
            const Spectrum b = a + wd * t;
            const double mismatch = reflectancePairDifference(obs, mismatchLight, a, b);
            if (mismatch > best.de00Mismatch) {
                best.a = a;
                best.b = b;
                best.de00Mismatch = mismatch;
                bestStep = wd;
                bestT = t;
            }
        }
        // Walk back along the best direction to the target mismatch: the smallest change of
        // spectrum that gives it, so b stays as plausible a surface as a.
        if (targetMismatch > 0.0 && best.de00Mismatch > targetMismatch) {
            double lo = 0.0;
            double hi = bestT;
            for (int it = 0; it < 40; ++it) {
                const double mid = 0.5 * (lo + hi);
                const double mm =
                        reflectancePairDifference(obs, mismatchLight, a, a + bestStep * mid);
                (mm < targetMismatch ? lo : hi) = mid;
            }
            best.b = a + bestStep * hi;
            best.de00Mismatch = reflectancePairDifference(obs, mismatchLight, a, best.b);
        }
        if (best.de00Mismatch >= minMismatch) {
            best.seed = seeds.names[s];
            best.de00Match = reflectancePairDifference(obs, matchLight, best.a, best.b);
            candidates.push_back(best);
        }
    }
    return spreadHues(std::move(candidates), obs, mismatchLight, count);
}

Expected<void> saveMetamerPairs(const std::vector<MetamerPair>& pairs,
                                const std::filesystem::path& path,
                                const std::string& provenance)
{
    std::string text = fmt::format("# Replica metameric pairs: {}\n", provenance);
    for (const auto& p : pairs) {
        text += fmt::format(
                "# {}: from {}; CIEDE2000 {:.4f} under the matching light, {:.2f} under the "
                "other\n",
                p.name, p.seed, p.de00Match, p.de00Mismatch);
    }
    text += "wavelength_nm";
    for (const auto& p : pairs) {
        text += fmt::format(",{}_a,{}_b", p.name, p.name);
    }
    text += "\n";
    for (std::size_t l = 0; l < kBands; ++l) {
        text += fmt::format("{}", colour::bandCentreNm(l));
        for (const auto& p : pairs) {
            text += fmt::format(",{:.6f},{:.6f}", p.a[l], p.b[l]);
        }
        text += "\n";
    }
    if (path.has_parent_path()) {
        std::error_code ec;
        std::filesystem::create_directories(path.parent_path(), ec);
    }
    return writeOutputFile(path, text, "metamer pairs");
}

} // namespace replica::pipeline::spectral
