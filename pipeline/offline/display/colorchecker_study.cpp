// ColorChecker through the whole chain.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>

#include <fmt/format.h>

#include <pipeline/colour/cat02.h>
#include <pipeline/colour/channel_basis.h>
#include <pipeline/colour/ciede2000.h>
#include <pipeline/colour/cielab.h>
#include <pipeline/colour/spectral_table.h>
#include <pipeline/colour/xyz.h>
#include <pipeline/display/dither.h>
#include <pipeline/offline/display/colorchecker_study.h>
#include <pipeline/spectral/light_classifier.h>

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

// The screen's reflection of the booth light: what the pipeline subtracts from its targets (the
// profile's estimate, none when it was measured in the lit booth) and what the screen's front
// surface really adds to the reading (independent of the profile's note).
struct BoothFlare {
    FlareHandling handling = FlareHandling::Dark;
    glm::dvec3 estimate{0.0};
    glm::dvec3 real{0.0};

    BoothFlare(const DisplayModel& model,
               FlareHandling h,
               double illuminanceLux,
               const glm::dvec3& lightUnitY)
        : handling(h)
    {
        if (h != FlareHandling::Dark) {
            estimate = frontSurfaceFlareXyz(model, illuminanceLux, lightUnitY);
            real = model.frontSurfaceReflectance * illuminanceLux / std::numbers::pi * lightUnitY;
        }
    }
    // The XYZ the display is asked for when the render gives 'xyz'.
    glm::dvec3 target(const glm::dvec3& xyz) const
    {
        return handling == FlareHandling::InBoothSubtract ? xyz - estimate : xyz;
    }
    // What a meter reads in front of the panel showing 'counts' (one dither tile).
    glm::dvec3 reading(const glm::dvec3& counts,
                       double maxCount,
                       const std::function<glm::dvec3(const glm::dvec3&)>& panel) const
    {
        return tileReading(counts, maxCount, panel) + real;
    }
};

