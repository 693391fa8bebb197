// Display profiles on disk: the fitted model, its fit report, the viewing-angle table and the
// measurement condition, as JSON (data/displays/*.json).
#pragma once

#include <filesystem>
#include <string>

#include <pipeline/base/expected.h>
#include <pipeline/display/display_model.h>

namespace replica::pipeline::display {

std::string profileToJson(const DisplayModel& model);
// 'source' names the file in messages. The model is validated.
Expected<DisplayModel> profileFromJson(const std::string& json, const std::string& source);

Expected<DisplayModel> loadProfile(const std::filesystem::path& path);
Expected<void> saveProfile(const DisplayModel& model, const std::filesystem::path& path);

} // namespace replica::pipeline::display
