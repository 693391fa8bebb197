// JSON encoding of Replica's messages and the JSON Schemas that let MCAP viewers plot them.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include <fmt/format.h>

#include <recordings/sample_codec.h>

namespace replica::recordings {
namespace {

using nlohmann::json;

bool finite(const glm::dvec3& v)
{
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

template <std::size_t N>
bool finite(const std::array<double, N>& a)
{
    for (double x : a) {
        if (!std::isfinite(x)) {
            return false;
        }
    }
    return true;
}

json vec3(const glm::dvec3& v)
{
    return {{"x", v.x}, {"y", v.y}, {"z", v.z}};
}

glm::dvec3 vec3From(const json& j)
{
    return {j.at("x").get<double>(), j.at("y").get<double>(), j.at("z").get<double>()};
}

json deviceJson(const hal::DeviceInfo& d)
{
    return {{"model", d.model},
            {"serial", d.serial},
            {"firmware", d.firmware},
            {"source", hal::toString(d.kind)}};
}

hal::DeviceInfo deviceFromJson(const json& j)
{
    hal::DeviceInfo d{j.at("model"), j.at("serial"), j.at("firmware"), hal::SourceKind::Sim};
    const std::string k = j.at("source");
    d.kind = k == "live"     ? hal::SourceKind::Live
             : k == "replay" ? hal::SourceKind::Replay
                             : hal::SourceKind::Sim;
    return d;
}

constexpr const char* kDevice =
        R"({"type": "object", "properties": {"model": {"type": "string"},
      "serial": {"type": "string"}, "firmware": {"type": "string"},
      "source": {"type": "string", "enum": ["live", "sim", "replay"]}}})";

std::string schemaText(const std::string& title,
                       const std::string& description,
                       const std::string& properties,
                       const std::string& required)
{
    return jsonSchemaText(title, description, properties, required);
}

// "key": {"type": "integer"} for each key, two to a line: a line break before the odd ones
// (oddBreaks) or the even ones. The layout the format-5 schemas were written in, so that their
// bytes stay the same.
std::string integerProps(const std::vector<std::string>& keys, bool oddBreaks)
{
    std::string out;
    for (std::size_t i = 0; i < keys.size(); ++i) {
        if (i > 0) {
            out += (i % 2 == 1) == oddBreaks ? ",\n    " : ", ";
        }
        out += "\"" + keys[i] + R"(": {"type": "integer"})";
    }
    return out;
}

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

