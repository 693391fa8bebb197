// What was shown (format 4): the display digest, thumbnail, booth frames, eye, decided light and
// log channels' schemas and JSON payloads, in Foxglove's schemas where one exists.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include <recordings/codec_json.h>

namespace replica::recordings {
namespace {

// Foxglove's published JSON Schemas (github.com/foxglove/schemas, schemas/jsonschema/), restated:
// the field names, types and nesting viewers decode by.
constexpr const char* kFoxgloveTime =
        R"({"type": "object", "title": "time", "properties": {"sec": {"type": "integer",
      "minimum": 0}, "nsec": {"type": "integer", "minimum": 0, "maximum": 999999999}}})";
constexpr const char* kFoxgloveVector3 =
        R"({"title": "foxglove.Vector3", "type": "object", "properties": {"x": {"type": "number"},
      "y": {"type": "number"}, "z": {"type": "number"}}})";
constexpr const char* kFoxgloveQuaternion =
        R"({"title": "foxglove.Quaternion", "type": "object", "properties": {"x": {"type":
      "number"}, "y": {"type": "number"}, "z": {"type": "number"}, "w": {"type": "number"}}})";

std::string foxgloveSchema(const std::string& title,
                           const std::string& description,
                           const std::string& properties)
{
    return R"({"title": ")" + title + R"(", "description": ")" + description +
           R"(", "type": "object", "properties": {)" + properties + "}}";
}

json foxgloveTime(std::int64_t unixNs)
{
    const std::int64_t v = std::max<std::int64_t>(unixNs, 0);
    return {{"sec", v / 1'000'000'000}, {"nsec", v % 1'000'000'000}};
}

json quaternion(double x, double y, double z, double w)
{
    return {{"x", x}, {"y", y}, {"z", z}, {"w", w}};
}

json transform(const json& stamp,
               std::string_view parent,
               std::string_view child,
               const glm::dvec3& t,
               const json& rotation)
{
    return {{"timestamp", stamp},
            {"parent_frame_id", parent},
            {"child_frame_id", child},
            {"translation", vec3(t)},
            {"rotation", rotation}};
}

} // namespace

