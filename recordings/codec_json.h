// What the codecs of recordings/sample_codec.h share: JSON helpers, attaching raw inputs to
// their samples, and the channels of what was shown (format 4, shown_codec.cpp). Not for use
// outside recordings/.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>
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

// Field `key` of `j`, an integer as Replica writes it: a JSON integer that fits T. (get<T>() would
// take 3.5 as 3, 1e29 as whatever the cast makes of it, and 18446744073709551615 as -1 for an
// int64_t: values no Replica build wrote, that the reader would otherwise use.)
template <typename T>
T integerValue(const json& v, std::string_view what)
{
    if (v.is_number_unsigned()) {
        const auto u = v.get<std::uint64_t>();
        if (std::in_range<T>(u)) {
            return static_cast<T>(u);
        }
    } else if (v.is_number_integer()) {
        const auto i = v.get<std::int64_t>();
        if (std::in_range<T>(i)) {
            return static_cast<T>(i);
        }
    } else {
        throw std::out_of_range(fmt::format("{}: expected an integer, found {} {}", what,
                                            v.type_name(), v.dump().substr(0, 40)));
    }
    throw std::out_of_range(fmt::format("{}: {} is out of range [{}, {}]", what, v.dump(),
                                        std::numeric_limits<T>::min(),
                                        std::numeric_limits<T>::max()));
}
template <typename T>
T integerField(const json& j, const char* key)
{
    return integerValue<T>(j.at(key), key);
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