// The renderer's XYZ (cd/m^2) of a reflectance through a six-channel basis under E lux.
glm::dvec3 sixChannelXyz(const colour::ChannelBasis& basis,
                         const colour::ChannelToXyz& toXyz,
                         const colour::Spectrum& reflectance,
                         double illuminanceLux)
{
    const colour::ChannelCoeffs c = colour::projectReflectance(basis, reflectance);
    glm::dvec3 xyz(0.0);
    for (std::size_t k = 0; k < colour::kChannels; ++k) {
        xyz += c[k] * toXyz[k];
    }
    return xyz * (illuminanceLux / std::numbers::pi);
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

namespace {

// One light's patches through every workflow: the full-spectral XYZ (on the absolute scale), the
// renderer's six channels, what the panel shows of them mapped and clipped, and the paper's six.
struct ShownPatches {
    std::vector<glm::dvec3> spectral, channel, shownMapped, shownClipped, paper, shownPaper;
};

ShownPatches showPatches(const DisplayInverse& inverse,
                         const std::function<glm::dvec3(const glm::dvec3&)>& panel,
                         const colour::Observer& observer,
                         const SensedSamples& chart,
                         const colour::Spectrum& spd,
                         const StudyOptions& options,
                         LightResult& lr)
{
    const double e = options.illuminanceLux;
    // Absolute scale: a perfect diffuser under E lux has luminance E / pi.
    const colour::Xyz lightXyz = colour::spectrumToXyz(observer, spd);
    const double scale = e / std::numbers::pi / lightXyz.y;
    const colour::ChannelToXyz toXyz = colour::channelToXyz(options.basis, observer, spd);
    const BoothFlare flare(inverse.model(), options.flare, e, lightXyz / lightXyz.y);
    const double maxCount = inverse.model().maxCount();
    ShownPatches s;
    std::vector<spectral::Xyz> paperVectors;
    if (options.paperSix != nullptr) {
        paperVectors = options.paperSix->lightVectors(spd);
    }
    for (std::size_t p = 0; p < chart.reflectances.size(); ++p) {
        const colour::Spectrum& refl = chart.reflectances[p];
        s.spectral.push_back(colour::spectrumToXyz(observer, refl * spd) * scale);
        const glm::dvec3 xyz = sixChannelXyz(options.basis, toXyz, refl, e);
        s.channel.push_back(xyz);
        const glm::dvec3 target = flare.target(xyz);
        const InverseResult mapped = inverse.invert(target, GamutMode::HueKeeping);
        const InverseResult clipped = inverse.invert(target, GamutMode::Clip);
        s.shownMapped.push_back(flare.reading(mapped.counts, maxCount, panel));
        s.shownClipped.push_back(flare.reading(clipped.counts, maxCount, panel));
        PatchResult pr;
        pr.name = chart.names[p];
        pr.gamutClass = mapped.gamutClass;
        pr.targetXyz = target;
        if (options.paperSix != nullptr) {
            const glm::dvec3 px = spectral::shade(options.paperSix->encode(refl), paperVectors) *
                                  e / std::numbers::pi;
            s.paper.push_back(px);
            const InverseResult pm = inverse.invert(flare.target(px), GamutMode::HueKeeping);
            s.shownPaper.push_back(flare.reading(pm.counts, maxCount, panel));
            pr.paperSixGamutClass = pm.gamutClass;
        }
        lr.patches.push_back(pr);
    }
    return s;
}

// Each patch's differences from the full-spectral workflow, and their statistics.
void comparePatches(const ShownPatches& s,
                    std::size_t whiteIndex,
                    const glm::dvec3& lightUnitY,
                    const StudyOptions& options,
                    LightResult& lr)
{
    const double e = options.illuminanceLux;
    const glm::dvec3 d65{0.95047, 1.0, 1.08883};
    // The paper's comparison: each workflow relative to its own white patch, put on the
    // spectral workflow's scale, adapted (CAT02) from the light's white to D65, then CIELAB.
    auto relative = [&](const std::vector<glm::dvec3>& v, std::size_t i) {
        const double wY = v[whiteIndex].y;
        const double ref = s.spectral[whiteIndex].y / (e / std::numbers::pi);
        const glm::dvec3 rel = wY > 0.0 ? v[i] / wY * ref : glm::dvec3(0.0);
        return colour::xyzToLab(colour::cat02Adapt(rel, lightUnitY, d65), d65);
    };
    // Against the perfect diffuser: the light's white at E / pi, on the spectral scale.
    auto absolute = [&](const std::vector<glm::dvec3>& v, std::size_t i) {
        const glm::dvec3 rel = v[i] / (e / std::numbers::pi);
        return colour::xyzToLab(colour::cat02Adapt(rel, lightUnitY, d65), d65);
    };
    std::vector<double> dmAbs, dcAbs, six, dm, dc, dmIn, ps, psm, psmIn;
    for (std::size_t i = 0; i < lr.patches.size(); ++i) {
        auto& pr = lr.patches[i];
        const colour::Lab base = relative(s.spectral, i);
        if (options.paperSix != nullptr) {
            pr.paperSixDe00 = colour::ciede2000(base, relative(s.paper, i));
            pr.paperSixMappedDe00 = colour::ciede2000(base, relative(s.shownPaper, i));
            ps.push_back(pr.paperSixDe00);
            psm.push_back(pr.paperSixMappedDe00);
            if (pr.paperSixGamutClass == GamutClass::InGamut) {
                psmIn.push_back(pr.paperSixMappedDe00);
            }
        }
        pr.sixChannelDe00 = colour::ciede2000(base, relative(s.channel, i));
        pr.mappedDe00 = colour::ciede2000(base, relative(s.shownMapped, i));
        pr.clippedDe00 = colour::ciede2000(base, relative(s.shownClipped, i));
        const colour::Lab baseAbs = absolute(s.spectral, i);
        pr.mappedAbsoluteDe00 = colour::ciede2000(baseAbs, absolute(s.shownMapped, i));
        pr.clippedAbsoluteDe00 = colour::ciede2000(baseAbs, absolute(s.shownClipped, i));
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
    lr.paperSix = errorStats(ps);
    lr.paperSixMapped = errorStats(psm);
    lr.paperSixMappedInGamut = errorStats(psmIn);
}

} // namespace

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
    auto chart = colorCheckerSamples(dataDir);
    if (!chart) {
        return tl::unexpected(chart.error());
    }
    const auto whiteIt = std::find(chart->names.begin(), chart->names.end(), kWhitePatch);
    if (whiteIt == chart->names.end()) {
        return makeError(ErrorCode::NotFound,
                         fmt::format("{}: no column '{}'", kColorChecker, kWhitePatch));
    }
    const auto whiteIndex = static_cast<std::size_t>(whiteIt - chart->names.begin());
    std::vector<LightResult> results;
    for (const auto& light : boothLights()) {
        auto table = colour::loadSpectralCsv(dataDir / "spectra" / light.file);
        if (!table) {
            return tl::unexpected(table.error());
        }
        auto spd = table->spectrum(light.column, colour::GridSampling::BandAverage);
        if (!spd) {
            return tl::unexpected(spd.error());
        }
        const colour::Xyz lightXyz = colour::spectrumToXyz(*observer, *spd);
        if (!(lightXyz.y > 0.0)) {
            return makeError(
                    ErrorCode::InvalidArgument,
                    fmt::format("{}: light '{}' has no luminance", table->source, light.column));
        }
        LightResult lr;
        lr.light = light.name;
        const ShownPatches shown =
                showPatches(inverse, panel, *observer, *chart, *spd, options, lr);
        comparePatches(shown, whiteIndex, lightXyz / lightXyz.y, options, lr);
        results.push_back(std::move(lr));
    }
    return results;
}

Expected<SensedSamples> colorCheckerSamples(const std::filesystem::path& dataDir)
{
    auto chart = colour::loadSpectralCsv(dataDir / "spectra" / kColorChecker);
    if (!chart) {
        return tl::unexpected(chart.error());
    }
    auto patches = chart->allSpectra(colour::GridSampling::AtBandCentre);
    if (!patches) {
        return tl::unexpected(patches.error());
    }
    return SensedSamples{chart->columns, std::move(*patches)};
}

Expected<std::vector<spectral::FineLight>> fineBoothLights(const std::filesystem::path& dataDir)
{
    std::vector<spectral::FineLight> out;
    for (const auto& light : boothLights()) {
        auto table = colour::loadSpectralCsv(dataDir / "spectra" / light.file);
        if (!table) {
            return tl::unexpected(table.error());
        }
        auto fine = spectral::restoreLines(*table, light.column);
        if (!fine) {
            return tl::unexpected(fine.error());
        }
        fine->name = light.name;
        out.push_back(std::move(*fine));
    }
    return out;
}

namespace {

// The shift found once against the lines of whichever calibration lights have them (the booth's
// fluorescent lamps, measured beforehand averaging 50 spectra: what 'replica calibrate
// spectrometer' does); NaN when none has lines.
Expected<double> calibratedOffset(const std::vector<spectral::FineLight>& lights,
                                  const colour::Observer& observer,
                                  const spectral::InstrumentImpairments& imp,
                                  std::uint64_t drawSeed)
{
    double sum = 0.0;
    int found = 0;
    spectral::SensingCorrections pre;
    pre.strayLight = true;
    pre.wavelengthLines = true;
    pre.scansAveraged = 50;
    for (std::size_t k = 0; k < lights.size(); ++k) {
        if (lights[k].lines.empty()) {
            continue;
        }
        auto m = spectral::senseLight(lights[k], observer, imp, pre, drawSeed * 31 + 101 + k);
        if (!m) {
            return tl::unexpected(m.error());
        }
        if (m->linesFound) {
            sum += m->wavelengthFoundNm;
            ++found;
        }
    }
    return found > 0 ? sum / found : std::numeric_limits<double>::quiet_NaN();
}

// Classifier mode: the nearest of the lights as the same instrument measured each beforehand
// (averaging 50 spectra), at the real light's Y; the sensed spectrum itself when none is near.
Expected<colour::Spectrum> classifierLight(const std::vector<spectral::FineLight>& lights,
                                           const colour::Observer& observer,
                                           const spectral::InstrumentImpairments& imp,
                                           const spectral::SensingCorrections& corr,
                                           const colour::Spectrum& sensed,
                                           std::uint64_t drawSeed,
                                           double realY,
                                           int& chosen)
{
    std::vector<spectral::StoredLight> stored;
    spectral::SensingCorrections pre = corr;
    pre.scansAveraged = 50;
    for (std::size_t k = 0; k < lights.size(); ++k) {
        auto m = spectral::senseLight(lights[k], observer, imp, pre, drawSeed * 31 + 17 + k);
        if (!m) {
            return tl::unexpected(m.error());
        }
        stored.push_back({lights[k].name, m->spd});
    }
    auto classifier = spectral::LightClassifier::create(stored);
    if (!classifier) {
        return tl::unexpected(classifier.error());
    }
    const spectral::Classification c = classifier->nearest(sensed);
    chosen = c.index;
    if (c.index < 0) {
        return sensed;
    }
    const colour::Spectrum& spd = stored[static_cast<std::size_t>(c.index)].spd;
    return spd * (realY / std::max(colour::spectrumToXyz(observer, spd).y, 1e-300));
}

// The working-grid SPDs of the lights, each with luminance.
Expected<std::vector<colour::Spectrum>> realLights(const std::vector<spectral::FineLight>& lights,
                                                   const colour::Observer& observer)
{
    std::vector<colour::Spectrum> real;
    for (const auto& l : lights) {
        auto spd = spectral::fineLightToWorkingGrid(l);
        if (!spd) {
            return tl::unexpected(spd.error());
        }
        if (!(colour::spectrumToXyz(observer, *spd).y > 0.0)) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("{}: the light has no luminance", l.name));
        }
        real.push_back(*spd);
    }
    return real;
}

