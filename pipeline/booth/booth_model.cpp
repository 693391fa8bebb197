// booth.json reading and writing; nlohmann exceptions are caught here and become Error values.

#include <algorithm>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <pipeline/base/input_file.h>
#include <pipeline/base/json_file.h>
#include <pipeline/base/json_schema.h>
#include <pipeline/base/output_file.h>
#include <pipeline/booth/booth_model.h>
#include <pipeline/image/exr.h>

namespace replica::pipeline::booth {
namespace {

constexpr const char* kFormat = "replica-booth/1";

// booth.json: positions in metres inside a room-sized box, SPDs per 10 nm band (relative power;
// negative noise is clipped below, but not a negative lamp).
const JsonSchema& boothSchema()
{
    using namespace json_schema;
    static const JsonSchema s = object({
            {"format", string()},
            {"lights",
             array(object({{"name", string(128)},
                           {"luminance", string(128)},
                           {"centre", array(number(-100.0, 100.0), 3, 3)},
                           {"edge_u", array(number(-100.0, 100.0), 3, 3)},
                           {"edge_v", array(number(-100.0, 100.0), 3, 3)},
                           {"spd", array(number(-1e6, 1e9), colour::kBands, colour::kBands)}}),
                   1, 64)},
            {"walls", object({{"reflectance",
                               array(number(0.0, 1.0), colour::kBands, colour::kBands).optional()}})
                              .optional()},
    });
    return s;
}

Expected<Vec3> vec3Field(const nlohmann::json& j, const char* key, const std::string& where)
{
    if (!j.contains(key) || !j[key].is_array() || j[key].size() != 3) {
        return makeError(
                ErrorCode::Corrupt,
                fmt::format("{}: '{}' must be an array of 3 numbers (metres)", where, key));
    }
    Vec3 v;
    for (int k = 0; k < 3; ++k) {
        if (!j[key][static_cast<std::size_t>(k)].is_number()) {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("{}: '{}'[{}] is not a number", where, key, k));
        }
        v[k] = j[key][static_cast<std::size_t>(k)].get<double>();
        if (!std::isfinite(v[k])) {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("{}: '{}'[{}] is not finite", where, key, k));
        }
    }
    return v;
}

} // namespace

const BoothLight* Booth::find(const std::string& name) const
{
    for (const auto& l : lights) {
        if (l.name == name) {
            return &l;
        }
    }
    // Short forms: "d65" finds "d65-fluorescent" when exactly one light starts with "d65-".
    const BoothLight* match = nullptr;
    for (const auto& l : lights) {
        if (l.name.rfind(name + "-", 0) == 0) {
            if (match != nullptr) {
                return nullptr;
            }
            match = &l;
        }
    }
    return match;
}

std::string Booth::names() const
{
    std::string s;
    for (const auto& l : lights) {
        s += (s.empty() ? "" : ", ") + l.name;
    }
    return s;
}

