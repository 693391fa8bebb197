// Scene folder reading and writing with checks that name the file and the field or texel.
#include <cmath>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <pipeline/base/json_file.h>
#include <pipeline/base/json_schema.h>
#include <pipeline/base/output_file.h>
#include <pipeline/image/exr.h>
#include <pipeline/surface/surface_scene.h>

namespace replica::pipeline::surface {
namespace {

constexpr const char* kFormat = "replica-scene/1";

// scene.json (docs/scenes.md): sizes in metres, reflectances per 10 nm band.
const JsonSchema& sceneSchema()
{
    using namespace json_schema;
    static const JsonSchema s = object({
            {"format", string()},
            {"name", string(256).optional()},
            {"size_m", array(number(1e-6, 1000.0), 2, 2)},
            {"palette", array(object({{"name", string(256).optional()},
                                      {"reflectance",
                                       array(number(0.0, 1.5), colour::kBands, colour::kBands)}}),
                              1, 256)},
            {"ward",
             object({{"alpha", number(0.0, 5.0).optional()},
                     {"rho_s", array(number(0.0, 1.0), colour::kBands, colour::kBands).optional()},
                     {"model", string(64).optional()}})
                     .optional()},
    });
    return s;
}

Expected<colour::Spectrum>
spectrumField(const nlohmann::json& j, const std::string& where, double maxValue)
{
    if (!j.is_array() || j.size() != colour::kBands) {
        return makeError(
                ErrorCode::Corrupt,
                fmt::format("{}: must hold {} values (380-730 nm, 10 nm)", where, colour::kBands));
    }
    colour::Spectrum s;
    for (std::size_t b = 0; b < colour::kBands; ++b) {
        if (!j[b].is_number() || !std::isfinite(j[b].get<double>()) || j[b].get<double>() < 0.0 ||
            j[b].get<double>() > maxValue) {
            return makeError(ErrorCode::Corrupt, fmt::format("{}[{}]: must be a number in [0, {}]",
                                                             where, b, maxValue));
        }
        s[b] = j[b].get<double>();
    }
    return s;
}

} // namespace

colour::Spectrum SurfaceScene::reflectance(int x, int y) const
{
    const std::size_t k = static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
                          static_cast<std::size_t>(x);
    const double t = mix[k];
    return (palette[static_cast<std::size_t>(pigmentA[k])] * (1.0 - t) +
            palette[static_cast<std::size_t>(pigmentB[k])] * t) *
           static_cast<double>(shade[k]);
}

colour::ChannelCoeffs
SurfaceScene::channels(const std::vector<colour::ChannelCoeffs>& pc, int x, int y) const
{
    const std::size_t k = static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
                          static_cast<std::size_t>(x);
    const double t = mix[k];
    colour::ChannelCoeffs c{};
    for (std::size_t j = 0; j < colour::kChannels; ++j) {
        c[j] = ((1.0 - t) * pc[static_cast<std::size_t>(pigmentA[k])][j] +
                t * pc[static_cast<std::size_t>(pigmentB[k])][j]) *
               shade[k];
    }
    return c;
}

namespace {

// The Ward BRDF's parameters (the "ward" object; defaults where absent).
Expected<void> readWard(const nlohmann::json& w, const std::string& f, SurfaceScene& s)
{
    s.alpha = w.value("alpha", 0.1);
    if (!(s.alpha >= 0.0 && s.alpha <= 5.0)) {
        return makeError(ErrorCode::Corrupt, fmt::format("{}: ward.alpha must be in [0, 5]", f));
    }
    if (w.contains("rho_s")) {
        auto r = spectrumField(w["rho_s"], f + ": ward.rho_s", 1.0);
        if (!r) {
            return tl::unexpected(r.error());
        }
        s.rhoS = *r;
    }
    const std::string model = w.value("model", "ward-duer-guarded");
    bool known = false;
    for (auto m : {brdf::WardModel::Ward1992, brdf::WardModel::WardDur,
                   brdf::WardModel::WardDurGuarded, brdf::WardModel::Gmd}) {
        if (model == brdf::wardModelName(m)) {
            s.model = m;
            known = true;
        }
    }
    if (!known) {
        return makeError(ErrorCode::Corrupt, fmt::format("{}: ward.model '{}' unknown (ward-1992, "
                                                         "ward-duer, ward-duer-guarded, ward-gmd)",
                                                         f, model));
    }
    return {};
}

// The texels: material.exr (pigments A and B, their mix, the shade) and height.exr, the same size
// and square over the scene's size.
Expected<void> readTexels(const std::filesystem::path& dir, const std::string& f, SurfaceScene& s)
{
    auto mat = image::readExr(dir / "material.exr", {"A", "B", "mix", "shade"});
    if (!mat) {
        return tl::unexpected(mat.error());
    }
    auto hf = image::readExr(dir / "height.exr", {"H"});
    if (!hf) {
        return tl::unexpected(hf.error());
    }
    if (hf->width != mat->width || hf->height != mat->height) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: height.exr is {}x{} but material.exr is {}x{}",
                                     dir.string(), hf->width, hf->height, mat->width, mat->height));
    }
    s.width = mat->width;
    s.height = mat->height;
    const std::size_t n = static_cast<std::size_t>(s.width) * static_cast<std::size_t>(s.height);
    const int paletteSize = static_cast<int>(s.palette.size());
    for (std::size_t k = 0; k < n; ++k) {
        const float a = mat->planes[0][k];
        const float b = mat->planes[1][k];
        const float t = mat->planes[2][k];
        const float sh = mat->planes[3][k];
        const auto bad = [&](const char* what) {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("{}: texel ({}, {}): {}", (dir / "material.exr").string(),
                                         k % static_cast<std::size_t>(s.width),
                                         k / static_cast<std::size_t>(s.width), what));
        };
        if (a != std::floor(a) || b != std::floor(b) || a < 0.0f || b < 0.0f ||
            a >= static_cast<float>(paletteSize) || b >= static_cast<float>(paletteSize)) {
            return bad("pigment index is not an integer palette entry");
        }
        if (!(t >= 0.0f && t <= 1.0f) || !(sh >= 0.0f && sh <= 1.5f)) {
            return bad("mix must be in [0, 1] and shade in [0, 1.5]");
        }
        s.pigmentA.push_back(static_cast<int>(a));
        s.pigmentB.push_back(static_cast<int>(b));
        s.mix.push_back(t);
        s.shade.push_back(sh);
    }
    s.relief.width = s.width;
    s.relief.height = s.height;
    s.relief.pitchM = s.widthM / s.width;
    s.relief.m.assign(hf->planes[0].begin(), hf->planes[0].end());
    if (std::abs(s.heightM / s.height - s.relief.pitchM) > 1e-6 * s.relief.pitchM) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: texels must be square: size_m {}x{} over {}x{} texels", f,
                                     s.widthM, s.heightM, s.width, s.height));
    }
    return {};
}

} // namespace

