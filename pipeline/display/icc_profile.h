// The display model as an ICC display profile (written with Little CMS 2), v2.4 by default (what
// ArgyllCMS 2.3's iccdump, xicclu and profcheck read: they refuse v4) or v4.3: matrix/TRC, the
// black offset folded into the tone curves. The model is additive, XYZ = XYZ_k + M r(d); with
// b = M^-1 XYZ_k (the black in channel units, all >= 0 when black's chromaticity lies inside the
// primaries' triangle) it is XYZ = M diag(1 + b) TRC(d) with TRC_c = (r_c + b_c) / (1 + b_c), which
// a matrix/TRC profile holds exactly. The colorants are adapted to the D50 PCS with Bradford (a
// chad tag records it) and white's absolute luminance goes in the lumi tag. The media white point
// (wtpt) is the v4 rule's D50 in v4; in v2 it is the display's own white relative to Y = 1, not
// adapted (the v2 convention Argyll's colprof follows), so that absolute colorimetric gives the
// display's white back. The description is a textDescription in v2, a multiLocalizedUnicode in v4
// (lcms2 writes the type the version asks for). A crosstalk term
// (DisplayModel::crosstalk) does not fit the matrix/TRC form: the profile holds the additive part
// (C = 0) and the report says so.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <pipeline/base/expected.h>
#include <pipeline/display/display_model.h>

namespace replica::pipeline::display {

struct IccWriteReport {
    glm::dvec3 blackChannels{0.0}; // b = M^-1 XYZ_k
    bool blackClipped = false;     // some b_c < 0 was set to 0 (black outside the triangle)
    bool crosstalkOmitted = false; // the model's crosstalk term is not in the profile
};

enum class IccVersion { V2_4, V4_3 };

Expected<IccWriteReport> writeIccProfile(const DisplayModel& model,
                                         const std::filesystem::path& path,
                                         IccVersion version = IccVersion::V2_4);

// The same profile in memory, its tone curves as 'trcSamples' 16-bit entries over the count range:
// 256 entries are exact at every value of an 8-bit image's pixels (a PNG's iCCP chunk). Its
// creation date is fixed at 1970-01-01 00:00:00: the same model gives the same bytes. v4 (the PNGs
// that embed it were made with v4; every PNG reader takes it).
Expected<std::vector<std::uint8_t>> iccProfileBytes(const DisplayModel& model,
                                                    int trcSamples = 256,
                                                    IccVersion version = IccVersion::V4_3);

// Bradford adaptation matrix from 'white' (any scale) to D50 (X 0.9642, Y 1, Z 0.8249).
glm::dmat3 bradfordToD50(const glm::dvec3& white);

// What Little CMS reads back from a profile's header and tags.
struct IccInfo {
    double version = 0.0; // e.g. 4.3
    bool displayClass = false;
    bool rgbToXyz = false; // colour space RGB, PCS XYZ
    double luminanceCdM2 = 0.0;
    glm::dvec3 mediaWhite{0.0}; // the wtpt tag as written (lcms2's reader substitutes D50 in v2)
    std::string description;
};
Expected<IccInfo> readIccInfo(const std::filesystem::path& path);

// Relative colorimetric RGB -> PCS XYZ (D50, white Y = 1) of a profile read back with Little CMS,
// for counts at 'bitDepth': the check that the file says what the model says.
Expected<std::vector<glm::dvec3>>
iccForward(const std::filesystem::path& path, const std::vector<glm::dvec3>& counts, int bitDepth);

} // namespace replica::pipeline::display
