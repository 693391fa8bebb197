// A booth model on disk: booth.json (poses, SPDs) beside one luminance EXR per light.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <pipeline/base/expected.h>
#include <pipeline/booth/booth_light.h>
#include <pipeline/booth/booth_walls.h>

namespace replica::pipeline::booth {

// The one booth type: its lights (booth.json order; the appliance's lamp index is the index
// into 'lights') with their luminance images, SPDs and, from scene::loadDefaultBooth, the lamp
// fields the state stage uses.
struct Booth {
    std::string id; // "replica-booth-1" from scene::loadDefaultBooth; empty from loadBooth
    std::vector<BoothLight> lights;
    // The booth's walls when booth.json declares them ("walls": {"reflectance": [36 values],
    // optional, default Munsell N7}): the appliance then lights the surface with them too
    // (docs/rendering.md, "The booth's walls"). Their box is the ceiling's down to the floor,
    // deep enough for the stand (scene::defaultBoothWalls fills it in; loadBooth leaves it 0).
    // None: the walls are not modelled (every shipped booth).
    std::optional<BoothWalls> walls;

    // The ceiling, the one emitter of every lamp: the first light's rectangle (loadDefaultBooth
    // checks that all lights share it).
    // Precondition: !lights.empty() (loadBooth refuses a booth without lights).
    const BoothLight& ceiling() const { return lights.front(); }

    // Exact name, or the one light whose name is 'name-...' ("d65" for "d65-fluorescent").
    const BoothLight* find(const std::string& name) const;
    std::string names() const; // "a, b, c" for messages
};

// Reads <dir>/booth.json and the EXRs it names (channel "Y", cd/m^2). Errors name the file and
// field.
Expected<Booth> loadBooth(const std::filesystem::path& dir);

// Writes booth.json and <name>.exr per light into dir (created if needed).
Expected<void> saveBooth(const std::filesystem::path& dir, const Booth& booth);

} // namespace replica::pipeline::booth
