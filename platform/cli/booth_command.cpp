// 'replica booth generate|build' and 'replica scene generate': the shipped booth and scenes, and
// the offline capture path (bracketed PNG exposures -> HDR -> calibrated -> warped onto the
// ceiling).
#include <cstdio>
#include <fstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <png.h>

#include <pipeline/base/data_dir.h>
#include <pipeline/base/input_file.h>
#include <pipeline/base/json_schema.h>
#include <pipeline/colour/spectral_table.h>
#include <pipeline/offline/booth/booth_generator.h>
#include <pipeline/offline/booth/hdr_capture.h>
#include <pipeline/offline/surface/scene_generator.h>
#include <platform/cli/commands.h>

namespace replica::platform {
namespace {

int fail(const char* cmd, int code, const std::string& msg)
{
    std::fprintf(stderr, "replica %s: %s\n", cmd, msg.c_str());
    return code;
}

// Reads an 8-bit PNG as grey (the luminance-like channel mix libpng applies for colour input).
Expected<pipeline::booth::Exposure> readPngGrey(const std::filesystem::path& path)
{
    if (auto ok = checkInputFile(path, kMaxImageBytes, "PNG"); !ok) {
        return tl::unexpected(ok.error());
    }
    png_image img{};
    img.version = PNG_IMAGE_VERSION;
    if (png_image_begin_read_from_file(&img, path.c_str()) == 0) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: cannot read PNG ({})", path.string(), img.message));
    }
    // The header's size is checked before the pixels are allocated.
    if (img.width > static_cast<png_uint_32>(kMaxImageSide) ||
        img.height > static_cast<png_uint_32>(kMaxImageSide)) {
        const auto w = img.width;
        const auto h = img.height;
        png_image_free(&img);
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: {}x{} pixels; at most {} per side are read",
                                     path.string(), w, h, kMaxImageSide));
    }
    img.format = PNG_FORMAT_GRAY;
    pipeline::booth::Exposure e;
    e.width = static_cast<int>(img.width);
    e.height = static_cast<int>(img.height);
    e.z.resize(PNG_IMAGE_SIZE(img));
    if (png_image_finish_read(&img, nullptr, e.z.data(), 0, nullptr) == 0) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: cannot decode PNG ({})", path.string(), img.message));
    }
    return e;
}

int runGenerate(const std::string& out)
{
    auto booth = pipeline::booth::generateShippedBooth(dataDir());
    if (!booth) {
        return fail("booth generate", kExitFailure, booth.error().message);
    }
    if (auto ok = pipeline::booth::saveBooth(out, *booth); !ok) {
        return fail("booth generate", kExitFailure, ok.error().message);
    }
    std::printf("%s: booth with lights %s\n", out.c_str(), booth->names().c_str());
    return kExitOk;
}

// capture.json, as below: distances in metres, image positions in pixels, a light map of at most
// 4096 texels per side, exposures of 1 us to an hour, spectra that are not negative.
const JsonSchema& captureSchema()
{
    using namespace json_schema;
    static const JsonSchema v3 = array(number(-100.0, 100.0), 3, 3);
    static const JsonSchema px = number(-1e6, 1e6);
    static const JsonSchema s = object({
            {"lights",
             array(object({
                           {"name", string(128)},
                           {"spd_column", string(128).optional()},
                           {"spd", array(number(0.0, 1e9), pipeline::colour::kBands,
                                         pipeline::colour::kBands)
                                           .optional()},
                           {"centre", v3},
                           {"edge_u", v3},
                           {"edge_v", v3},
                           {"texels", array(integer(1, 4096), 2, 2)},
                           {"corners", array(array(px, 2, 2), 4, 4)},
                           {"exposures", array(object({{"file", string(4096)},
                                                       {"seconds", number(1e-6, 3600.0)}}),
                                               1, 64)},
                           {"calibration",
                            object({{"cdm2_per_unit", number(1e-12, 1e12).optional()},
                                    {"spot", object({{"x", px},
                                                     {"y", px},
                                                     {"radius", number(0.0, 1e6)},
                                                     {"cdm2", number(1e-9, 1e9)}})
                                                     .optional()}})},
                   }),
                   1, 64)},
    });
    return s;
}