std::vector<ChannelDefinition> makeDefinitions(const DeviceKinds& kinds)
{
    const std::string time = kFoxgloveTime;
    const std::string v3 = kFoxgloveVector3;
    const std::string quat = kFoxgloveQuaternion;
    const std::string dev = kDevice;
    // The composite channels name every device kind: the session its source, a frame the sample
    // it consumed, the recorder what it dropped (frames after the first three devices: format 2's
    // order).
    std::string sessionDevices;
    std::vector<std::string> frameKeys{"frame", "tick_ns"};
    std::vector<std::string> droppedKeys;
    for (const auto* k : kinds) {
        sessionDevices += (sessionDevices.empty() ? "\"" : ", \"") + k->name() + "\": " + dev;
        frameKeys.push_back(k->names().frameKey);
        droppedKeys.push_back(k->names().droppedKey);
    }
    const auto framesAt = std::min<std::size_t>(3, droppedKeys.size());
    droppedKeys.insert(droppedKeys.begin() + static_cast<std::ptrdiff_t>(framesAt),
                       "dropped_frames");
    droppedKeys.push_back("dropped_shown");
    struct Def {
        std::uint16_t id;
        std::string topic;
        std::string name, schema;
    };
    std::vector<Def> defs = {
            {static_cast<std::uint16_t>(ChannelId::Session), std::string(kSessionTopic),
             "replica.Session",
             schemaText(
                     "replica.Session",
                     "What was recorded: software, configuration, booth, scene, display, devices",
                     R"("format_version": {"type": "integer"}, "software": {"type": "string"},
    "config": {"type": "string", "description": "resolved run configuration, as JSON text"},
    "booth": {"type": "string"}, "scene": {"type": "string"},
    "display_profile": {"type": "string"},
    "wall_clock_start_ns": {"type": "integer", "description": "Unix time (ns) at session time 0"},
    )" + sessionDevices,
                     R"("format_version", "software", "config", "wall_clock_start_ns")")},
            {static_cast<std::uint16_t>(ChannelId::Frame), std::string(kFrameTopic),
             "replica.Frame",
             schemaText("replica.Frame",
                        "A rendered frame: its tick time and the device sequence numbers of the "
                        "samples it consumed (absent: none yet)",
                        integerProps(frameKeys, false), R"("frame", "tick_ns")")},
            {static_cast<std::uint16_t>(ChannelId::Recorder), std::string(kRecorderTopic),
             "replica.RecorderStatus",
             schemaText("replica.RecorderStatus",
                        "Samples the recorder could not write (queue full, or NaN/infinite "
                        "values), cumulative since the session start",
                        integerProps(droppedKeys, true) + R"(,
    "dropped_total": {"type": "integer"},
    "rejected_nonfinite": {"type": "integer"}, "queue_capacity": {"type": "integer"})",
                        R"("dropped_total")")},
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
    };
    for (const auto* k : kinds) {
        const auto& n = k->names();
        defs.push_back({n.channel.id, n.channel.topic, n.channel.schemaName, n.channel.schemaText});
        if (n.rawChannel) {
            defs.push_back({n.rawChannel->id, n.rawChannel->topic, n.rawChannel->schemaName,
                            n.rawChannel->schemaText});
        }
    }
    std::stable_sort(defs.begin(), defs.end(),
                     [](const Def& a, const Def& b) { return a.id < b.id; });
    std::vector<ChannelDefinition> out;
    for (const auto& d : defs) {
        const auto id = d.id;
        out.push_back({mcap::Schema{id, d.name, "jsonschema", d.schema},
                       mcap::Channel{id, id, std::string(d.topic), "json", {}}});
    }
    return out;
}

} // namespace

const std::vector<ChannelDefinition>& channelDefinitions()
{
    static const std::vector<ChannelDefinition> defs = makeDefinitions(deviceKinds());
    return defs;
}

std::vector<ChannelDefinition> channelDefinitions(const DeviceKinds& kinds)
{
    return makeDefinitions(kinds);
}

std::string jsonSchemaText(const std::string& title,
                           const std::string& description,
                           const std::string& properties,
                           const std::string& required)
{
    return R"({"$schema": "https://json-schema.org/draft/2020-12/schema", "title": ")" + title +
           R"(", "description": ")" + description + R"(", "type": "object", "properties": {)" +
           properties + R"(}, "required": [)" + required + "]}";
}

std::string encodeSession(const SessionInfo& s, int formatVersion, const DeviceKinds& kinds)
{
    json j{{"format_version", formatVersion},
           {"software", s.softwareVersion},
           {"config", s.configJson},
           {"booth", s.boothModel},
           {"scene", s.scene},
           {"display_profile", s.displayProfile},
           {"wall_clock_start_ns", s.wallClockStartNs}};
    for (const auto* k : kinds) {
        j[k->name()] = deviceJson(s.device(*k));
    }
    return j.dump();
}

std::optional<std::string> encodeSpectrum(const hal::SpectrumSample& s)
{
    if (!finite(s.wavelengthCoeffs) || !finite(s.nonlinearityCoeffs)) {
        return std::nullopt;
    }
    return json{{"t", s.timestampNs},
                {"seq", s.sequence},
                {"integration_time_us", s.integrationTimeUs},
                {"counts", s.counts},
                {"wavelength_coeffs", s.wavelengthCoeffs},
                {"nonlinearity_coeffs", s.nonlinearityCoeffs},
                {"saturated", s.saturated}}
            .dump();
}