// One light of the sensed study: every draw sensed, rendered, shown and compared.
struct SensedLightRun {
    const DisplayInverse& inverse;
    const std::function<glm::dvec3(const glm::dvec3&)>& panel;
    const colour::Observer& observer;
    const std::vector<spectral::FineLight>& lights;
    const SensedSamples& samples;
    const std::function<Expected<std::vector<glm::dvec3>>(const colour::Spectrum&)>& render;
    const SensedStudyOptions& options;

    Expected<SensedLightStats> run(std::size_t li, const colour::Spectrum& real) const
    {
        const double e = options.illuminanceLux;
        const glm::dvec3 d65{0.95047, 1.0, 1.08883};
        const colour::Xyz lightXyz = colour::spectrumToXyz(observer, real);
        const glm::dvec3 lightUnitY = lightXyz / lightXyz.y;
        const double scale = e / std::numbers::pi / lightXyz.y;
        auto lab = [&](const glm::dvec3& xyz) {
            return colour::xyzToLab(
                    colour::cat02Adapt(xyz / (e / std::numbers::pi), lightUnitY, d65), d65);
        };
        std::vector<colour::Lab> truth;
        for (const auto& refl : samples.reflectances) {
            truth.push_back(lab(colour::spectrumToXyz(observer, refl * real) * scale));
        }
        const BoothFlare flare(inverse.model(), options.flare, e, lightUnitY);
        const double maxCount = inverse.model().maxCount();
        SensedLightStats st;
        st.light = lights[li].name;
        std::vector<double> dRender, dIn, dOut;
        double shape = 0.0;
        for (int d = 0; d < options.draws; ++d) {
            const std::uint64_t drawSeed =
                    options.seed * 1'000'003ULL + static_cast<std::uint64_t>(d);
            auto used = sensedLight(li, real, lightXyz.y, drawSeed, st, shape);
            if (!used) {
                return tl::unexpected(used.error());
            }
            auto xyz = render(*used);
            if (!xyz) {
                return tl::unexpected(xyz.error());
            }
            for (std::size_t p = 0; p < xyz->size(); ++p) {
                dRender.push_back(colour::ciede2000(truth[p], lab((*xyz)[p])));
                const InverseResult mapped =
                        inverse.invert(flare.target((*xyz)[p]), GamutMode::HueKeeping);
                const glm::dvec3 shown = flare.reading(mapped.counts, maxCount, panel);
                const double de = colour::ciede2000(truth[p], lab(shown));
                (mapped.gamutClass == GamutClass::InGamut ? dIn : dOut).push_back(de);
            }
        }
        st.render = errorStats(dRender);
        st.panelInGamut = errorStats(dIn);
        st.panelOutOfGamut = errorStats(dOut);
        st.lightShapeError = shape / options.draws;
        return st;
    }