// capture.json: {"lights": [{"name", "spd_column" (CIE table column) | "spd" [36], "centre",
// "edge_u", "edge_v", "texels": [w, h], "corners": [[x, y] x 4] (image pixels of ceiling uv
// (0,0),(1,0),(1,1),(0,1)), "exposures": [{"file", "seconds"}], "calibration": {"cdm2_per_unit": k}
// | {"spot": {"x", "y", "radius", "cdm2"}}}]}. Paths are relative to capture.json.
// docs/booth-capture.md documents it, with a worked example.
// The calibration's scale from the HDR image's units to cd/m^2: given, or from a spot of known
// luminance.
Expected<double> calibrationScale(const nlohmann::json& cal,
                                  const pipeline::booth::LuminanceImage& hdr,
                                  const std::string& where)
{
    double scale = 0.0;
    if (cal.contains("cdm2_per_unit")) {
        scale = cal["cdm2_per_unit"].get<double>();
    } else {
        const auto& spot = cal.at("spot");
        const double sx = spot.at("x").get<double>(), sy = spot.at("y").get<double>();
        const double r = spot.at("radius").get<double>();
        double sum = 0.0;
        int count = 0;
        for (int y = 0; y < hdr.height; ++y) {
            for (int x = 0; x < hdr.width; ++x) {
                if ((x + 0.5 - sx) * (x + 0.5 - sx) + (y + 0.5 - sy) * (y + 0.5 - sy) <= r * r) {
                    sum += hdr.at(x, y);
                    ++count;
                }
            }
        }
        if (count == 0 || !(sum > 0.0)) {
            return makeError(ErrorCode::InvalidArgument,
                             where + ": calibration spot covers no lit pixel");
        }
        scale = spot.at("cdm2").get<double>() / (sum / count);
    }
    if (!(scale > 0.0) || !std::isfinite(scale)) {
        return makeError(ErrorCode::InvalidArgument, where + ": calibration scale must be > 0");
    }
    return scale;
}

// One light of the capture description: its rectangle, spectrum, and luminance from its
// exposure series (HDR merge, calibration, warp to the ceiling's texels).
Expected<pipeline::booth::BoothLight> buildLight(const nlohmann::json& lj,
                                                 const std::string& where,
                                                 const pipeline::colour::SpectralTable& table,
                                                 const std::filesystem::path& base)
{
    using namespace pipeline;
    booth::BoothLight l;
    l.name = lj.at("name").get<std::string>();
    // The name becomes OUT/NAME.exr: never a path out of --out.
    if (auto ok = checkPlainName(l.name, where + ".name"); !ok) {
        return tl::unexpected(ok.error());
    }
    const auto v3 = [&](const char* k) {
        const auto& a = lj.at(k);
        return glm::dvec3(a.at(0).get<double>(), a.at(1).get<double>(), a.at(2).get<double>());
    };
    l.centre = v3("centre");
    l.edgeU = v3("edge_u");
    l.edgeV = v3("edge_v");
    if (lj.contains("spd_column")) {
        auto s = table.spectrum(lj["spd_column"].get<std::string>(),
                                colour::GridSampling::BandAverage);
        if (!s) {
            return makeError(ErrorCode::InvalidArgument, where + ": " + s.error().message);
        }
        l.spd = *s;
    } else {
        const auto& s = lj.at("spd");
        if (s.size() != colour::kBands) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("{}: spd must hold {} values", where, colour::kBands));
        }
        for (std::size_t b = 0; b < colour::kBands; ++b) {
            l.spd[b] = std::max(s[b].get<double>(), 0.0);
        }
    }
    std::vector<booth::Exposure> series;
    for (const auto& ej : lj.at("exposures")) {
        auto e = readPngGrey(base / ej.at("file").get<std::string>());
        if (!e) {
            return tl::unexpected(e.error());
        }
        e->seconds = ej.at("seconds").get<double>();
        series.push_back(std::move(*e));
    }
    auto curve = booth::recoverResponse(series);
    if (!curve) {
        return makeError(ErrorCode::InvalidArgument, where + ": " + curve.error().message);
    }
    auto hdr = booth::mergeHdr(series, *curve);
    if (!hdr) {
        return makeError(ErrorCode::InvalidArgument, where + ": " + hdr.error().message);
    }
    auto scale = calibrationScale(lj.at("calibration"), *hdr, where);
    if (!scale) {
        return tl::unexpected(scale.error());
    }
    for (double& v : hdr->cdM2) {
        v *= *scale;
    }
    std::array<glm::dvec2, 4> corners;
    for (std::size_t k = 0; k < 4; ++k) {
        corners[k] = {lj.at("corners").at(k).at(0).get<double>(),
                      lj.at("corners").at(k).at(1).get<double>()};
    }
    auto hm = booth::homographyFromCorners(corners);
    if (!hm) {
        return makeError(ErrorCode::InvalidArgument, where + ": " + hm.error().message);
    }
    auto warped = booth::warpToCeiling(*hdr, *hm, lj.at("texels").at(0).get<int>(),
                                       lj.at("texels").at(1).get<int>());
    if (!warped) {
        return makeError(ErrorCode::InvalidArgument, where + ": " + warped.error().message);
    }
    l.luminance = std::move(*warped);
    return l;
}