std::vector<ChannelText> shownChannels()
{
    const std::string time = kFoxgloveTime;
    const std::string v3 = kFoxgloveVector3;
    const std::string quat = kFoxgloveQuaternion;
    return {
            {static_cast<std::uint16_t>(ChannelId::DisplayDigest), std::string(kDisplayDigestTopic),
             "replica.DisplayDigest",
             schemaText("replica.DisplayDigest",
                        "A digest of the 8-bit frame that went to the panel, every frame: replay "
                        "recomputes it to check what the visitor saw",
                        R"("frame": {"type": "integer"}, "tick_ns": {"type": "integer"},
    "hash": {"type": "string", "enum": ["xxh3_64"]},
    "rgba": {"type": "string", "description": "XXH3-64 (seed 0) of the RGBA8 frame, rows bottom-up, 16 hex digits"})",
                        R"("frame", "tick_ns", "hash", "rgba")")},
            {static_cast<std::uint16_t>(ChannelId::Thumbnail), std::string(kThumbnailTopic),
             "foxglove.CompressedImage",
             foxgloveSchema("foxglove.CompressedImage", "A thumbnail of the frame the panel showed",
                            R"("timestamp": )" + time + R"(,
    "frame_id": {"type": "string"},
    "data": {"type": "string", "contentEncoding": "base64"},
    "format": {"type": "string"})")},
            {static_cast<std::uint16_t>(ChannelId::Transforms), std::string(kTransformsTopic),
             "foxglove.FrameTransforms",
             foxgloveSchema("foxglove.FrameTransforms",
                            "The booth's frames: panel (tilted), tracker and eye in the booth",
                            R"("transforms": {"type": "array", "items": {"title":
      "foxglove.FrameTransform", "type": "object", "properties": {"timestamp": )" +
                                    time + R"(,
      "parent_frame_id": {"type": "string"}, "child_frame_id": {"type": "string"},
      "translation": )" + v3 + R"(, "rotation": )" +
                                    quat + "}}}")},
            {static_cast<std::uint16_t>(ChannelId::Eye), std::string(kEyeTopic),
             "foxglove.PoseInFrame",
             foxgloveSchema("foxglove.PoseInFrame", "The viewer's eye in the booth frame (m)",
                            R"("timestamp": )" + time + R"(, "frame_id": {"type": "string"},
    "pose": {"title": "foxglove.Pose", "type": "object", "properties": {"position": )" +
                                    v3 + R"(, "orientation": )" + quat + "}}")},
            {static_cast<std::uint16_t>(ChannelId::Light), std::string(kLightTopic),
             "replica.Light",
             schemaText("replica.Light",
                        "The light the appliance decided to render with, when it changes",
                        R"json("t": {"type": "integer", "description": "session time (ns)"},
    "frame": {"type": "integer"},
    "mode": {"type": "string", "enum": ["lamp", "direct-sensor"]},
    "lamp": {"type": "integer", "description": "booth lamp index; -1 in direct-sensor mode"},
    "name": {"type": "string"},
    "cct_k": {"type": "number", "description": "correlated colour temperature (K); absent where undefined"},
    "duv": {"type": "number"},
    "distance": {"type": "number", "description": "spectral shape distance to the nearest stored lamp"},
    "why": {"type": "string"})json",
                        R"("t", "frame", "mode", "lamp", "name", "why")")},
            {static_cast<std::uint16_t>(ChannelId::Log), std::string(kLogTopic), "foxglove.Log",
             foxgloveSchema("foxglove.Log", "The appliance's warnings and errors",
                            R"("timestamp": )" + time + R"(,
    "level": {"title": "foxglove.LogLevel", "oneOf": [{"title": "UNKNOWN", "const": 0},
      {"title": "DEBUG", "const": 1}, {"title": "INFO", "const": 2},
      {"title": "WARNING", "const": 3}, {"title": "ERROR", "const": 4},
      {"title": "FATAL", "const": 5}]},
    "message": {"type": "string"}, "name": {"type": "string"}, "file": {"type": "string"},
    "line": {"type": "integer", "minimum": 0})")},
            {static_cast<std::uint16_t>(ChannelId::ErrorProbe), std::string(kErrorProbeTopic),
             "replica.ErrorProbe",
             schemaText(
                     "replica.ErrorProbe",
                     "The running appliance's error: CIEDE2000 between the frame's XYZ and the "
                     "exact reference at n random pixels of the surface, every few seconds",
                     R"json("t": {"type": "integer", "description": "session time (ns) of the probed frame"},
    "frame": {"type": "integer"},
    "n": {"type": "integer", "description": "pixels compared"},
    "de00_mean": {"type": "number"}, "de00_p95": {"type": "number"}, "de00_max": {"type": "number"},
    "budget_p95": {"type": "number", "description": "the error budget: p95 above it is over"},
    "over_budget": {"type": "boolean"},
    "cpu_ms": {"type": "number", "description": "the probe's CPU time, at idle priority"})json",
                     R"("t", "frame", "n", "de00_p95", "de00_max")")},
    };
}

std::string encodeDisplayDigest(const DisplayDigestRecord& d)
{
    char hex[17];
    std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(d.rgba));
    return json{{"frame", d.frameIndex}, {"tick_ns", d.tickNs}, {"hash", "xxh3_64"}, {"rgba", hex}}
            .dump();
}

DisplayDigestRecord decodeDisplayDigest(const json& j)
{
    DisplayDigestRecord d;
    d.frameIndex = integerField<std::uint64_t>(j, "frame");
    d.tickNs = integerField<std::int64_t>(j, "tick_ns");
    if (j.at("hash").get<std::string>() != "xxh3_64") {
        throw std::out_of_range("display digest: unknown hash " + j.at("hash").get<std::string>());
    }
    const std::string hex = j.at("rgba");
    if (hex.size() != 16 || hex.find_first_not_of("0123456789abcdef") != std::string::npos) {
        throw std::out_of_range("display digest: rgba is not 16 hex digits");
    }
    d.rgba = std::stoull(hex, nullptr, 16);
    return d;
}

