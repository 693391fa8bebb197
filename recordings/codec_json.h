// What the codecs of recordings/sample_codec.h share: JSON helpers, attaching raw inputs to
// their samples, and the channels of what was shown (format 4, shown_codec.cpp). Not for use
// outside recordings/.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <recordings/sample_codec.h>

namespace replica::recordings {

using json = nlohmann::json;

inline bool finite(const glm::dvec3& v)
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

inline json vec3(const glm::dvec3& v)
{
    return {{"x", v.x}, {"y", v.y}, {"z", v.z}};
}

inline glm::dvec3 vec3From(const json& j)
{
    return {j.at("x").get<double>(), j.at("y").get<double>(), j.at("z").get<double>()};
}

inline std::string schemaText(const std::string& title,
                              const std::string& description,
                              const std::string& properties,
                              const std::string& required)
{
    return jsonSchemaText(title, description, properties, required);
}

// A channel's id, topic, schema name and JSON Schema text.
struct ChannelText {
    std::uint16_t id;
    std::string topic;
    std::string name, schema;
};

// The channels of what was shown (format 4): display digest, thumbnail, transforms, eye, light,
// log.
std::vector<ChannelText> shownChannels();

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

} // namespace replica::recordings
