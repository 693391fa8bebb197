// One written schema per JSON format the project reads, and the check that holds a document
// against it before any field is read: the offending JSON path is named (e.g.
// "scene.json: /ward/alpha: expected a number in [0, 5], found a string"), non-finite and
// out-of-range numbers are refused, and unknown keys are reported as warnings. Once a document
// has passed, nlohmann's accessors on the fields the schema names cannot throw.
#pragma once

#include <cmath>
#include <cstddef>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <pipeline/base/expected.h>
#include <pipeline/base/json_limits.h>

namespace replica {

struct JsonSchemaField;

struct JsonSchema {
    enum class Type { Any, Object, Array, String, Number, Integer, Bool };
    Type type = Type::Any;
    bool required = true;
    bool nullable = false;
    double min = -std::numeric_limits<double>::max(); // numbers: inclusive range
    double max = std::numeric_limits<double>::max();
    std::size_t minItems = 0; // arrays (and strings: length)
    std::size_t maxItems = std::numeric_limits<std::size_t>::max();
    // Objects: the known keys. A plain struct, not std::pair: clang with libstdc++ refuses a
    // pair of a type still incomplete here (the libFuzzer build, tests/fuzz/run_fuzz.sh).
    std::vector<JsonSchemaField> fields;
    bool openObject = false; // objects: any key, each checked against 'items' (a map)
    std::shared_ptr<const JsonSchema> items; // arrays: every element

    JsonSchema optional() const;
};

struct JsonSchemaField {
    std::string first; // the key
    JsonSchema second; // its schema
};

inline JsonSchema JsonSchema::optional() const
{
    JsonSchema s = *this;
    s.required = false;
    return s;
}

namespace json_schema {

inline JsonSchema any()
{
    return {};
}
inline JsonSchema number(double min = -std::numeric_limits<double>::max(),
                         double max = std::numeric_limits<double>::max())
{
    JsonSchema s;
    s.type = JsonSchema::Type::Number;
    s.min = min;
    s.max = max;
    return s;
}
inline JsonSchema integer(double min, double max)
{
    JsonSchema s = number(min, max);
    s.type = JsonSchema::Type::Integer;
    return s;
}
inline JsonSchema string(std::size_t maxLength = 4096)
{
    JsonSchema s;
    s.type = JsonSchema::Type::String;
    s.maxItems = maxLength;
    return s;
}
inline JsonSchema boolean()
{
    JsonSchema s;
    s.type = JsonSchema::Type::Bool;
    return s;
}
inline JsonSchema array(JsonSchema item, std::size_t minItems, std::size_t maxItems)
{
    JsonSchema s;
    s.type = JsonSchema::Type::Array;
    s.items = std::make_shared<const JsonSchema>(std::move(item));
    s.minItems = minItems;
    s.maxItems = maxItems;
    return s;
}
inline JsonSchema object(std::vector<JsonSchemaField> fields)
{
    JsonSchema s;
    s.type = JsonSchema::Type::Object;
    s.fields = std::move(fields);
    return s;
}
// An object used as a map: any key, each value checked against 'value'.
inline JsonSchema map(JsonSchema value, std::size_t maxKeys)
{
    JsonSchema s;
    s.type = JsonSchema::Type::Object;
    s.openObject = true;
    s.items = std::make_shared<const JsonSchema>(std::move(value));
    s.maxItems = maxKeys;
    return s;
}

inline std::string kindOf(const nlohmann::json& j)
{
    switch (j.type()) {
    case nlohmann::json::value_t::null:
        return "null";
    case nlohmann::json::value_t::object:
        return "an object";
    case nlohmann::json::value_t::array:
        return "an array";
    case nlohmann::json::value_t::string:
        return "a string";
    case nlohmann::json::value_t::boolean:
        return "a boolean";
    case nlohmann::json::value_t::number_integer:
    case nlohmann::json::value_t::number_unsigned:
        return "an integer";
    case nlohmann::json::value_t::number_float:
        return std::isfinite(j.get<double>()) ? "a number" : "a non-finite number";
    default:
        return "something else";
    }
}

inline std::string escapeKey(const std::string& key)
{
    std::string out;
    for (const char c : key) {
        if (c == '~') {
            out += "~0";
        } else if (c == '/') {
            out += "~1";
        } else if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
            out += fmt::format("\\x{:02x}", static_cast<unsigned char>(c));
        } else {
            out += c;
        }
    }
    return out;
}

inline Expected<void> check(const nlohmann::json& j,
                            const JsonSchema& s,
                            const std::string& path,
                            std::vector<std::string>& warnings);

inline Expected<void>
mismatch(const std::string& path, const std::string& expected, const nlohmann::json& j)
{
    return makeError(ErrorCode::Corrupt,
                     fmt::format("{}: expected {}, found {}", path.empty() ? "/" : path, expected,
                                 kindOf(j)));
}

inline Expected<void>
checkNumber(const nlohmann::json& j, const JsonSchema& s, const std::string& path)
{
    const bool integral = s.type == JsonSchema::Type::Integer;
    const std::string expected =
            fmt::format("{} in [{}, {}]", integral ? "an integer" : "a number", s.min, s.max);
    if (!j.is_number() || (integral && !j.is_number_integer())) {
        return mismatch(path, expected, j);
    }
    const double v = j.get<double>();
    if (!std::isfinite(v) || v < s.min || v > s.max) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: expected {}, found {}", path.empty() ? "/" : path,
                                     expected, j.dump()));
    }
    return {};
}

