// ColorChecker through the whole chain.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

#include <fmt/format.h>

#include <pipeline/colour/cat02.h>
#include <pipeline/colour/channel_basis.h>
#include <pipeline/colour/ciede2000.h>
#include <pipeline/colour/cielab.h>
#include <pipeline/colour/spectral_table.h>
#include <pipeline/colour/xyz.h>
#include <pipeline/display/colorchecker_study.h>
#include <pipeline/display/dither.h>

namespace replica::pipeline::display {
namespace {

constexpr const char* kColorChecker = "colorchecker24_babelcolor_avg_10nm_380_730.csv";
constexpr const char* kWhitePatch = "white_9.5";

// The reading of a spot meter over one dither tile.
glm::dvec3 tileReading(const glm::dvec3& counts,
                       double maxCount,
                       const std::function<glm::dvec3(const glm::dvec3&)>& panel)
{
    glm::dvec3 sum(0.0);
    for (int y = 0; y < kDitherSize; ++y) {
        for (int x = 0; x < kDitherSize; ++x) {
            glm::dvec3 q;
            for (int c = 0; c < 3; ++c) {
                q[c] = quantiseCount(counts[c], x, y, maxCount);
            }
            sum += panel(q);
        }
    }
    return sum / static_cast<double>(kDitherSize * kDitherSize);
}

} // namespace

std::vector<StudyLight> boothLights()
{
    return {{"D65 booth (F7)", "cie_illuminants_F1_F12_5nm_380_780.csv", "F7"},
            {"D50 booth (F8)", "cie_illuminants_F1_F12_5nm_380_780.csv", "F8"},
            {"Ill. A booth", "cie_illuminants_A_D50_D65_5nm_300_780.csv", "A"}};
}

ErrorStats errorStats(const std::vector<double>& de)
{
    ErrorStats s;
    s.count = static_cast<int>(de.size());
    if (de.empty()) {
        return s;
    }
    s.mean = std::accumulate(de.begin(), de.end(), 0.0) / static_cast<double>(de.size());
    double var = 0.0;
    for (double d : de) {
        var += (d - s.mean) * (d - s.mean);
    }
    s.std = std::sqrt(var / static_cast<double>(de.size()));
    std::vector<double> sorted = de;
    std::sort(sorted.begin(), sorted.end());
    const double pos = 0.9 * static_cast<double>(sorted.size() - 1);
    const auto i = static_cast<std::size_t>(std::floor(pos));
    const std::size_t j = std::min(i + 1, sorted.size() - 1);
    s.p90 = sorted[i] + (pos - static_cast<double>(i)) * (sorted[j] - sorted[i]);
    s.max = sorted.back();
    return s;
}

Expected<std::vector<LightResult>>
colorCheckerStudy(const DisplayInverse& inverse,
                  const std::function<glm::dvec3(const glm::dvec3&)>& panel,
                  const std::filesystem::path& dataDir,
                  const StudyOptions& options)
{
    auto observer = colour::loadCie1931(dataDir);
    if (!observer) {
        return tl::unexpected(observer.error());
    }
    auto chart = colour::loadSpectralCsv(dataDir / "spectra" / kColorChecker);
    if (!chart) {
        return tl::unexpected(chart.error());
    }
    auto patches = chart->allSpectra();
    if (!patches) {
        return tl::unexpected(patches.error());
    }
    const auto whiteIt = std::find(chart->columns.begin(), chart->columns.end(), kWhitePatch);
    if (whiteIt == chart->columns.end()) {
        return makeError(ErrorCode::NotFound,
                         fmt::format("{}: no column '{}'", chart->source, kWhitePatch));
    }
    const auto whiteIndex = static_cast<std::size_t>(whiteIt - chart->columns.begin());
    const colour::ChannelBasis& basis = options.basis;
    const DisplayModel& model = inverse.model();
    const double maxCount = model.maxCount();
    const double e = options.illuminanceLux;
    const glm::dvec3 d65{0.95047, 1.0, 1.08883};

    std::vector<LightResult> results;
    for (const auto& light : boothLights()) {
        auto table = colour::loadSpectralCsv(dataDir / "spectra" / light.file);
        if (!table) {
            return tl::unexpected(table.error());
        }
        auto spd = table->spectrum(light.column);
        if (!spd) {
            return tl::unexpected(spd.error());
        }
        // Absolute scale: a perfect diffuser under E lux has luminance E / pi.
        const colour::Xyz lightXyz = colour::spectrumToXyz(*observer, *spd);
        if (!(lightXyz.y > 0.0)) {
            return makeError(
                    ErrorCode::InvalidArgument,
                    fmt::format("{}: light '{}' has no luminance", table->source, light.column));
        }
        const glm::dvec3 lightUnitY = lightXyz / lightXyz.y;
        const double scale = e / std::numbers::pi / lightXyz.y;
        const colour::ChannelToXyz toXyz = colour::channelToXyz(basis, *observer, *spd);
        const glm::dvec3 flare = options.flare == FlareHandling::Dark
                                         ? glm::dvec3(0.0)
                                         : frontSurfaceFlareXyz(model, e, lightUnitY);
        // What the screen's front surface really reflects (independent of the profile's note).
        const glm::dvec3 realFlare =
                options.flare == FlareHandling::Dark
                        ? glm::dvec3(0.0)
                        : model.frontSurfaceReflectance * e / std::numbers::pi * lightUnitY;

        LightResult lr;
        lr.light = light.name;
        std::vector<glm::dvec3> spectral;
        std::vector<glm::dvec3> channel;
        std::vector<glm::dvec3> shownMapped;
        std::vector<glm::dvec3> shownClipped;
        for (std::size_t p = 0; p < patches->size(); ++p) {
            const colour::Spectrum& refl = (*patches)[p];
            spectral.push_back(colour::spectrumToXyz(*observer, refl * *spd) * scale);
            const colour::ChannelCoeffs c = colour::projectReflectance(basis, refl);
            glm::dvec3 xyz(0.0);
            for (std::size_t k = 0; k < colour::kChannels; ++k) {
                xyz += c[k] * toXyz[k];
            }
            xyz *= e / std::numbers::pi;
            channel.push_back(xyz);
            const glm::dvec3 target =
                    options.flare == FlareHandling::InBoothSubtract ? xyz - flare : xyz;
            const InverseResult mapped = inverse.invert(target, GamutMode::HueKeeping);
            const InverseResult clipped = inverse.invert(target, GamutMode::Clip);
            shownMapped.push_back(tileReading(mapped.counts, maxCount, panel) + realFlare);
            shownClipped.push_back(tileReading(clipped.counts, maxCount, panel) + realFlare);
            PatchResult pr;
            pr.name = chart->columns[p];
            pr.gamutClass = mapped.gamutClass;
            pr.targetXyz = target;
            lr.patches.push_back(pr);
        }
        // The paper's comparison: each workflow relative to its own white patch, put on the
        // spectral workflow's scale, adapted (CAT02) from the light's white to D65, then CIELAB.
        auto relative = [&](const std::vector<glm::dvec3>& v, std::size_t i) {
            const double wY = v[whiteIndex].y;
            const double ref = spectral[whiteIndex].y / (e / std::numbers::pi);
            const glm::dvec3 rel = wY > 0.0 ? v[i] / wY * ref : glm::dvec3(0.0);
            return colour::xyzToLab(colour::cat02Adapt(rel, lightUnitY, d65), d65);
        };
        // Against the perfect diffuser: the light's white at E / pi, on the spectral scale.
        auto absolute = [&](const std::vector<glm::dvec3>& v, std::size_t i) {
            const glm::dvec3 rel = v[i] / (e / std::numbers::pi);
            return colour::xyzToLab(colour::cat02Adapt(rel, lightUnitY, d65), d65);
        };
        std::vector<double> dmAbs;
        std::vector<double> dcAbs;
        std::vector<double> six;
        std::vector<double> dm;
        std::vector<double> dc;
        std::vector<double> dmIn;
        for (std::size_t i = 0; i < lr.patches.size(); ++i) {
            auto& pr = lr.patches[i];
            const colour::Lab base = relative(spectral, i);
            pr.sixChannelDe00 = colour::ciede2000(base, relative(channel, i));
            pr.mappedDe00 = colour::ciede2000(base, relative(shownMapped, i));
            pr.clippedDe00 = colour::ciede2000(base, relative(shownClipped, i));
            const colour::Lab baseAbs = absolute(spectral, i);
            pr.mappedAbsoluteDe00 = colour::ciede2000(baseAbs, absolute(shownMapped, i));
            pr.clippedAbsoluteDe00 = colour::ciede2000(baseAbs, absolute(shownClipped, i));
            dmAbs.push_back(pr.mappedAbsoluteDe00);
            dcAbs.push_back(pr.clippedAbsoluteDe00);
            six.push_back(pr.sixChannelDe00);
            dm.push_back(pr.mappedDe00);
            dc.push_back(pr.clippedDe00);
            if (pr.gamutClass == GamutClass::InGamut) {
                dmIn.push_back(pr.mappedDe00);
            } else {
                lr.outOfGamut.push_back(pr.name);
            }
        }
        lr.sixChannel = errorStats(six);
        lr.mapped = errorStats(dm);
        lr.clipped = errorStats(dc);
        lr.mappedInGamut = errorStats(dmIn);
        lr.mappedAbsolute = errorStats(dmAbs);
        lr.clippedAbsolute = errorStats(dcAbs);
        results.push_back(std::move(lr));
    }
    return results;
}

} // namespace replica::pipeline::display
