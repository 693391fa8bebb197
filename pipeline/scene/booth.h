// The appliance's booth (booth::Booth with its lamps' reference spectra and nominal luminances).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <pipeline/base/expected.h>
#include <pipeline/booth/booth_light.h>
#include <pipeline/booth/booth_model.h>
#include <pipeline/booth/booth_walls.h>
#include <pipeline/scene/stand.h>

namespace replica::pipeline::scene {

// The booth the appliance ships with: the booth model dataDir/booth/booth.json, whose lights are
// the lamps in its order (tungsten, d50-fluorescent, d65-fluorescent: the lamp index is the index
// into 'lights'), each given by name its CIE reference spectrum (tungsten CIE A, D50 fluorescent
// simulator CIE F8, D65 fluorescent simulator CIE F7, read from dataDir/spectra) and nominal
// luminance. Booth frame: right-handed, metres; origin on the booth floor at its centre, x to the
// right, y up, z out of the booth towards the viewer. Fails, naming booth.json, when a light is
// not a lamp this build knows or when the lights do not share one ceiling (the appliance's booth
// has one emitter, booth::Booth::ceiling(), whichever lamp it shows).
Expected<booth::Booth> loadDefaultBooth(const std::string& dataDir);

// The same for the booth model in 'boothDir' (one 'replica booth build' made from a site's
// captures): its lights must be named after lamps this build knows and share one ceiling, as
// above; the reference spectra come from dataDir/spectra.
Expected<booth::Booth> loadApplianceBooth(const std::filesystem::path& boothDir,
                                          const std::string& dataDir);

// The booth's walls as the appliance models them (booth::defaultWalls: N7, the box under the
// ceiling), the back wall 5 cm behind the furthest the stand's panel reaches when tilted back.
booth::BoothWalls defaultBoothWalls(const booth::BoothLight& ceiling, const StandModel& stand = {});

// A booth read by booth::loadBooth declares its walls' reflectance only: give them the box
// defaultBoothWalls makes (what loadApplianceBooth does), keeping the reflectance. No walls: no
// change.
void placeBoothWalls(booth::Booth& booth, const StandModel& stand = {});

} // namespace replica::pipeline::scene