Expected<SurfaceScene> loadScene(const std::filesystem::path& dir)
{
    const auto file = dir / "scene.json";
    auto parsed = readJsonManifest(file, sceneSchema(), "scene manifest",
                                   "--scene must name a folder with scene.json", kFormat);
    if (!parsed) {
        return tl::unexpected(parsed.error());
    }
    nlohmann::json& j = *parsed;
    const std::string f = file.string();
    SurfaceScene s;
    s.name = j.value("name", dir.filename().string());
    if (!j.contains("size_m") || !j["size_m"].is_array() || j["size_m"].size() != 2 ||
        !j["size_m"][0].is_number() || !j["size_m"][1].is_number() ||
        !(j["size_m"][0].get<double>() > 0.0) || !(j["size_m"][1].get<double>() > 0.0)) {
        return makeError(
                ErrorCode::Corrupt,
                fmt::format("{}: 'size_m' must be [width, height] in metres, both > 0", f));
    }
    s.widthM = j["size_m"][0].get<double>();
    s.heightM = j["size_m"][1].get<double>();
    if (!j.contains("palette") || !j["palette"].is_array() || j["palette"].empty()) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: 'palette' must be a non-empty array", f));
    }
    for (std::size_t k = 0; k < j["palette"].size(); ++k) {
        const auto& p = j["palette"][k];
        auto r = spectrumField(p.value("reflectance", nlohmann::json()),
                               fmt::format("{}: palette[{}].reflectance", f, k), 1.5);
        if (!r) {
            return tl::unexpected(r.error());
        }
        s.paletteNames.push_back(p.value("name", fmt::format("p{}", k)));
        s.palette.push_back(*r);
    }
    if (auto ok = readWard(j.value("ward", nlohmann::json::object()), f, s); !ok) {
        return tl::unexpected(ok.error());
    }
    if (auto ok = readTexels(dir, f, s); !ok) {
        return tl::unexpected(ok.error());
    }
    return s;
}

