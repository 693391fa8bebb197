// A booth model on disk: booth.json (poses, SPDs) beside one luminance EXR per light.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <pipeline/base/expected.h>
#include <pipeline/booth/booth_light.h>

namespace replica::pipeline::booth {

struct BoothModel {
    std::vector<BoothLight> lights;

    // Exact name, or the one light whose name is 'name-...' ("d65" for "d65-fluorescent").
    const BoothLight* find(const std::string& name) const;
    std::string names() const; // "a, b, c" for messages
};

// Reads <dir>/booth.json and the EXRs it names (channel "Y", cd/m^2). Errors name the file and
// field.
Expected<BoothModel> loadBooth(const std::filesystem::path& dir);

// Writes booth.json and <name>.exr per light into dir (created if needed).
Expected<void> saveBooth(const std::filesystem::path& dir, const BoothModel& booth);

} // namespace replica::pipeline::booth
