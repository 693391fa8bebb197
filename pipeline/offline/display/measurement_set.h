// Display measurements: rows of digital counts and the absolute XYZ a meter read for them, from a
// CSV with the columns R,G,B,X,Y,Z (counts at the panel's bit depth, XYZ in cd/m^2).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include <pipeline/base/expected.h>

namespace replica::pipeline::display {

struct Measurement {
    glm::dvec3 counts{0.0};
    glm::dvec3 xyz{0.0};
    int line = 0; // in the source file, for messages
};

struct MeasurementSet {
    std::string source;
    int bitDepth = 8;
    std::vector<Measurement> rows;
};

// '#' comment lines and blank lines are skipped; the first other line must be the header
// R,G,B,X,Y,Z. bitDepth 0 infers it from the largest count (which must then be 2^n - 1, a
// full-drive measurement). Errors name source:line.
Expected<MeasurementSet>
parseMeasurementCsv(const std::string& text, const std::string& source, int bitDepth = 0);
Expected<MeasurementSet> loadMeasurementCsv(const std::filesystem::path& path, int bitDepth = 0);

// A reading's XYZ (cd/m^2) as a display's light can be: Y not below -1e-3 (noise about black), and
// X, Y and Z within 1e5 (ten times the brightest HDR panel: a larger one is a typo or a unit
// mistake, and one near 1e308 overflows the fit). The error names source:line.
Expected<void> checkMeasuredXyz(const glm::dvec3& xyz, const std::string& source, int line);

// CSV text of a measurement set (the header, then one row per measurement), as read back above.
std::string measurementCsv(const std::vector<Measurement>& rows, const std::string& comment);

} // namespace replica::pipeline::display
