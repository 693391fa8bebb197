// The channels of a Replica recording, the composite messages that name every device kind (session,
// frame, recorder status), and base64. Each device kind's codec is in its own file
// (spectrum_codec.cpp, tracker_codec.cpp, accel_codec.cpp, lamp_codec.cpp); the channels of what
// was shown in shown_codec.cpp.
#include <algorithm>
#include <stdexcept>

#include <recordings/codec_json.h>

namespace replica::recordings {
namespace {

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

// The composite channels name every device kind: the session its source, a frame the sample it
// consumed, the recorder what it dropped (frames after the first three devices: format 2's order).
std::vector<ChannelText> compositeChannels(const DeviceKinds& kinds)
{
    const std::string dev = kDevice;
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
    return {
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
    };
}

std::vector<ChannelDefinition> makeDefinitions(const DeviceKinds& kinds)
{
    std::vector<ChannelText> defs = compositeChannels(kinds);
    for (auto& d : shownChannels()) {
        defs.push_back(std::move(d));
    }
    for (const auto* k : kinds) {
        const auto& n = k->names();
        defs.push_back({n.channel.id, n.channel.topic, n.channel.schemaName, n.channel.schemaText});
        if (n.rawChannel) {
            defs.push_back({n.rawChannel->id, n.rawChannel->topic, n.rawChannel->schemaName,
                            n.rawChannel->schemaText});
        }
    }
    std::stable_sort(defs.begin(), defs.end(),
                     [](const ChannelText& a, const ChannelText& b) { return a.id < b.id; });
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
            s.devices[k] = deviceFromJson(j.at(k->name()));
        }
    }
    return s;
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

FrameRecord decodeFrame(const json& j, const DeviceKinds& kinds)
{
    FrameRecord f;
    f.frameIndex = integerField<std::uint64_t>(j, "frame");
    f.tickNs = integerField<std::int64_t>(j, "tick_ns");
    for (const auto* k : kinds) {
        if (j.contains(k->names().frameKey)) {
            f.sequences[k] = integerField<std::uint32_t>(j, k->names().frameKey.c_str());
        }
    }
    return f;
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

} // namespace replica::recordings