    // One draw's instrument sensing light 'li': the light the renderer then uses.
    Expected<colour::Spectrum> sensedLight(std::size_t li,
                                           const colour::Spectrum& real,
                                           double realY,
                                           std::uint64_t drawSeed,
                                           SensedLightStats& st,
                                           double& shape) const
    {
        spectral::InstrumentImpairments imp = options.impairments;
        imp.wavelengthErrorNm =
                spectral::drawWavelengthError(options.wavelengthErrorMaxNm, drawSeed);
        spectral::SensingCorrections corr = options.corrections;
        if (corr.wavelengthLines || corr.applianceChain) {
            auto offset = calibratedOffset(
                    options.calibrationLights.empty() ? lights : options.calibrationLights,
                    observer, imp, drawSeed);
            if (!offset) {
                return tl::unexpected(offset.error());
            }
            corr.rememberedOffsetNm = *offset;
        }
        auto sensed = spectral::senseLight(lights[li], observer, imp, corr, drawSeed * 31 + li);
        if (!sensed) {
            return tl::unexpected(sensed.error());
        }
        shape += spectral::spectralShapeDistance(sensed->spd, real);
        if (options.mode != SensingMode::Classifier) {
            return sensed->spd;
        }
        int chosen = -1;
        auto used =
                classifierLight(lights, observer, imp, corr, sensed->spd, drawSeed, realY, chosen);
        if (chosen != static_cast<int>(li)) {
            ++st.misclassified;
        }
        return used;
    }
};

} // namespace

