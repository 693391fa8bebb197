// Display profile JSON.
#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <pipeline/base/input_file.h>
#include <pipeline/base/json_limits.h>
#include <pipeline/base/json_schema.h>
#include <pipeline/base/output_file.h>
#include <pipeline/display/display_profile.h>

namespace replica::pipeline::display {
namespace {

constexpr int kFormatVersion = 1;
constexpr std::array<const char*, 3> kChannelKeys{"r", "g", "b"};

nlohmann::json vec3Json(const glm::dvec3& v)
{
    return nlohmann::json::array({v.x, v.y, v.z});
}

glm::dvec3 vec3From(const nlohmann::json& j)
{
    if (!j.is_array() || j.size() != 3) {
        throw std::runtime_error("expected an array of 3 numbers");
    }
    return {j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()};
}

// The profile (docs/display.md): luminances in cd/m^2 of a real panel, tone curves of at most
// 65536 points (a 16-bit panel's every code).
const JsonSchema& profileSchema()
{
    using namespace json_schema;
    static const JsonSchema xyz = array(number(-1e5, 1e5), 3, 3);
    static const JsonSchema curve = object({{"counts", array(number(0.0, 1e6), 2, 65536)},
                                            {"r", array(number(-1e3, 1e3), 2, 65536)}});
    static const JsonSchema angles = array(number(-1e6, 1e6), 0, 4096);
    static const JsonSchema crossCol = array(number(-1.0, 1.0), 3, 3);
    static const JsonSchema s = object({
            {"format", string(64)},
            {"version", integer(0, 1e6)},
            {"name", string(256)},
            {"description", string(65536).optional()},
            {"synthetic", boolean().optional()},
            {"bit_depth", integer(1, 16)},
            {"measured_in", string(64)},
            {"front_surface_reflectance", number(0.0, 1.0)},
            {"black_xyz_cd_m2", xyz},
            {"primaries_xyz_cd_m2", object({{"r", xyz}, {"g", xyz}, {"b", xyz}})},
            {"tone_curves", object({{"r", curve}, {"g", curve}, {"b", curve}})},
            {"viewing_angle", object({{"angle_deg", angles},
                                      {"luminance_ratio", angles},
                                      {"dx", angles},
                                      {"dy", angles}})
                                      .optional()},
            {"fit", map(any(), 256).optional()},
            {"gamut_edge_tolerance", number(0.0, 0.05).optional()},
            {"gamut_edge_floor", number(0.0, 0.05).optional()},
            {"crosstalk",
             object({{"rg", crossCol}, {"gb", crossCol}, {"br", crossCol}}).optional()},
    });
    return s;
}

// The key of the first number in 'j' that is not finite ("fit.additivity_luminance_percent"), or
// of a null (what a NaN or an infinity becomes when written): no reader takes either.
std::optional<std::string> nonFiniteKey(const nlohmann::json& j, const std::string& at)
{
    if (j.is_null() || (j.is_number_float() && !std::isfinite(j.get<double>()))) {
        return at;
    }
    if (j.is_object()) {
        for (const auto& [key, value] : j.items()) {
            if (auto bad = nonFiniteKey(value, at.empty() ? key : at + "." + key)) {
                return bad;
            }
        }
    } else if (j.is_array()) {
        for (std::size_t i = 0; i < j.size(); ++i) {
            if (auto bad = nonFiniteKey(j[i], fmt::format("{}[{}]", at, i))) {
                return bad;
            }
        }
    }
    return std::nullopt;
}

// A primary's X, Y and Z are amounts of light: Y above 0, and X and Z no more negative than a
// measurement's noise (1 % of Y). [-1, -1, -1] inverts to nonsense and renders wrong colours.
Expected<void> checkPrimary(const glm::dvec3& xyz, const char* key, const std::string& source)
{
    if (!(xyz.y > 0.0) || xyz.x < -0.01 * xyz.y || xyz.z < -0.01 * xyz.y) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: primaries_xyz_cd_m2.{} = [{:g}, {:g}, {:g}]: a "
                                     "primary's light cannot be negative (Y above 0, X and Z at "
                                     "least -1 % of Y); fit the profile again ('replica display "
                                     "fit')",
                                     source, key, xyz.x, xyz.y, xyz.z));
    }
    return {};
}