std::optional<std::string> encodePose(const hal::PoseSample& s)
{
    if (!finite(s.eyeTrackerM)) {
        return std::nullopt;
    }
    return json{{"t", s.timestampNs},
                {"seq", s.sequence},
                {"tracked", s.tracked},
                {"eye", vec3(s.eyeTrackerM)}}
            .dump();
}

std::optional<std::string> encodeAccel(const hal::AccelSample& s)
{
    if (!finite(s.gravity)) {
        return std::nullopt;
    }
    return json{{"t", s.timestampNs}, {"seq", s.sequence}, {"gravity", vec3(s.gravity)}}.dump();
}

std::string encodeLamp(const hal::LampSample& s)
{
    std::vector<int> levels;
    for (std::uint32_t i = 0; i < std::min<std::uint32_t>(s.lineCount, 32); ++i) {
        levels.push_back((s.lineLevels >> i) & 1u ? 1 : 0);
    }
    return json{{"t", s.timestampNs},
                {"seq", s.sequence},
                {"lamp", s.lamp},
                {"state", hal::lampStateName(s.lamp)},
                {"levels", levels}}
            .dump();
}

std::string encodeFrame(const FrameRecord& f, const DeviceKinds& kinds)
{
    json j{{"frame", f.frameIndex}, {"tick_ns", f.tickNs}};
    for (const auto* k : kinds) {
        if (const auto seq = f.sequence(*k)) {
            j[k->names().frameKey] = *seq;
        }
    }
    return j.dump();
}

std::string encodeRecorderStatus(const RecorderStatus& r)
{
    json j{{"dropped_frames", r.droppedFrames},
           {"dropped_shown", r.droppedShown},
           {"dropped_total", r.droppedTotal()},
           {"rejected_nonfinite", r.rejectedNonFinite},
           {"queue_capacity", r.queueCapacity}};
    for (const auto& [key, dropped] : r.droppedDevices) {
        j[key] = dropped;
    }
    return j.dump();
}