int runBuild(const std::string& input, const std::string& out)
{
    using namespace pipeline;
    const char* cmd = "booth build";
    auto text = readInputFile(input, kMaxJsonBytes, "capture description");
    if (!text) {
        return fail(cmd, kExitFailure, text.error().message);
    }
    std::vector<std::string> warnings;
    auto parsed = parseJsonChecked(*text, captureSchema(), input, &warnings);
    if (!parsed) {
        return fail(cmd, kExitFailure, parsed.error().message);
    }
    const nlohmann::json& j = *parsed;
    for (const auto& w : warnings) {
        std::fprintf(stderr, "replica %s: warning: %s\n", cmd, w.c_str());
    }
    const std::filesystem::path base = std::filesystem::path(input).parent_path();
    auto table = colour::loadSpectralCsv(dataDir() / "spectra" /
                                         "cie_illuminants_10nm_380_730_triangular.csv");
    if (!table) {
        return fail(cmd, kExitFailure, table.error().message);
    }
    booth::Booth model;
    try {
        for (std::size_t li = 0; li < j.at("lights").size(); ++li) {
            const auto& lj = j["lights"][li];
            const std::string where = fmt::format("{}: lights[{}]", input, li);
            auto l = buildLight(lj, where, *table, base);
            if (!l) {
                return fail(cmd, kExitFailure, l.error().message);
            }
            model.lights.push_back(std::move(*l));
        }
    } catch (const nlohmann::json::exception& e) {
        return fail(cmd, kExitFailure,
                    fmt::format("{}: missing or malformed field ({})", input, e.what()));
    }
    if (auto ok = booth::saveBooth(out, model); !ok) {
        return fail(cmd, kExitFailure, ok.error().message);
    }
    std::printf("%s: booth with lights %s\n", out.c_str(), model.names().c_str());
    return kExitOk;
}

int runSceneGenerate(const std::string& kind, const std::string& out)
{
    auto s = pipeline::surface::generateScene(kind, dataDir());
    if (!s) {
        return fail("scene generate", kExitUsage, s.error().message);
    }
    if (auto ok = pipeline::surface::saveScene(out, *s); !ok) {
        return fail("scene generate", kExitFailure, ok.error().message);
    }
    std::printf("%s: scene '%s', %dx%d texels, %.3f x %.3f m\n", out.c_str(), s->name.c_str(),
                s->width, s->height, s->widthM, s->heightM);
    return kExitOk;
}

} // namespace

void registerBoothCommand(CLI::App& app, int& exitCode)
{
    CLI::App* booth = app.add_subcommand(
            "booth", "build or generate booth light models (luminance EXR + SPD)");
    booth->require_subcommand(1);
    auto genOut = std::make_shared<std::string>();
    CLI::App* gen = booth->add_subcommand(
            "generate",
            "write the shipped three-light booth (tungsten CIE A, D50 sim CIE F8, D65 sim CIE F7)");
    gen->add_option("--out", *genOut, "output folder")->required();
    gen->callback([genOut, &exitCode] { exitCode = runGenerate(*genOut); });

    auto input = std::make_shared<std::string>();
    auto buildOut = std::make_shared<std::string>();
    CLI::App* build =
            booth->add_subcommand("build", "merge bracketed PNG exposures into a calibrated "
                                           "luminance image per light and warp it onto the "
                                           "ceiling (capture.json: docs/booth-capture.md)");
    build->add_option("--capture", *input,
                      "capture.json describing exposures, corners, geometry and calibration "
                      "(docs/booth-capture.md, with a worked example)")
            ->required();
    build->add_option("--out", *buildOut, "output booth folder")->required();
    build->callback([input, buildOut, &exitCode] { exitCode = runBuild(*input, *buildOut); });
    registerBoothWallsCommand(*booth, exitCode);
}

void registerSceneCommand(CLI::App& app, int& exitCode)
{
    CLI::App* scene = app.add_subcommand("scene", "generate the shipped surface scenes");
    scene->require_subcommand(1);
    auto kind = std::make_shared<std::string>();
    auto out = std::make_shared<std::string>();
    CLI::App* gen = scene->add_subcommand(
            "generate",
            "write a scene folder (colorchecker, metamer, metamer-d65, painting, glossy-cylinder)");
    gen->add_option("--kind", *kind,
                    "colorchecker, metamer (matched under tungsten), metamer-d65, painting or "
                    "glossy-cylinder")
            ->required();
    gen->add_option("--out", *out, "output folder")->required();
    gen->callback([kind, out, &exitCode] { exitCode = runSceneGenerate(*kind, *out); });
}

} // namespace replica::platform
