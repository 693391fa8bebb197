// ArgyllCMS's CGATS files for display measurement: .ti1 patch sets (RGB_R/G/B in 0-100) and .ti3
// readings (the same RGB plus XYZ_X/Y/Z), so a set measured with dispread elsewhere imports as it
// is and a set measured here reads in Argyll. Only the first table of a file is read (targen's
// extra tables are skipped). XYZ in a display .ti3 is normalised to white Y = 100 unless
// NORMALIZED_TO_Y_100 is "NO"; LUMINANCE_XYZ_CDM2 then gives white's absolute XYZ (Argyll's own
// reading of the keywords). Files without it (fakeread's, dispread's without -Y) take white's
// luminance from the caller (display fit --white-cdm2), which also wins over the keyword. Counts
// are RGB / 100 x (2^bits - 1), rounded to the nearest count: what a frame buffer of that depth
// shows.
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>

#include <pipeline/base/expected.h>
#include <pipeline/offline/display/measurement_set.h>

namespace replica::pipeline::display {

struct CgatsTable {
    std::string identifier;                                    // CTI1, CTI3
    std::vector<std::pair<std::string, std::string>> keywords; // name, value without quotes
    std::vector<std::string> fields;
    std::vector<std::vector<std::string>> rows;
    std::vector<int> rowLines; // line of each row in the file, for messages

    const std::string* keyword(const std::string& name) const;
    int field(const std::string& name) const; // index, or -1
};

// The first table; errors name source:line.
Expected<CgatsTable> parseCgats(const std::string& text, const std::string& source);
std::string cgatsText(const CgatsTable& table);

// .ti3 readings -> a measurement set at 'bitDepth' (Argyll's RGB carry no depth; 8 unless told).
// whiteCdM2 > 0: white's luminance for readings normalised to white Y = 100 (scale whiteCdM2 /
// 100), in place of LUMINANCE_XYZ_CDM2; 0: the keyword, and an error without it.
Expected<MeasurementSet> parseTi3(const std::string& text,
                                  const std::string& source,
                                  int bitDepth = 8,
                                  double whiteCdM2 = 0.0);
// .ti3 text of readings in absolute cd/m^2: normalised to the brightest reading's Y = 100 with
// LUMINANCE_XYZ_CDM2 set to that reading, as dispread writes it.
std::string
ti3Text(const std::vector<Measurement>& rows, int bitDepth, const std::string& originator);

// .ti1 patch set -> counts at 'bitDepth'.
Expected<std::vector<glm::dvec3>>
parseTi1(const std::string& text, const std::string& source, int bitDepth = 8);
std::string
ti1Text(const std::vector<glm::dvec3>& counts, int bitDepth, const std::string& originator);

// Measurements from a .ti3 (by its extension) or the R,G,B,X,Y,Z CSV. bitDepth 0: the CSV infers
// it, a .ti3 takes 8. whiteCdM2: parseTi3's (a CSV is in cd/m^2 already: an error there).
Expected<MeasurementSet>
loadMeasurements(const std::filesystem::path& path, int bitDepth = 0, double whiteCdM2 = 0.0);
// True for a path that loadMeasurements reads as a .ti3.
bool isTi3Path(const std::filesystem::path& path);

} // namespace replica::pipeline::display
