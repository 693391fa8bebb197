// Scene generators. Reflectances come from measured data in data/spectra (BabelColor ColorChecker
// average, CIE test colour samples); geometry is procedural with a fixed-seed Mersenne twister.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include <fmt/format.h>

#include <pipeline/colour/ciede2000.h>
#include <pipeline/colour/cielab.h>
#include <pipeline/colour/spectral_table.h>
#include <pipeline/offline/surface/scene_generator.h>

namespace replica::pipeline::surface {
namespace {

// mt19937's sequence is fixed by the standard; the library distributions are not, so map by hand.
struct Rng {
    std::mt19937 g;
    explicit Rng(unsigned seed) : g(seed) {}
    double uniform(double lo, double hi)
    {
        return lo + (hi - lo) * static_cast<double>(g() >> 8) / 16777216.0;
    }
};

SurfaceScene blank(const std::string& name, int w, int h, double pitchM)
{
    SurfaceScene s;
    s.name = name;
    s.width = w;
    s.height = h;
    s.widthM = w * pitchM;
    s.heightM = h * pitchM;
    const std::size_t n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
    s.pigmentA.assign(n, 0);
    s.pigmentB.assign(n, 0);
    s.mix.assign(n, 0.0f);
    s.shade.assign(n, 1.0f);
    s.relief.width = w;
    s.relief.height = h;
    s.relief.pitchM = pitchM;
    s.relief.m.assign(n, 0.0);
    return s;
}

Expected<SurfaceScene> colorChecker(const std::filesystem::path& dataDir)
{
    auto t = colour::loadSpectralCsv(dataDir / "spectra" /
                                     "colorchecker24_babelcolor_avg_10nm_380_730.csv");
    if (!t) {
        return tl::unexpected(t.error());
    }
    auto spectra = t->allSpectra(colour::GridSampling::AtBandCentre);
    if (!spectra) {
        return tl::unexpected(spectra.error());
    }
    // 6 x 4 patches of 40 mm on a 1 mm grid, 5 mm black frame between them (as on the real chart).
    const int patch = 40, gap = 5;
    SurfaceScene s = blank("colorchecker", 6 * patch + 7 * gap, 4 * patch + 5 * gap, 0.001);
    s.palette = *spectra;
    s.paletteNames = t->columns;
    s.palette.push_back((*spectra)[23] * 0.85); // the chart's frame, a little darker than black 2
    s.paletteNames.push_back("frame");
    const int frame = static_cast<int>(s.palette.size()) - 1;
    for (int y = 0; y < s.height; ++y) {
        for (int x = 0; x < s.width; ++x) {
            const int px = (x - gap) / (patch + gap);
            const int py = (y - gap) / (patch + gap);
            const bool inPatch = x >= gap && y >= gap && (x - gap) % (patch + gap) < patch &&
                                 (y - gap) % (patch + gap) < patch && px < 6 && py < 4;
            const std::size_t k = static_cast<std::size_t>(y) * s.width + x;
            s.pigmentA[k] = s.pigmentB[k] = inPatch ? py * 6 + px : frame;
        }
    }
    s.alpha = 0.15; // semi-gloss lacquer
    s.rhoS = colour::Spectrum::constant(0.03);
    return s;
}

} // namespace

colour::Spectrum metamericBlack(const colour::Observer& obs,
                                const colour::Spectrum& light,
                                const colour::Spectrum& shape)
{
    // Remove from 'shape' its component in the span of the three light-weighted CMFs (Cohen's
    // matrix R): what is left gives zero tristimulus values under this light.
    const colour::Spectrum rows[3] = {obs.xbar * light, obs.ybar * light, obs.zbar * light};
    double g[3][3];
    double b[3];
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            g[i][j] = (rows[i] * rows[j]).sum();
        }
        b[i] = (rows[i] * shape).sum();
    }
    // Solve g c = b (3x3, symmetric positive definite) by Cramer's rule.
    const auto det3 = [](double m[3][3]) {
        return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
               m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
               m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    };
    const double d = det3(g);
    colour::Spectrum out = shape;
    if (!(std::abs(d) > 0.0)) {
        return out;
    }
    for (int c = 0; c < 3; ++c) {
        double m[3][3];
        for (int i = 0; i < 3; ++i) {
            for (int j = 0; j < 3; ++j) {
                m[i][j] = j == c ? b[i] : g[i][j];
            }
        }
        out = out + rows[c] * (-det3(m) / d);
    }
    return out;
}