Expected<Booth> loadBooth(const std::filesystem::path& dir)
{
    const auto file = dir / "booth.json";
    auto parsed = readJsonManifest(file, boothSchema(), "booth model",
                                   "run 'replica booth build' or point --booth at a folder with "
                                   "booth.json",
                                   kFormat);
    if (!parsed) {
        return tl::unexpected(parsed.error());
    }
    nlohmann::json& j = *parsed;
    if (!j.contains("lights") || !j["lights"].is_array() || j["lights"].empty()) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: 'lights' must be a non-empty array", file.string()));
    }
    Booth booth;
    for (std::size_t k = 0; k < j["lights"].size(); ++k) {
        const auto& lj = j["lights"][k];
        const std::string where = fmt::format("{}: lights[{}]", file.string(), k);
        BoothLight l;
        if (!lj.contains("name") || !lj["name"].is_string() || !lj.contains("luminance") ||
            !lj["luminance"].is_string()) {
            return makeError(ErrorCode::Corrupt,
                             where + ": needs string fields 'name' and 'luminance'");
        }
        l.name = lj["name"].get<std::string>();
        // A lamp is chosen by name (the site file's default lamp, --light, the plan's keys, the
        // recording's lamp labels): an empty name or a second lamp of the same name could never be
        // chosen, or would silently be the first.
        if (l.name.empty()) {
            return makeError(ErrorCode::Corrupt,
                             where + ".name: is empty; name the lamp (tungsten, d50, ...)");
        }
        if (std::any_of(booth.lights.begin(), booth.lights.end(),
                        [&](const BoothLight& o) { return o.name == l.name; })) {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("{}.name: '{}' names another lamp of this booth too; "
                                         "each lamp needs a name of its own",
                                         where, l.name));
        }
        // The luminance map is a file next to booth.json, named, never a path elsewhere.
        if (auto ok = checkPlainName(lj["luminance"].get<std::string>(), where + ".luminance");
            !ok) {
            return tl::unexpected(ok.error());
        }
        auto c = vec3Field(lj, "centre", where);
        auto u = vec3Field(lj, "edge_u", where);
        auto v = vec3Field(lj, "edge_v", where);
        if (!c || !u || !v) {
            return tl::unexpected(!c ? c.error() : (!u ? u.error() : v.error()));
        }
        l.centre = *c;
        l.edgeU = *u;
        l.edgeV = *v;
        if (!(l.areaM2() > 0.0)) {
            return makeError(ErrorCode::Corrupt, where + ": edge_u and edge_v span no area");
        }
        if (!lj.contains("spd") || !lj["spd"].is_array() || lj["spd"].size() != colour::kBands) {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("{}: 'spd' must hold {} values (380-730 nm, 10 nm)", where,
                                         colour::kBands));
        }
        for (std::size_t b = 0; b < colour::kBands; ++b) {
            if (!lj["spd"][b].is_number() || !std::isfinite(lj["spd"][b].get<double>())) {
                return makeError(ErrorCode::Corrupt,
                                 fmt::format("{}: spd[{}] is not a finite number", where, b));
            }
            // Negative sensor noise in a measured SPD is clipped: light power cannot be negative.
            l.spd[b] = std::max(lj["spd"][b].get<double>(), 0.0);
        }
        if (!(l.spd.sum() > 0.0)) {
            return makeError(ErrorCode::Corrupt,
                             where + ": spd has no positive power; a lamp must emit light");
        }
        auto img = image::readExr(dir / lj["luminance"].get<std::string>(), {"Y"});
        if (!img) {
            return tl::unexpected(img.error());
        }
        l.luminance.width = img->width;
        l.luminance.height = img->height;
        l.luminance.cdM2.assign(img->planes[0].begin(), img->planes[0].end());
        if (auto ok = checkLuminance(l.luminance,
                                     (dir / lj["luminance"].get<std::string>()).string());
            !ok) {
            return tl::unexpected(ok.error());
        }
        booth.lights.push_back(std::move(l));
    }
    if (j.contains("walls")) {
        BoothWalls w;
        w.reflectance = colour::Spectrum::constant(kMunsellN7Reflectance);
        if (j["walls"].contains("reflectance")) {
            for (std::size_t b = 0; b < colour::kBands; ++b) {
                w.reflectance[b] = j["walls"]["reflectance"][b].get<double>();
            }
        }
        booth.walls = w;
    }
    return booth;
}

Expected<void> saveBooth(const std::filesystem::path& dir, const Booth& booth)
{
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) {
        return makeError(ErrorCode::Io,
                         fmt::format("{}: cannot create folder ({})", dir.string(), ec.message()));
    }
    nlohmann::json j;
    j["format"] = kFormat;
    j["lights"] = nlohmann::json::array();
    for (const auto& l : booth.lights) {
        // A light's name becomes a file name in 'dir': never a path that leaves it.
        if (auto ok = checkPlainName(l.name, (dir / "booth.json").string() + ": light name"); !ok) {
            return ok;
        }
        nlohmann::json lj;
        lj["name"] = l.name;
        lj["luminance"] = l.name + ".exr";
        lj["centre"] = {l.centre.x, l.centre.y, l.centre.z};
        lj["edge_u"] = {l.edgeU.x, l.edgeU.y, l.edgeU.z};
        lj["edge_v"] = {l.edgeV.x, l.edgeV.y, l.edgeV.z};
        lj["spd"] = std::vector<double>(l.spd.v.begin(), l.spd.v.end());
        j["lights"].push_back(lj);
        image::ChannelImage img;
        img.width = l.luminance.width;
        img.height = l.luminance.height;
        img.names = {"Y"};
        img.planes.emplace_back(l.luminance.cdM2.begin(), l.luminance.cdM2.end());
        if (auto ok = image::writeExr(dir / (l.name + ".exr"), img, {{"units", "cd/m^2"}}); !ok) {
            return ok;
        }
    }
    if (booth.walls) {
        j["walls"]["reflectance"] = std::vector<double>(booth.walls->reflectance.v.begin(),
                                                        booth.walls->reflectance.v.end());
    }
    return writeOutputFile(dir / "booth.json", j.dump(2) + "\n", "booth model");
}

} // namespace replica::pipeline::booth
