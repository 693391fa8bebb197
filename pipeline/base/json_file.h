// Reading a project manifest (booth.json, scene.json): the file read with input_file.h's limits,
// parsed and held against its schema (json_schema.h), and its "format" checked, with errors that
// name the file and say what to do when it is missing.
#pragma once

#include <filesystem>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <pipeline/base/expected.h>
#include <pipeline/base/input_file.h>
#include <pipeline/base/json_schema.h>

namespace replica {

// The checked document of 'file', or one error: NotFound "<file>: cannot open <what>;
// <missingHint>" for a missing file, the reader's or schema's error otherwise, Corrupt
// "<file>: 'format' must be "<format>"" for another format.
inline Expected<nlohmann::json> readJsonManifest(const std::filesystem::path& file,
                                                 const JsonSchema& schema,
                                                 const std::string& what,
                                                 const std::string& missingHint,
                                                 const std::string& format)
{
    auto text = readInputFile(file, kMaxJsonBytes, what);
    if (!text) {
        if (text.error().code == ErrorCode::NotFound) {
            return makeError(ErrorCode::NotFound, fmt::format("{}: cannot open {}; {}",
                                                              file.string(), what, missingHint));
        }
        return tl::unexpected(text.error());
    }
    auto parsed = parseJsonChecked(*text, schema, file.string());
    if (!parsed) {
        return tl::unexpected(parsed.error());
    }
    if (!parsed->contains("format") || (*parsed)["format"] != format) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: 'format' must be \"{}\"", file.string(), format));
    }
    return parsed;
}

} // namespace replica
