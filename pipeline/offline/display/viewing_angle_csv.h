// Reading a viewing-angle measurement: the panel's full white measured at angles off its normal,
// as a CSV with the columns angle_deg,X,Y,Z (XYZ in cd/m^2, the first row at 0 deg), turned into
// the ViewingAngleTable a profile carries.
#pragma once

#include <filesystem>
#include <string>

#include <pipeline/base/expected.h>
#include <pipeline/display/viewing_angle.h>

namespace replica::pipeline::display {

// '#' comments and blank lines skipped; errors name source:line.
Expected<ViewingAngleTable> parseViewingAngleCsv(const std::string& text,
                                                 const std::string& source);
Expected<ViewingAngleTable> loadViewingAngleCsv(const std::filesystem::path& path);

} // namespace replica::pipeline::display