namespace {

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

std::string base64Encode(const std::vector<std::uint8_t>& bytes)
{
    static constexpr char kAlphabet[] =
            "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    out.reserve((bytes.size() + 2) / 3 * 4);
    std::size_t i = 0;
    for (; i + 3 <= bytes.size(); i += 3) {
        const std::uint32_t v =
                (std::uint32_t{bytes[i]} << 16) | (std::uint32_t{bytes[i + 1]} << 8) | bytes[i + 2];
        out += kAlphabet[(v >> 18) & 63];
        out += kAlphabet[(v >> 12) & 63];
        out += kAlphabet[(v >> 6) & 63];
        out += kAlphabet[v & 63];
    }
    const std::size_t rest = bytes.size() - i;
    if (rest > 0) {
        std::uint32_t v = std::uint32_t{bytes[i]} << 16;
        if (rest == 2) {
            v |= std::uint32_t{bytes[i + 1]} << 8;
        }
        out += kAlphabet[(v >> 18) & 63];
        out += kAlphabet[(v >> 12) & 63];
        out += rest == 2 ? kAlphabet[(v >> 6) & 63] : '=';
        out += '=';
    }
    return out;
}

std::vector<std::uint8_t> base64Decode(const std::string& text)
{
    const auto value = [](char c) -> int {
        if (c >= 'A' && c <= 'Z') {
            return c - 'A';
        }
        if (c >= 'a' && c <= 'z') {
            return c - 'a' + 26;
        }
        if (c >= '0' && c <= '9') {
            return c - '0' + 52;
        }
        return c == '+' ? 62 : c == '/' ? 63 : -1;
    };
    if (text.size() % 4 != 0) {
        throw std::out_of_range("bytes: base64 text whose length is not a multiple of 4");
    }
    std::vector<std::uint8_t> out;
    out.reserve(text.size() / 4 * 3);
    for (std::size_t i = 0; i < text.size(); i += 4) {
        const bool last = i + 4 == text.size();
        int v[4];
        int pad = 0;
        for (std::size_t k = 0; k < 4; ++k) {
            const char c = text[i + k];
            if (c == '=' && last && k >= 2 && (k == 3 || text[i + 3] == '=')) {
                v[k] = 0;
                ++pad;
                continue;
            }
            v[k] = value(c);
            if (v[k] < 0 || pad > 0) {
                throw std::out_of_range("bytes: not base64");
            }
        }
        const std::uint32_t w = (static_cast<std::uint32_t>(v[0]) << 18) |
                                (static_cast<std::uint32_t>(v[1]) << 12) |
                                (static_cast<std::uint32_t>(v[2]) << 6) |
                                static_cast<std::uint32_t>(v[3]);
        out.push_back(static_cast<std::uint8_t>(w >> 16));
        if (pad < 2) {
            out.push_back(static_cast<std::uint8_t>((w >> 8) & 0xff));
        }
        if (pad < 1) {
            out.push_back(static_cast<std::uint8_t>(w & 0xff));
        }
    }
    return out;
}

std::string encodeRawTrackerDescriptor(std::int64_t tNs,
                                       std::uint32_t id,
                                       const std::vector<std::uint8_t>& descriptor)
{
    return json{{"t", tNs},
                {"kind", "hid-descriptor"},
                {"descriptor", id},
                {"bytes", base64Encode(descriptor)}}
            .dump();
}

std::optional<std::string> encodeRawTracker(const hal::PoseSample& s, std::uint32_t descriptorId)
{
    if (!s.raw) {
        return std::nullopt;
    }
    const hal::RawTrackerInput& r = *s.raw;
    json j{{"t", r.arrivalNs}, {"seq", s.sequence}, {"bytes", base64Encode(r.bytes)}};
    if (r.kind == hal::RawTrackerInput::Kind::OpentrackDatagram) {
        if (!std::isfinite(r.zSign) || !finite(r.eyeOffsetHeadM)) {
            return std::nullopt;
        }
        j["kind"] = "opentrack";
        j["z_sign"] = r.zSign;
        j["eye_offset_head_m"] = vec3(r.eyeOffsetHeadM);
    } else {
        j["kind"] = "hid";
        j["descriptor"] = descriptorId;
        j["axes"] = r.axes;
        j["reanchor_ns"] = r.reanchorNs;
    }
    return j.dump();
}

std::optional<std::string> encodeRawAccel(const hal::AccelSample& s)
{
    if (!s.raw || !finite(s.raw->raw) || !finite(s.raw->scale) || !finite(s.raw->offset)) {
        return std::nullopt;
    }
    return json{{"t", s.timestampNs},    {"seq", s.sequence},       {"raw", s.raw->raw},
                {"scale", s.raw->scale}, {"offset", s.raw->offset}, {"axes", s.raw->axes}}
            .dump();
}

namespace {

// A report or descriptor larger than any HID device's (4096 bytes, the kernel's limit).
constexpr std::size_t kMaxRawBytes = 4096;

std::vector<std::uint8_t> rawBytes(const json& j)
{
    auto bytes = base64Decode(j.at("bytes").get<std::string>());
    if (bytes.size() > kMaxRawBytes) {
        throw std::out_of_range(fmt::format("{} raw bytes; a device report is at most {}",
                                            bytes.size(), kMaxRawBytes));
    }
    return bytes;
}

} // namespace

RawTrackerMessage
decodeRawTracker(const json& j,
                 const std::map<std::uint32_t, std::shared_ptr<const std::vector<std::uint8_t>>>&
                         descriptors)
{
    RawTrackerMessage m;
    const std::string kind = j.at("kind");
    if (kind == "hid-descriptor") {
        m.descriptorId = j.at("descriptor").get<std::uint32_t>();
        m.descriptor = std::make_shared<const std::vector<std::uint8_t>>(rawBytes(j));
        return m;
    }
    auto r = std::make_shared<hal::RawTrackerInput>();
    m.sequence = j.at("seq");
    r->arrivalNs = j.at("t");
    r->bytes = rawBytes(j);
    if (kind == "opentrack") {
        r->kind = hal::RawTrackerInput::Kind::OpentrackDatagram;
        r->zSign = j.at("z_sign");
        r->eyeOffsetHeadM = vec3From(j.at("eye_offset_head_m"));
    } else if (kind == "hid") {
        r->kind = hal::RawTrackerInput::Kind::HidReport;
        const auto id = j.at("descriptor").get<std::uint32_t>();
        const auto it = descriptors.find(id);
        // A descriptor the file does not hold before the report (e.g. its chunk was lost and
        // 'replica recover' dropped it) leaves the report unusable: no raw input, not an error.
        if (it == descriptors.end()) {
            m.descriptorMissing = true;
            return m;
        }
        r->hidDescriptor = it->second;
        r->axes = j.at("axes");
        r->reanchorNs = j.at("reanchor_ns");
    } else {
        throw std::out_of_range("unknown raw tracker kind '" + kind + "'");
    }
    m.raw = std::move(r);
    return m;
}

std::pair<std::uint32_t, std::shared_ptr<hal::RawAccelInput>> decodeRawAccel(const json& j)
{
    auto r = std::make_shared<hal::RawAccelInput>();
    const std::uint32_t seq = j.at("seq");
    (void)j.at("t").get<std::int64_t>();
    r->raw = j.at("raw");
    r->scale = j.at("scale");
    r->offset = j.at("offset");
    r->axes = j.at("axes");
    return {seq, std::move(r)};
}

std::string encodeDisplayDigest(const DisplayDigestRecord& d)
{
    char hex[17];
    std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(d.rgba));
    return json{{"frame", d.frameIndex}, {"tick_ns", d.tickNs}, {"hash", "xxh3_64"}, {"rgba", hex}}
            .dump();
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

DisplayDigestRecord decodeDisplayDigest(const json& j)
{
    DisplayDigestRecord d;
    d.frameIndex = j.at("frame");
    d.tickNs = j.at("tick_ns");
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

LightRecord decodeLight(const json& j)
{
    LightRecord l;
    l.tNs = j.at("t");
    l.frameIndex = j.at("frame");
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

SessionInfo decodeSession(const json& j, int& formatVersion, const DeviceKinds& kinds)
{
    SessionInfo s;
    formatVersion = j.at("format_version");
    s.softwareVersion = j.at("software");
    s.configJson = j.at("config");
    s.boothModel = j.at("booth");
    s.scene = j.at("scene");
    s.displayProfile = j.at("display_profile");
    s.wallClockStartNs = j.at("wall_clock_start_ns");
    for (const auto* k : kinds) {
        // An optional kind is absent from recordings made before it (the lamp selector: 1, 2).
        if (!k->names().optional || j.contains(k->name())) {
            s.devices[k->name()] = deviceFromJson(j.at(k->name()));
        }
    }
    return s;
}

hal::SpectrumSample decodeSpectrum(const json& j)
{
    hal::SpectrumSample s;
    s.timestampNs = j.at("t");
    s.sequence = j.at("seq");
    s.integrationTimeUs = j.at("integration_time_us");
    if (j.at("counts").size() > kMaxSpectrumCounts) {
        throw std::out_of_range(fmt::format("{} counts; a spectrometer has at most {} pixels",
                                            j.at("counts").size(), kMaxSpectrumCounts));
    }
    s.counts = j.at("counts").get<std::vector<std::uint16_t>>();
    s.wavelengthCoeffs = j.at("wavelength_coeffs");
    s.nonlinearityCoeffs = j.at("nonlinearity_coeffs");
    s.saturated = j.at("saturated");
    return s;
}

hal::PoseSample decodePose(const json& j)
{
    hal::PoseSample s;
    s.timestampNs = j.at("t");
    s.sequence = j.at("seq");
    s.tracked = j.at("tracked");
    s.eyeTrackerM = vec3From(j.at("eye"));
    return s;
}

hal::AccelSample decodeAccel(const json& j)
{
    hal::AccelSample s;
    s.timestampNs = j.at("t");
    s.sequence = j.at("seq");
    s.gravity = vec3From(j.at("gravity"));
    return s;
}

hal::LampSample decodeLamp(const json& j)
{
    hal::LampSample s;
    s.timestampNs = j.at("t");
    s.sequence = j.at("seq");
    s.lamp = j.at("lamp");
    const auto levels = j.at("levels").get<std::vector<int>>();
    if (levels.size() > 32 || s.lamp < hal::kLampLost) {
        throw std::out_of_range("lamp selector sample: more than 32 lines or an unknown lamp code");
    }
    s.lineCount = static_cast<std::uint32_t>(levels.size());
    for (std::size_t i = 0; i < levels.size(); ++i) {
        s.lineLevels |= levels[i] != 0 ? (1u << i) : 0u;
    }
    return s;
}

FrameRecord decodeFrame(const json& j, const DeviceKinds& kinds)
{
    FrameRecord f;
    f.frameIndex = j.at("frame");
    f.tickNs = j.at("tick_ns");
    for (const auto* k : kinds) {
        if (j.contains(k->names().frameKey)) {
            f.sequences[k->name()] = j.at(k->names().frameKey).get<std::uint32_t>();
        }
    }
    return f;
}

RecorderStatus decodeRecorderStatus(const json& j, const DeviceKinds& kinds)
{
    RecorderStatus r;
    for (const auto* k : kinds) {
        r.droppedDevices[k->names().droppedKey] = j.value(k->names().droppedKey, std::uint64_t{0});
    }
    r.droppedFrames = j.value("dropped_frames", std::uint64_t{0});
    r.droppedShown = j.value("dropped_shown", std::uint64_t{0});
    r.rejectedNonFinite = j.value("rejected_nonfinite", std::uint64_t{0});
    r.queueCapacity = j.value("queue_capacity", std::uint64_t{0});
    return r;
}

// The device channels' schemas (device_kinds.cpp puts them on their channels).

std::pair<std::string, std::string> spectrumSchema()
{
    return {"replica.SpectrometerSample",
            schemaText("replica.SpectrometerSample",
                       "One raw spectrum with the device calibration needed to convert it",
                       std::string(kTimeSeqProps) + R"(,
    "integration_time_us": {"type": "integer"},
    "counts": {"type": "array", "items": {"type": "integer", "minimum": 0, "maximum": 65535},
      "description": "raw counts, pixel 0 first"},
    "wavelength_coeffs": {"type": "array", "items": {"type": "number"}, "minItems": 4,
      "maxItems": 4, "description": "wavelength (nm) of pixel p = c0 + c1 p + c2 p^2 + c3 p^3"},
    "nonlinearity_coeffs": {"type": "array", "items": {"type": "number"}, "minItems": 8,
      "maxItems": 8, "description": "counts correction polynomial, order 0..7"},
    "saturated": {"type": "boolean"})",
                       R"("t", "seq", "integration_time_us", "counts", "wavelength_coeffs",
    "nonlinearity_coeffs", "saturated")")};
}

std::pair<std::string, std::string> poseSchema()
{
    return {"replica.TrackerPose",
            schemaText("replica.TrackerPose",
                       "The viewer's eye position in the tracker frame (m): x right, y up, z "
                       "towards the viewer",
                       std::string(kTimeSeqProps) + R"(, "tracked": {"type": "boolean"}, "eye": )" +
                               std::string(kVec3Schema),
                       R"("t", "seq", "tracked", "eye")")};
}

std::pair<std::string, std::string> accelSchema()
{
    return {"replica.AccelSample",
            schemaText("replica.AccelSample", "Gravity in the display's device frame (m/s^2)",
                       std::string(kTimeSeqProps) + R"(, "gravity": )" + std::string(kVec3Schema),
                       R"("t", "seq", "gravity")")};
}

std::pair<std::string, std::string> lampSchema()
{
    return {"replica.LampSelectorSample",
            schemaText("replica.LampSelectorSample",
                       "The booth's lamp selector switch once its GPIO lines settled (debounced): "
                       "one line per lamp, in the booth's lamp order",
                       std::string(kTimeSeqProps) + R"(,
    "lamp": {"type": "integer", "minimum": -3, "description":
      "booth lamp index (line i alone active = lamp i); -1 off, -2 invalid (several lines), -3 lines lost"},
    "state": {"type": "string", "enum": ["lamp", "off", "invalid", "lost"]},
    "levels": {"type": "array", "items": {"type": "integer", "minimum": 0, "maximum": 1},
      "maxItems": 32, "description": "debounced level of each line, 1 = active: the switch closes it"})",
                       R"("t", "seq", "lamp", "levels")")};
}

std::pair<std::string, std::string> rawTrackerSchema()
{
    return {"replica.RawTracker",
            schemaText(
                    "replica.RawTracker",
                    "Raw in, processed out: what the head tracker sent for pose seq, before "
                    "processing, with the processing's parameters; or (kind hid-descriptor) "
                    "the report descriptor of one opening of a HID tracker",
                    R"json("t": {"type": "integer", "description": "session time (ns) the bytes arrived"},
    "seq": {"type": "integer", "description": "the pose on /hal/tracker made from them"},
    "kind": {"type": "string", "enum": ["opentrack", "hid", "hid-descriptor"]},
    "bytes": {"type": "string", "contentEncoding": "base64", "description":
      "opentrack: the 48-byte datagram; hid: the input report, report ID first when numbered; hid-descriptor: the report descriptor"},
    "descriptor": {"type": "integer", "description": "hid, hid-descriptor: which descriptor"},
    "z_sign": {"type": "number", "description": "opentrack: sign of z in the tracker frame"},
    "eye_offset_head_m": )json" +
                            std::string(kVec3Schema) +
                            R"json(, "axes": {"type": "string", "description": "hid: device axes to the tracker frame, e.g. x,-y,z"},
    "reanchor_ns": {"type": "integer", "description": "hid: device clock re-anchoring threshold"})json",
                    R"("t", "kind", "bytes")")};
}