nlohmann::json profileJson(const DisplayModel& m)
{
    nlohmann::json j;
    j["format"] = "replica-display-profile";
    j["version"] = kFormatVersion;
    j["name"] = m.name;
    j["description"] = m.description;
    j["synthetic"] = m.synthetic;
    j["bit_depth"] = m.bitDepth;
    j["measured_in"] = m.condition == MeasurementCondition::LitBooth ? "lit-booth" : "dark";
    j["front_surface_reflectance"] = m.frontSurfaceReflectance;
    j["black_xyz_cd_m2"] = vec3Json(m.blackXyz);
    j["primaries_xyz_cd_m2"] = {{"r", vec3Json(m.matrix[0])},
                                {"g", vec3Json(m.matrix[1])},
                                {"b", vec3Json(m.matrix[2])}};
    nlohmann::json tone;
    for (std::size_t c = 0; c < 3; ++c) {
        tone[kChannelKeys[c]] = {{"counts", m.tone[c].counts()}, {"r", m.tone[c].values()}};
    }
    j["tone_curves"] = tone;
    j["viewing_angle"] = {{"angle_deg", m.viewing.angleDeg},
                          {"luminance_ratio", m.viewing.luminanceRatio},
                          {"dx", m.viewing.dx},
                          {"dy", m.viewing.dy}};
    if (m.gamutEdgeTolerance > 0.0) {
        j["gamut_edge_tolerance"] = m.gamutEdgeTolerance;
        j["gamut_edge_floor"] = m.gamutEdgeFloor;
    }
    if (m.hasCrosstalk()) {
        j["crosstalk"] = {{"rg", vec3Json(m.crosstalk[0])},
                          {"gb", vec3Json(m.crosstalk[1])},
                          {"br", vec3Json(m.crosstalk[2])}};
    }
    const auto& f = m.fit;
    j["fit"] = {{"training_colours", f.trainingColours},
                {"held_out_colours", f.heldOutColours},
                {"held_out_mean_de00", f.heldOutMeanDe00},
                {"held_out_p90_de00", f.heldOutP90De00},
                {"held_out_max_de00", f.heldOutMaxDe00},
                {"training_mean_de00", f.trainingMeanDe00},
                {"direct_primaries_held_out_mean_de00", f.directPrimariesHeldOutMeanDe00},
                {"additivity_de00", f.additivityDe00},
                {"additivity_luminance_percent", f.additivityLuminancePercent},
                {"chromaticity_drift", f.chromaticityDrift},
                {"monotonic_corrections", f.monotonicCorrections},
                {"optimiser_evaluations", f.optimiserEvaluations}};
    if (f.noisePercent >= 0.0) {
        // The noise-robust fit's report (absent from profiles made by the interpolating fit).
        auto& jf = j["fit"];
        jf["noise_percent"] = f.noisePercent;
        jf["tone_shape"] = f.toneShape;
        jf["tone_smoothing"] = f.toneSmoothing;
        jf["inverse_counts_rms"] = f.inverseCountsRms;
        jf["inverse_counts_max"] = f.inverseCountsMax;
        jf["held_out_noise_mean_de00"] = f.heldOutNoiseMeanDe00;
        jf["additivity_luminance_sigma_percent"] = f.additivityLuminanceSigmaPercent;
        jf["additivity_noise_de00"] = f.additivityNoiseDe00;
        jf["additive_within_noise"] = f.additiveWithinNoise;
        jf["gamut_edge_sigma"] = f.gamutEdgeSigma;
        if (!f.crosstalkModel.empty()) {
            jf["crosstalk_model"] = f.crosstalkModel;
            jf["crosstalk_gain_de00"] = f.crosstalkGainDe00;
        }
    }
    return j;
}

} // namespace

