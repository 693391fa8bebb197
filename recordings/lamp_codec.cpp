// The lamp selector's samples on /hal/lamp_selector: JSON payload, schema and codec.
#include <algorithm>
#include <stdexcept>

#include <recordings/codec_json.h>

namespace replica::recordings {
namespace {

constexpr std::size_t kMaxSelectorLines = 32; // GPIO lines a lamp selector may have

} // namespace

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
    s.timestampNs = integerField<std::int64_t>(j, "t");
    s.sequence = integerField<std::uint32_t>(j, "seq");
    s.lamp = integerField<int>(j, "lamp");
    const auto levels = j.at("levels").get<std::vector<int>>();
    // A selector has at most 32 lines and lamp i is line i alone: an index of 32 or more (or below
    // the codes -1..-3) is not one any Replica build wrote.
    if (levels.size() > kMaxSelectorLines || s.lamp < hal::kLampLost ||
        s.lamp >= static_cast<int>(kMaxSelectorLines)) {
        throw std::out_of_range(fmt::format("lamp selector sample: {} lines, lamp {}; a selector "
                                            "has at most {} lines, lamp codes are -3..{}",
                                            levels.size(), s.lamp, kMaxSelectorLines,
                                            kMaxSelectorLines - 1));
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