Expected<std::vector<SensedLightStats>>
sensedStudy(const DisplayInverse& inverse,
            const std::function<glm::dvec3(const glm::dvec3&)>& panel,
            const colour::Observer& observer,
            const std::vector<spectral::FineLight>& lights,
            const SensedSamples& samples,
            const spectral::AdaptiveEncoder* encoder,
            const colour::ChannelBasis& basis,
            const SensedStudyOptions& options)
{
    if (options.draws < 1 || lights.empty() || samples.reflectances.empty()) {
        return makeError(ErrorCode::InvalidArgument,
                         "sensed study: needs at least one draw, one light and one sample");
    }
    auto real = realLights(lights, observer);
    if (!real) {
        return tl::unexpected(real.error());
    }
    // XYZ (cd/m^2) of every sample rendered under 'spd' (scaled to the real light's Y).
    const std::function<Expected<std::vector<glm::dvec3>>(const colour::Spectrum&)> render =
            [&](const colour::Spectrum& spd) -> Expected<std::vector<glm::dvec3>> {
        colour::ChannelBasis b = basis;
        if (encoder != nullptr) {
            auto adapted = encoder->basisFor(spd);
            if (!adapted) {
                return tl::unexpected(adapted.error());
            }
            b = std::move(*adapted);
        }
        const colour::ChannelToXyz toXyz = colour::channelToXyz(b, observer, spd);
        std::vector<glm::dvec3> out;
        for (const auto& refl : samples.reflectances) {
            out.push_back(sixChannelXyz(b, toXyz, refl, options.illuminanceLux));
        }
        return out;
    };
    const SensedLightRun run{inverse, panel, observer, lights, samples, render, options};
    std::vector<SensedLightStats> results;
    for (std::size_t li = 0; li < lights.size(); ++li) {
        auto st = run.run(li, (*real)[li]);
        if (!st) {
            return tl::unexpected(st.error());
        }
        results.push_back(std::move(*st));
    }
    return results;
}

} // namespace replica::pipeline::display