std::pair<std::string, std::string> rawAccelSchema()
{
    return {"replica.RawAccel",
            schemaText("replica.RawAccel",
                       "Raw in, processed out: the accelerometer's sysfs reading for accel "
                       "sample seq; gravity = -mounting((raw + offset) * scale)",
                       std::string(kTimeSeqProps) + R"(,
    "raw": {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3,
      "description": "in_accel_{x,y,z}_raw"},
    "scale": {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3},
    "offset": {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3},
    "axes": {"type": "string", "description": "mounting: sensor axis for the panel's x, y, z"})",
                       R"("t", "seq", "raw", "scale", "offset", "axes")")};
}

// The codecs of the device sample types.

SampleCodec<hal::SpectrumSample> spectrumCodec()
{
    SampleCodec<hal::SpectrumSample> c;
    c.encode = encodeSpectrum;
    c.decode = decodeSpectrum;
    return c;
}

namespace {

// Writer state of the raw tracker channel: the HID descriptor written last and its id.
struct RawTrackerWriterState {
    std::shared_ptr<const std::vector<std::uint8_t>> lastDescriptor;
    std::uint32_t descriptorId = 0;
};
// Reader state: descriptors by id, raw inputs by pose sequence.
struct RawTrackerReaderState {
    std::map<std::uint32_t, std::shared_ptr<const std::vector<std::uint8_t>>> descriptors;
    std::map<std::uint32_t, std::shared_ptr<const hal::RawTrackerInput>> raw;
};
using RawAccelReaderState = std::map<std::uint32_t, std::shared_ptr<const hal::RawAccelInput>>;

template <typename State>
State& stateOf(std::any& a)
{
    if (!a.has_value()) {
        a = State{};
    }
    return std::any_cast<State&>(a);
}

// Gives each sample its raw input; returns how many raw inputs found no sample.
template <typename Sample, typename Raw>
std::uint64_t attachRawBySequence(std::vector<Sample>& samples,
                                  const std::map<std::uint32_t, std::shared_ptr<const Raw>>& raw)
{
    std::uint64_t matched = 0;
    for (auto& s : samples) {
        if (auto it = raw.find(s.sequence); it != raw.end()) {
            s.raw = it->second;
            ++matched;
        }
    }
    return matched >= raw.size() ? 0 : raw.size() - matched;
}

} // namespace

