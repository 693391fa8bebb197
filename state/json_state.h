// Helpers for the estimators' saved state (scene_estimator.h: save/restore): optional values as
// JSON null, and checked reads that throw std::exception with a one-line reason.
#pragma once

#include <cmath>
#include <optional>
#include <stdexcept>

#include <fmt/format.h>
#include <glm/vec3.hpp>
#include <nlohmann/json.hpp>

#include <pipeline/colour/spectrum.h>

namespace replica::state {

template <typename T>
nlohmann::json optionalJson(const std::optional<T>& v)
{
    return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
}

template <typename T>
std::optional<T> optionalFromJson(const nlohmann::json& j)
{
    if (j.is_null()) {
        return std::nullopt;
    }
    return j.get<T>();
}

inline double finiteFromJson(const nlohmann::json& j)
{
    const double v = j.get<double>();
    if (!std::isfinite(v)) {
        throw std::out_of_range(fmt::format("{} is not a finite number", j.dump()));
    }
    return v;
}

inline pipeline::colour::Spectrum spectrumFromJson(const nlohmann::json& j)
{
    pipeline::colour::Spectrum s;
    if (!j.is_array() || j.size() != s.v.size()) {
        throw std::out_of_range(fmt::format("a spectrum needs {} numbers", s.v.size()));
    }
    for (std::size_t i = 0; i < s.v.size(); ++i) {
        s.v[i] = finiteFromJson(j[i]);
    }
    return s;
}

inline nlohmann::json vec3Json(const glm::dvec3& v)
{
    return nlohmann::json::array({v.x, v.y, v.z});
}

inline glm::dvec3 vec3FromJson(const nlohmann::json& j)
{
    if (!j.is_array() || j.size() != 3) {
        throw std::out_of_range("a position needs 3 numbers");
    }
    return {finiteFromJson(j[0]), finiteFromJson(j[1]), finiteFromJson(j[2])};
}

} // namespace replica::state