std::string profileToJson(const DisplayModel& m)
{
    return profileJson(m).dump(2) + "\n";
}

namespace {

// The fit report a profile carries (fields absent from older profiles keep their defaults).
FitReport fitReportFromJson(const nlohmann::json& f)
{
    FitReport r;
    r.trainingColours = f.value("training_colours", 0);
    r.heldOutColours = f.value("held_out_colours", 0);
    r.heldOutMeanDe00 = f.value("held_out_mean_de00", 0.0);
    r.heldOutP90De00 = f.value("held_out_p90_de00", 0.0);
    r.heldOutMaxDe00 = f.value("held_out_max_de00", 0.0);
    r.trainingMeanDe00 = f.value("training_mean_de00", 0.0);
    r.directPrimariesHeldOutMeanDe00 = f.value("direct_primaries_held_out_mean_de00", 0.0);
    r.additivityDe00 = f.value("additivity_de00", -1.0);
    r.additivityLuminancePercent = f.value("additivity_luminance_percent", 0.0);
    if (f.contains("chromaticity_drift")) {
        r.chromaticityDrift = f.at("chromaticity_drift").get<std::array<double, 3>>();
    }
    r.monotonicCorrections = f.value("monotonic_corrections", 0);
    r.optimiserEvaluations = f.value("optimiser_evaluations", 0);
    if (f.contains("noise_percent")) {
        r.noisePercent = f.at("noise_percent").get<double>();
        r.toneShape = f.at("tone_shape").get<std::array<std::string, 3>>();
        r.toneSmoothing = f.at("tone_smoothing").get<std::array<double, 3>>();
        r.inverseCountsRms = f.at("inverse_counts_rms").get<std::array<double, 3>>();
        r.inverseCountsMax = f.at("inverse_counts_max").get<std::array<double, 3>>();
        r.heldOutNoiseMeanDe00 = f.value("held_out_noise_mean_de00", -1.0);
        r.additivityLuminanceSigmaPercent = f.value("additivity_luminance_sigma_percent", -1.0);
        r.additivityNoiseDe00 = f.value("additivity_noise_de00", -1.0);
        r.additiveWithinNoise = f.value("additive_within_noise", false);
        r.gamutEdgeSigma = f.value("gamut_edge_sigma", -1.0);
        r.crosstalkModel = f.value("crosstalk_model", std::string());
        r.crosstalkGainDe00 = f.value("crosstalk_gain_de00", 0.0);
    }
    return r;
}

} // namespace