namespace {

// Pairs side by side, one pair a row, on a neutral surround (palette 0): pair p's two halves are
// palette entries 1 + 2p and 2 + 2p. Three rows keep the 40 mm patches of the first target.
void layOutPairs(SurfaceScene& s, int rows)
{
    const int pitch = 150 / rows, patchH = pitch * 4 / 5;
    const int top = (s.height - rows * pitch + (pitch - patchH)) / 2;
    for (int y = 0; y < s.height; ++y) {
        for (int x = 0; x < s.width; ++x) {
            const std::size_t k = static_cast<std::size_t>(y) * s.width + x;
            const int row = (y - top) / pitch;
            const int yy = (y - top) % pitch;
            int pig = 0;
            if (y >= top && row < rows && yy < patchH && x >= 20 && x < 220 &&
                !(x >= 118 && x < 122)) {
                pig = 1 + 2 * row + (x >= 120 ? 1 : 0);
            }
            s.pigmentA[k] = s.pigmentB[k] = pig;
        }
    }
    s.alpha = 0.3;
    s.rhoS = colour::Spectrum{}; // matte: the planner skips the specular pass
}

// The paper's target (Fig. 7): the six pairs of 'replica spectral metamers'
// (data/scenes/metamers/metamers_A_D65.csv), each a match under tungsten (CIE A) and a visible
// difference under D65 and the booth's D65 simulator.
Expected<SurfaceScene> metamerTarget(const std::filesystem::path& dataDir)
{
    auto cc = colour::loadSpectralCsv(dataDir / "spectra" /
                                      "colorchecker24_babelcolor_avg_10nm_380_730.csv");
    auto pairs = colour::loadSpectralCsv(dataDir / "scenes" / "metamers" / "metamers_A_D65.csv");
    if (!cc || !pairs) {
        return tl::unexpected(!cc ? cc.error() : pairs.error());
    }
    auto spectra = pairs->allSpectra(colour::GridSampling::AtBandCentre);
    if (!spectra) {
        return tl::unexpected(spectra.error());
    }
    if (spectra->empty() || spectra->size() % 2 != 0 || spectra->size() > 12) {
        return makeError(ErrorCode::InvalidArgument,
                         "metamers_A_D65.csv: expected 1 to 6 pairs of columns (_a, _b)");
    }
    SurfaceScene s = blank("metamer", 240, 160, 0.001);
    s.palette.push_back(*cc->spectrum("neutral_6.5", colour::GridSampling::AtBandCentre) * 0.9);
    s.paletteNames.push_back("surround");
    for (std::size_t i = 0; i < spectra->size(); ++i) {
        s.palette.push_back((*spectra)[i]);
        s.paletteNames.push_back(i % 2 == 0 ? pairs->columns[i]
                                            : pairs->columns[i] + "_metamer_under_A");
    }
    layOutPairs(s, static_cast<int>(spectra->size() / 2));
    return s;
}

// The reverse target (the first one shipped): three ColorChecker colours, each paired with a
// metamer under the booth's D65 simulator (CIE F7) that differs under tungsten.
Expected<SurfaceScene> metamerD65Target(const std::filesystem::path& dataDir)
{
    auto cc = colour::loadSpectralCsv(dataDir / "spectra" /
                                      "colorchecker24_babelcolor_avg_10nm_380_730.csv");
    auto ill = colour::loadSpectralCsv(dataDir / "spectra" /
                                       "cie_illuminants_10nm_380_730_triangular.csv");
    auto obs = colour::loadCie1931(dataDir);
    if (!cc || !ill || !obs) {
        return tl::unexpected(!cc ? cc.error() : (!ill ? ill.error() : obs.error()));
    }
    const colour::Spectrum f7 = *ill->spectrum("F7", colour::GridSampling::BandAverage);
    // Three pairs, matched under the booth's D65 simulator (F7): a grey, a skin tone, a foliage
    // green.
    SurfaceScene s = blank("metamer-d65", 240, 160, 0.001);
    const char* bases[3] = {"neutral_5", "light_skin", "foliage"};
    s.palette.push_back(*cc->spectrum("neutral_6.5", colour::GridSampling::AtBandCentre) * 0.9);
    s.paletteNames.push_back("surround");
    for (int p = 0; p < 3; ++p) {
        const colour::Spectrum r1 = *cc->spectrum(bases[p], colour::GridSampling::AtBandCentre);
        // Among smooth candidate shapes, keep the metameric black that separates the pair most
        // under tungsten (CIE A): the target should show a visible mismatch when the light is
        // switched.
        const colour::Spectrum a = *ill->spectrum("A", colour::GridSampling::BandAverage);
        const colour::Xyz whiteA =
                colour::reflectanceToXyz(*obs, a, colour::Spectrum::constant(1.0));
        colour::Spectrum bestR2 = r1;
        double bestDe = -1.0;
        for (int freq = 1; freq <= 4; ++freq) {
            for (int phase = 0; phase < 8; ++phase) {
                colour::Spectrum shape;
                for (std::size_t i = 0; i < colour::kBands; ++i) {
                    const double t = static_cast<double>(i) / (colour::kBands - 1);
                    shape[i] = std::sin(std::numbers::pi * (freq * t + phase / 8.0));
                }
                const colour::Spectrum black = metamericBlack(*obs, f7, shape);
                double scale = 1e9; // largest scale that keeps r2 within [0.02, 0.95]
                for (std::size_t i = 0; i < colour::kBands; ++i) {
                    if (black[i] > 0.0) {
                        scale = std::min(scale, (0.95 - r1[i]) / black[i]);
                    } else if (black[i] < 0.0) {
                        scale = std::min(scale, (r1[i] - 0.02) / -black[i]);
                    }
                }
                const colour::Spectrum r2 = r1 + black * (0.9 * std::max(scale, 0.0));
                const double de = colour::ciede2000(
                        colour::xyzToLab(colour::reflectanceToXyz(*obs, a, r1), whiteA),
                        colour::xyzToLab(colour::reflectanceToXyz(*obs, a, r2), whiteA));
                if (de > bestDe) {
                    bestDe = de;
                    bestR2 = r2;
                }
            }
        }
        s.palette.push_back(r1);
        s.palette.push_back(bestR2);
        s.paletteNames.push_back(fmt::format("{}_a", bases[p]));
        s.paletteNames.push_back(fmt::format("{}_b_metamer_under_F7", bases[p]));
    }
    layOutPairs(s, 3);
    return s;
}

Expected<SurfaceScene> painting(const std::filesystem::path& dataDir)
{
    auto cc = colour::loadSpectralCsv(dataDir / "spectra" /
                                      "colorchecker24_babelcolor_avg_10nm_380_730.csv");
    auto tcs = colour::loadSpectralCsv(dataDir / "spectra" / "cie_tcs01_14_5nm_360_830.csv");
    if (!cc || !tcs) {
        return tl::unexpected(!cc ? cc.error() : tcs.error());
    }
    const double pitch = 0.000625; // 0.625 mm texels
    SurfaceScene s = blank("painting", 384, 288, pitch);
    // Ground and pigments: measured reflectances standing in for paints.
    const std::pair<const char*, bool> names[] = {
            {"white_9.5", true}, {"orange", true},        {"yellow", true}, {"red", true},
            {"blue", true},      {"purplish_blue", true}, {"green", true},  {"foliage", true},
            {"dark_skin", true}, {"TCS09", false},        {"TCS10", false}, {"TCS11", false},
            {"TCS12", false}};
    // The TCS pigments are averaged over each band, as when the painting first shipped: they stand
    // in for paints, so the smoothing is part of the pigment, and the shipped scene (and its plan,
    // keyed by the scene's digest) stays what this makes.
    for (const auto& [name, fromChecker] : names) {
        auto sp = fromChecker ? cc->spectrum(name, colour::GridSampling::AtBandCentre)
                              : tcs->spectrum(name, colour::GridSampling::BandAverage);
        if (!sp) {
            return tl::unexpected(sp.error());
        }
        s.palette.push_back(*sp);
        s.paletteNames.emplace_back(name);
    }
    const int pigments = static_cast<int>(s.palette.size());
    Rng rng(20261123u);
    // Canvas weave: over-under threads with a 2.5 mm period, 60 um deep, on a white ground.
    for (int y = 0; y < s.height; ++y) {
        for (int x = 0; x < s.width; ++x) {
            const double xm = x * pitch, ym = y * pitch;
            const double p = 0.0025;
            const double warp = std::sin(std::numbers::pi * xm / (0.5 * p));
            const double weft = std::sin(std::numbers::pi * ym / (0.5 * p));
            const std::size_t k = static_cast<std::size_t>(y) * s.width + x;
            s.relief.m[k] = 6e-5 * 0.5 *
                            (std::abs(warp) * (weft > 0 ? 1.0 : 0.6) +
                             std::abs(weft) * (warp > 0 ? 0.6 : 1.0));
            s.pigmentA[k] = 0;
            s.pigmentB[k] = 8; // a thin warm underpainting glazed over the ground
            s.mix[k] = static_cast<float>(0.15 + 0.1 * std::sin(xm * 40.0) * std::cos(ym * 30.0));
        }
    }
    // Impasto: elongated strokes with bristle ridges, each a mix of two pigments along its length.
    std::vector<double> paint(s.relief.m.size(), 0.0);
    for (int stroke = 0; stroke < 70; ++stroke) {
        const double cx = rng.uniform(0.0, s.widthM), cy = rng.uniform(0.0, s.heightM);
        const double ang = rng.uniform(0.0, std::numbers::pi);
        const double len = rng.uniform(0.015, 0.05), wid = rng.uniform(0.003, 0.008);
        const double thick = rng.uniform(0.0002, 0.0006);
        const int a = 1 + static_cast<int>(rng.uniform(0.0, pigments - 1.0 - 1e-9));
        const int b = 1 + static_cast<int>(rng.uniform(0.0, pigments - 1.0 - 1e-9));
        const double dx = std::cos(ang), dy = std::sin(ang);
        const int x0 = std::max(0, static_cast<int>((cx - len) / pitch)),
                  x1 = std::min(s.width - 1, static_cast<int>((cx + len) / pitch));
        const int y0 = std::max(0, static_cast<int>((cy - len) / pitch)),
                  y1 = std::min(s.height - 1, static_cast<int>((cy + len) / pitch));
        for (int y = y0; y <= y1; ++y) {
            for (int x = x0; x <= x1; ++x) {
                const double rx = x * pitch - cx, ry = y * pitch - cy;
                const double along = rx * dx + ry * dy, across = -rx * dy + ry * dx;
                const double ta = along / (0.5 * len), tc = across / (0.5 * wid);
                if (std::abs(ta) >= 1.0 || std::abs(tc) >= 1.0) {
                    continue;
                }
                const double body = (1.0 - tc * tc) * std::sqrt(1.0 - ta * ta);
                const double bristles =
                        0.8 + 0.2 * std::sin(2.0 * std::numbers::pi * across / 0.0008);
                const double h = thick * body * bristles;
                const std::size_t k = static_cast<std::size_t>(y) * s.width + x;
                if (body > 0.15) {
                    s.pigmentA[k] = a;
                    s.pigmentB[k] = b;
                    s.mix[k] = static_cast<float>(0.5 + 0.5 * ta);
                    s.shade[k] = 1.0f;
                    paint[k] = std::max(paint[k] * 0.6, 0.0) +
                               h; // wet-on-wet: the new stroke pushes the old
                }
            }
        }
    }
    for (std::size_t k = 0; k < paint.size(); ++k) {
        s.relief.m[k] += paint[k];
    }
    s.alpha = 0.08; // gloss varnish
    s.rhoS = colour::Spectrum::constant(0.04);
    return s;
}

// The paper's Fig. 5: a curved glossy surface that mirrors the booth lamp. A horizontal cylinder
// segment (radius 0.15 m, its axis along the panel's width, so that the lamp's tubes run along
// it) painted a deep blue under a clear gloss coat; the curvature comes from the height field, so
// the normal map and the horizons follow it.
Expected<SurfaceScene> glossyCylinder(const std::filesystem::path& dataDir)
{
    auto cc = colour::loadSpectralCsv(dataDir / "spectra" /
                                      "colorchecker24_babelcolor_avg_10nm_380_730.csv");
    if (!cc) {
        return tl::unexpected(cc.error());
    }
    SurfaceScene s = blank("glossy-cylinder", 240, 160, 0.001);
    s.palette.push_back(*cc->spectrum("blue", colour::GridSampling::AtBandCentre));
    s.paletteNames.emplace_back("blue");
    const double radius = 0.15, half = 0.5 * s.heightM;
    const double rim = std::sqrt(radius * radius - half * half);
    for (int y = 0; y < s.height; ++y) {
        const double v = (y + 0.5) * 0.001 - half;
        const double h = std::sqrt(radius * radius - v * v) - rim;
        for (int x = 0; x < s.width; ++x) {
            s.relief.m[static_cast<std::size_t>(y) * s.width + x] = h;
        }
    }
    s.alpha = 0.05; // a high-gloss coat
    s.rhoS = colour::Spectrum::constant(0.05);
    return s;
}

} // namespace

Expected<SurfaceScene> generateScene(const std::string& kind, const std::filesystem::path& dataDir)
{
    if (kind == "colorchecker") {
        return colorChecker(dataDir);
    }
    if (kind == "metamer") {
        return metamerTarget(dataDir);
    }
    if (kind == "metamer-d65") {
        return metamerD65Target(dataDir);
    }
    if (kind == "painting") {
        return painting(dataDir);
    }
    if (kind == "glossy-cylinder") {
        return glossyCylinder(dataDir);
    }
    return makeError(ErrorCode::InvalidArgument,
                     fmt::format("unknown scene kind '{}'; use colorchecker, metamer, metamer-d65, "
                                 "painting or glossy-cylinder",
                                 kind));
}

} // namespace replica::pipeline::surface