inline Expected<void> checkArray(const nlohmann::json& j,
                                 const JsonSchema& s,
                                 const std::string& path,
                                 std::vector<std::string>& warnings)
{
    const std::string expected =
            s.minItems == s.maxItems
                    ? fmt::format("an array of {} items", s.minItems)
                    : fmt::format("an array of {} to {} items", s.minItems, s.maxItems);
    if (!j.is_array()) {
        return mismatch(path, expected, j);
    }
    if (j.size() < s.minItems || j.size() > s.maxItems) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: expected {}, found {}", path.empty() ? "/" : path,
                                     expected, j.size()));
    }
    for (std::size_t k = 0; k < j.size(); ++k) {
        if (auto ok = check(j[k], *s.items, fmt::format("{}/{}", path, k), warnings); !ok) {
            return ok;
        }
    }
    return {};
}

// An object used as a map: every value against the one item schema.
inline Expected<void> checkMap(const nlohmann::json& j,
                               const JsonSchema& s,
                               const std::string& path,
                               std::vector<std::string>& warnings)
{
    if (j.size() > s.maxItems) {
        return makeError(ErrorCode::Corrupt, fmt::format("{}: more than {} keys",
                                                         path.empty() ? "/" : path, s.maxItems));
    }
    for (const auto& [key, value] : j.items()) {
        if (auto ok = check(value, *s.items, path + "/" + escapeKey(key), warnings); !ok) {
            return ok;
        }
    }
    return {};
}

// An object with named fields: each required one present, each present one checked, and a
// warning for each key the schema does not name.
inline Expected<void> checkFields(const nlohmann::json& j,
                                  const JsonSchema& s,
                                  const std::string& path,
                                  std::vector<std::string>& warnings)
{
    for (const auto& [key, field] : s.fields) {
        const auto it = j.find(key);
        if (it == j.end()) {
            if (field.required) {
                return makeError(ErrorCode::Corrupt,
                                 fmt::format("{}/{}: required but missing", path, key));
            }
            continue;
        }
        if (auto ok = check(*it, field, path + "/" + escapeKey(key), warnings); !ok) {
            return ok;
        }
    }
    for (const auto& [key, value] : j.items()) {
        bool known = false;
        for (const auto& f : s.fields) {
            known = known || f.first == key;
        }
        if (!known) {
            warnings.push_back(fmt::format("{}/{}: unknown key, ignored", path, escapeKey(key)));
        }
    }
    return {};
}

inline Expected<void> check(const nlohmann::json& j,
                            const JsonSchema& s,
                            const std::string& path,
                            std::vector<std::string>& warnings)
{
    using T = JsonSchema::Type;
    if (j.is_null() && s.nullable) {
        return {};
    }
    switch (s.type) {
    case T::Any:
        return {};
    case T::Bool:
        return j.is_boolean() ? Expected<void>{} : mismatch(path, "true or false", j);
    case T::String:
        if (!j.is_string()) {
            return mismatch(path, "a string", j);
        }
        if (j.get_ref<const std::string&>().size() > s.maxItems) {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("{}: string longer than {} characters",
                                         path.empty() ? "/" : path, s.maxItems));
        }
        return {};
    case T::Number:
    case T::Integer:
        return checkNumber(j, s, path);
    case T::Array:
        return checkArray(j, s, path, warnings);
    case T::Object:
        if (!j.is_object()) {
            return mismatch(path, "an object", j);
        }
        return s.openObject ? checkMap(j, s, path, warnings) : checkFields(j, s, path, warnings);
    }
    return {};
}

} // namespace json_schema

// Where unknown-key warnings go when the caller collects none: the platform points it at its
// 'pipeline' logger (the pipeline itself logs nothing); by default they are dropped.
inline std::function<void(const std::string&)>& jsonWarningSink()
{
    static std::function<void(const std::string&)> sink;
    return sink;
}

// Holds 'j' against 's'; errors and warnings start with 'file'. Warnings go to 'warnings' when
// given, else to jsonWarningSink().
inline Expected<void> validateJson(const nlohmann::json& j,
                                   const JsonSchema& s,
                                   const std::string& file,
                                   std::vector<std::string>* warnings = nullptr)
{
    std::vector<std::string> w;
    auto ok = json_schema::check(j, s, "", w);
    for (auto& line : w) {
        if (warnings != nullptr) {
            warnings->push_back(file + ": " + line);
        } else if (jsonWarningSink()) {
            jsonWarningSink()(file + ": " + line);
        }
    }
    if (!ok) {
        return makeError(ok.error().code, file + ": " + ok.error().message);
    }
    return {};
}

// Parses 'text' (the contents of 'file') and holds it against 's': the parsed document, or one
// error naming the file (and the JSON path, for a schema violation). Warnings as validateJson.
inline Expected<nlohmann::json> parseJsonChecked(const std::string& text,
                                                 const JsonSchema& s,
                                                 const std::string& file,
                                                 std::vector<std::string>* warnings = nullptr)
{
    if (auto ok = checkJsonLimits(text, file); !ok) {
        return tl::unexpected(ok.error());
    }
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(text);
    } catch (const nlohmann::json::exception& e) {
        return makeError(ErrorCode::Corrupt, file + ": not valid JSON (" + e.what() + ")");
    }
    if (auto ok = validateJson(j, s, file, warnings); !ok) {
        return tl::unexpected(ok.error());
    }
    return j;
}

} // namespace replica
