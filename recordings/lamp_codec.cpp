// The lamp selector's samples on /hal/lamp_selector: JSON payload, schema and codec.
#include <algorithm>
#include <stdexcept>

#include <recordings/codec_json.h>

namespace replica::recordings {

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

SampleCodec<hal::LampSample> lampCodec()
{
    SampleCodec<hal::LampSample> c;
    c.encode = [](const hal::LampSample& s) { return std::optional<std::string>(encodeLamp(s)); };
    c.decode = decodeLamp;
    return c;
}

} // namespace replica::recordings