std::string encodeThumbnail(const ThumbnailRecord& t, std::int64_t wallStartNs)
{
    return json{{"timestamp", foxgloveTime(wallStartNs + t.tNs)},
                {"frame_id", kPanelFrame},
                {"data", base64Encode(t.png)},
                {"format", "png"}}
            .dump();
}

std::optional<std::string> encodeTransforms(const PosesRecord& p, std::int64_t wallStartNs)
{
    if (!finite(p.eyeBoothM) || !finite(p.trackerBoothM) || !std::isfinite(p.tiltRad)) {
        return std::nullopt;
    }
    const json stamp = foxgloveTime(wallStartNs + p.tNs);
    const json identity = quaternion(0.0, 0.0, 0.0, 1.0);
    // A rotation by the tilt about x: (sin(a/2), 0, 0, cos(a/2)).
    const json tilt = quaternion(std::sin(p.tiltRad / 2.0), 0.0, 0.0, std::cos(p.tiltRad / 2.0));
    json list = json::array();
    list.push_back(transform(stamp, kBoothFrame, kPanelFrame, glm::dvec3(0.0), tilt));
    list.push_back(transform(stamp, kBoothFrame, kTrackerFrame, p.trackerBoothM, identity));
    list.push_back(transform(stamp, kBoothFrame, kEyeFrame, p.eyeBoothM, identity));
    return json{{"transforms", list}}.dump();
}

std::optional<std::string> encodeEye(const PosesRecord& p, std::int64_t wallStartNs)
{
    if (!finite(p.eyeBoothM)) {
        return std::nullopt;
    }
    return json{
            {"timestamp", foxgloveTime(wallStartNs + p.tNs)},
            {"frame_id", kBoothFrame},
            {"pose",
             {{"position", vec3(p.eyeBoothM)}, {"orientation", quaternion(0.0, 0.0, 0.0, 1.0)}}}}
            .dump();
}

std::string encodeLight(const LightRecord& l)
{
    json j{{"t", l.tNs},     {"frame", l.frameIndex}, {"mode", l.mode},
           {"lamp", l.lamp}, {"name", l.name},        {"why", l.why}};
    if (std::isfinite(l.distance)) {
        j["distance"] = l.distance;
    }
    if (l.cctK && std::isfinite(*l.cctK)) {
        j["cct_k"] = *l.cctK;
    }
    if (l.duv && std::isfinite(*l.duv)) {
        j["duv"] = *l.duv;
    }
    return j.dump();
}

LightRecord decodeLight(const json& j)
{
    LightRecord l;
    l.tNs = integerField<std::int64_t>(j, "t");
    l.frameIndex = integerField<std::uint64_t>(j, "frame");
    l.mode = j.at("mode");
    l.lamp = j.at("lamp");
    l.name = j.at("name");
    l.why = j.at("why");
    l.distance = j.value("distance", 0.0);
    if (j.contains("cct_k")) {
        l.cctK = j.at("cct_k").get<double>();
    }
    if (j.contains("duv")) {
        l.duv = j.at("duv").get<double>();
    }
    return l;
}

std::string encodeLog(const LogRecord& l, std::int64_t wallStartNs)
{
    return json{{"timestamp", foxgloveTime(wallStartNs + l.tNs)},
                {"level", l.level},
                {"message", l.message},
                {"name", l.name},
                {"file", ""},
                {"line", 0}}
            .dump(-1, ' ', false, json::error_handler_t::replace);
}

std::optional<std::string> encodeErrorProbe(const ErrorProbeRecord& e)
{
    for (const double v : {e.meanDe00, e.p95De00, e.maxDe00, e.budgetP95, e.cpuMs}) {
        if (!std::isfinite(v)) {
            return std::nullopt;
        }
    }
    return json{{"t", e.tNs},
                {"frame", e.frameIndex},
                {"n", e.n},
                {"de00_mean", e.meanDe00},
                {"de00_p95", e.p95De00},
                {"de00_max", e.maxDe00},
                {"budget_p95", e.budgetP95},
                {"over_budget", e.p95De00 > e.budgetP95},
                {"cpu_ms", e.cpuMs}}
            .dump();
}

} // namespace replica::recordings