Expected<void> saveScene(const std::filesystem::path& dir, const SurfaceScene& s)
{
    // An in-memory scene with a pigment index outside its palette must not reach the disk (nor the
    // channel projection below, which indexes the palette with it).
    const std::size_t texels =
            static_cast<std::size_t>(s.width) * static_cast<std::size_t>(s.height);
    if (s.pigmentA.size() != texels || s.pigmentB.size() != texels || s.mix.size() != texels ||
        s.shade.size() != texels) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("scene '{}': material planes do not hold {}x{} texels", s.name,
                                     s.width, s.height));
    }
    for (std::size_t k = 0; k < texels; ++k) {
        if (s.pigmentA[k] < 0 || s.pigmentB[k] < 0 ||
            static_cast<std::size_t>(s.pigmentA[k]) >= s.palette.size() ||
            static_cast<std::size_t>(s.pigmentB[k]) >= s.palette.size()) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("scene '{}': texel ({}, {}) names pigment {}/{}, but the "
                                         "palette has {} entries",
                                         s.name, k % static_cast<std::size_t>(s.width),
                                         k / static_cast<std::size_t>(s.width), s.pigmentA[k],
                                         s.pigmentB[k], s.palette.size()));
        }
    }
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) {
        return makeError(ErrorCode::Io,
                         fmt::format("{}: cannot create folder ({})", dir.string(), ec.message()));
    }
    nlohmann::json j;
    j["format"] = kFormat;
    j["name"] = s.name;
    j["size_m"] = {s.widthM, s.heightM};
    j["palette"] = nlohmann::json::array();
    for (std::size_t k = 0; k < s.palette.size(); ++k) {
        j["palette"].push_back({{"name", s.paletteNames[k]},
                                {"reflectance", std::vector<double>(s.palette[k].v.begin(),
                                                                    s.palette[k].v.end())}});
    }
    j["ward"] = {{"alpha", s.alpha},
                 {"rho_s", std::vector<double>(s.rhoS.v.begin(), s.rhoS.v.end())},
                 {"model", brdf::wardModelName(s.model)}};
    if (auto ok = writeOutputFile(dir / "scene.json", j.dump(1) + "\n", "scene manifest"); !ok) {
        return ok;
    }
    const std::size_t n = static_cast<std::size_t>(s.width) * static_cast<std::size_t>(s.height);
    image::ChannelImage mat;
    mat.width = s.width;
    mat.height = s.height;
    mat.names = {"A", "B", "mix", "shade"};
    mat.planes.assign(4, std::vector<float>(n));
    for (std::size_t k = 0; k < n; ++k) {
        mat.planes[0][k] = static_cast<float>(s.pigmentA[k]);
        mat.planes[1][k] = static_cast<float>(s.pigmentB[k]);
        mat.planes[2][k] = s.mix[k];
        mat.planes[3][k] = s.shade[k];
    }
    if (auto ok = image::writeExr(dir / "material.exr", mat); !ok) {
        return ok;
    }
    image::ChannelImage h;
    h.width = s.width;
    h.height = s.height;
    h.names = {"H"};
    h.planes.emplace_back(s.relief.m.begin(), s.relief.m.end());
    if (auto ok = image::writeExr(dir / "height.exr", h, {{"units", "metres"}}); !ok) {
        return ok;
    }
    const colour::ChannelBasis basis = colour::boxBasis();
    std::vector<colour::ChannelCoeffs> pc;
    for (const auto& p : s.palette) {
        pc.push_back(colour::projectReflectance(basis, p));
    }
    image::ChannelImage c;
    c.width = s.width;
    c.height = s.height;
    for (std::size_t k = 0; k < colour::kChannels; ++k) {
        c.names.push_back(fmt::format("c{}", k));
    }
    c.planes.assign(colour::kChannels, std::vector<float>(n));
    for (int y = 0; y < s.height; ++y) {
        for (int x = 0; x < s.width; ++x) {
            const auto cc = s.channels(pc, x, y);
            for (std::size_t k = 0; k < colour::kChannels; ++k) {
                c.planes[k][static_cast<std::size_t>(y) * s.width + x] = static_cast<float>(cc[k]);
            }
        }
    }
    return image::writeExr(dir / "channels.exr", c, {{"basis", basis.name}});
}

} // namespace replica::pipeline::surface