Expected<DisplayModel> profileFromJson(const std::string& text, const std::string& source)
{
    DisplayModel m;
    if (auto ok = checkJsonLimits(text, source); !ok) {
        return tl::unexpected(ok.error());
    }
    try {
        const auto j = nlohmann::json::parse(text);
        if (!j.is_object() || j.value("format", "") != "replica-display-profile") {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("{}: not a Replica display profile (no \"format\": "
                                         "\"replica-display-profile\")",
                                         source));
        }
        if (j.at("version").get<int>() != kFormatVersion) {
            return makeError(ErrorCode::Unsupported,
                             fmt::format("{}: profile version {} (this build reads {})", source,
                                         j.at("version").get<int>(), kFormatVersion));
        }
        if (auto ok = validateJson(j, profileSchema(), source); !ok) {
            return tl::unexpected(ok.error());
        }
        m.name = j.at("name").get<std::string>();
        m.description = j.value("description", "");
        m.synthetic = j.value("synthetic", false);
        m.bitDepth = j.at("bit_depth").get<int>();
        const auto cond = j.at("measured_in").get<std::string>();
        if (cond != "dark" && cond != "lit-booth") {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("{}: measured_in '{}' must be 'dark' or 'lit-booth'",
                                         source, cond));
        }
        m.condition = cond == "dark" ? MeasurementCondition::Dark : MeasurementCondition::LitBooth;
        m.frontSurfaceReflectance = j.at("front_surface_reflectance").get<double>();
        m.blackXyz = vec3From(j.at("black_xyz_cd_m2"));
        m.gamutEdgeTolerance = j.value("gamut_edge_tolerance", 0.0);
        m.gamutEdgeFloor = j.value("gamut_edge_floor", 0.0);
        if (j.contains("crosstalk")) {
            // Absent (every profile before it): additive, C = 0.
            const auto& x = j.at("crosstalk");
            m.crosstalk =
                    glm::dmat3(vec3From(x.at("rg")), vec3From(x.at("gb")), vec3From(x.at("br")));
        }
        const auto& p = j.at("primaries_xyz_cd_m2");
        for (const char* key : kChannelKeys) {
            if (auto ok = checkPrimary(vec3From(p.at(key)), key, source); !ok) {
                return tl::unexpected(ok.error());
            }
        }
        m.matrix = glm::dmat3(vec3From(p.at("r")), vec3From(p.at("g")), vec3From(p.at("b")));
        for (std::size_t c = 0; c < 3; ++c) {
            const auto& t = j.at("tone_curves").at(kChannelKeys[c]);
            auto counts = t.at("counts").get<std::vector<double>>();
            auto values = t.at("r").get<std::vector<double>>();
            bool ok = counts.size() == values.size() && counts.size() >= 2;
            for (std::size_t i = 1; ok && i < counts.size(); ++i) {
                ok = counts[i] > counts[i - 1] && values[i] >= values[i - 1];
            }
            if (!ok) {
                return makeError(ErrorCode::Corrupt,
                                 fmt::format("{}: tone curve '{}' needs at least 2 points, "
                                             "counts strictly increasing and r non-decreasing",
                                             source, kChannelKeys[c]));
            }
            m.tone[c] = ToneCurve(std::move(counts), std::move(values));
        }
        if (j.contains("viewing_angle")) {
            const auto& v = j.at("viewing_angle");
            m.viewing.angleDeg = v.at("angle_deg").get<std::vector<double>>();
            m.viewing.luminanceRatio = v.at("luminance_ratio").get<std::vector<double>>();
            m.viewing.dx = v.at("dx").get<std::vector<double>>();
            m.viewing.dy = v.at("dy").get<std::vector<double>>();
        }
        if (j.contains("fit")) {
            m.fit = fitReportFromJson(j.at("fit"));
        }
    } catch (const std::exception& e) {
        return makeError(ErrorCode::Corrupt, fmt::format("{}: {}", source, e.what()));
    }
    if (auto ok = m.validate(); !ok) {
        return makeError(ok.error().code, fmt::format("{}: {}", source, ok.error().message));
    }
    return m;
}

Expected<DisplayModel> loadProfile(const std::filesystem::path& path)
{
    auto text = readInputFile(path, kMaxJsonBytes, "display profile");
    if (!text) {
        if (text.error().code == ErrorCode::NotFound) {
            return makeError(ErrorCode::NotFound,
                             fmt::format("{}: cannot open the display profile", path.string()));
        }
        return tl::unexpected(text.error());
    }
    return profileFromJson(*text, path.string());
}

Expected<void> saveProfile(const DisplayModel& model, const std::filesystem::path& path)
{
    // Never a profile that nothing can load: a number that is not finite (written as null), or
    // anything else the reader refuses, is an error here and nothing is written.
    const nlohmann::json j = profileJson(model);
    if (auto bad = nonFiniteKey(j, "")) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: the profile's {} is not a finite number; nothing "
                                     "written: check the measurements for a value out of range",
                                     path.string(), *bad));
    }
    const std::string text = j.dump(2) + "\n";
    if (auto back = profileFromJson(text, path.string()); !back) {
        return makeError(back.error().code, back.error().message + "; nothing written");
    }
    return writeOutputFile(path, text, "display profile");
}

} // namespace replica::pipeline::display