SampleCodec<hal::PoseSample> poseCodec()
{
    SampleCodec<hal::PoseSample> c;
    c.encode = encodePose;
    c.decode = decodePose;
    c.encodeRaw = [](const hal::PoseSample& p, std::uint16_t channel, std::any& state,
                     const DeviceEmitter& emit) {
        if (!p.raw) {
            return;
        }
        auto& st = stateOf<RawTrackerWriterState>(state);
        const auto& d = p.raw->hidDescriptor;
        if (p.raw->kind == hal::RawTrackerInput::Kind::HidReport && d &&
            d.get() != st.lastDescriptor.get()) {
            // A new opening of the device: its descriptor once, before its first report.
            st.lastDescriptor = d;
            ++st.descriptorId;
            emit.message(channel, p.raw->arrivalNs,
                         encodeRawTrackerDescriptor(p.raw->arrivalNs, st.descriptorId, *d));
        }
        if (auto raw = encodeRawTracker(p, st.descriptorId)) {
            emit.message(channel, p.raw->arrivalNs, std::move(*raw));
        } else {
            emit.rejectRaw();
        }
    };
    c.decodeRaw = [](const json& j, std::any& state) {
        auto& st = stateOf<RawTrackerReaderState>(state);
        auto r = decodeRawTracker(j, st.descriptors);
        if (r.descriptorId) {
            st.descriptors[*r.descriptorId] = r.descriptor;
        } else if (r.descriptorMissing) {
            return false;
        } else {
            st.raw[r.sequence] = std::move(r.raw);
        }
        return true;
    };
    c.attachRaw = [](std::vector<hal::PoseSample>& poses, std::any& state) {
        return attachRawBySequence(poses, stateOf<RawTrackerReaderState>(state).raw);
    };
    c.hasRaw = [](const hal::PoseSample& p) { return p.raw != nullptr; };
    return c;
}

SampleCodec<hal::AccelSample> accelCodec()
{
    SampleCodec<hal::AccelSample> c;
    c.encode = encodeAccel;
    c.decode = decodeAccel;
    c.encodeRaw = [](const hal::AccelSample& a, std::uint16_t channel, std::any&,
                     const DeviceEmitter& emit) {
        if (!a.raw) {
            return;
        }
        if (auto raw = encodeRawAccel(a)) {
            emit.message(channel, a.timestampNs, std::move(*raw));
        } else {
            emit.rejectRaw();
        }
    };
    c.decodeRaw = [](const json& j, std::any& state) {
        auto [seq, raw] = decodeRawAccel(j);
        stateOf<RawAccelReaderState>(state)[seq] = std::move(raw);
        return true;
    };
    c.attachRaw = [](std::vector<hal::AccelSample>& samples, std::any& state) {
        return attachRawBySequence(samples, stateOf<RawAccelReaderState>(state));
    };
    c.hasRaw = [](const hal::AccelSample& a) { return a.raw != nullptr; };
    return c;
}

SampleCodec<hal::LampSample> lampCodec()
{
    SampleCodec<hal::LampSample> c;
    c.encode = [](const hal::LampSample& s) { return std::optional<std::string>(encodeLamp(s)); };
    c.decode = decodeLamp;
    return c;
}

} // namespace replica::recordings
