// ArgyllCMS CGATS files in and out (hand-written in dispread's and targen's layout, and broken
// ones), and the ICC v2.4 and v4 profiles read back with Little CMS against the model it was
// written from.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include <unistd.h>

#include <pipeline/display/icc_profile.h>
#include <pipeline/display/xyz_difference.h>
#include <pipeline/offline/display/cgats.h>
#include <pipeline/offline/display/synthetic_display.h>

#include <gtest/gtest.h>

#include "display_test_support.h"

namespace replica::pipeline::display {
namespace {

// dispread's layout (keywords declared with KEYWORD, readings normalised to white Y = 100, white's
// absolute XYZ in LUMINANCE_XYZ_CDM2).
const char* kDispreadTi3 = R"(CTI3   

DESCRIPTOR "Argyll Calibration Target chart information 3"
ORIGINATOR "Argyll dispread"
CREATED "Wed Mar 18 11:44:51 2015"
KEYWORD "DEVICE_CLASS"
DEVICE_CLASS "DISPLAY"
KEYWORD "COLOR_REP"
COLOR_REP "RGB_XYZ"
KEYWORD "LUMINANCE_XYZ_CDM2"
LUMINANCE_XYZ_CDM2 "115.999513 125.380126 138.006230"
KEYWORD "NORMALIZED_TO_Y_100"
NORMALIZED_TO_Y_100 "YES"
KEYWORD "TARGET_INSTRUMENT"
TARGET_INSTRUMENT "X-Rite i1 DisplayPro, ColorMunki Display"

NUMBER_OF_FIELDS 7
BEGIN_DATA_FORMAT
SAMPLE_ID RGB_R RGB_G RGB_B XYZ_X XYZ_Y XYZ_Z 
END_DATA_FORMAT

NUMBER_OF_SETS 4
BEGIN_DATA
1 100.00 100.00 100.00 92.51826 100.00 110.0703 
2 0.0000 0.0000 0.0000 0.212340 0.225170 0.346780 
3 50.196 0.0000 0.0000 9.7393 5.5060 1.4095 
4	25	50	75	12.5	14.25	30.0
END_DATA
)";

std::string withLine(std::string text, const std::string& from, const std::string& to)
{
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return at == std::string::npos ? text : text.replace(at, from.size(), to);
}

TEST(Cgats, ReadsDispreadReadingsInAbsoluteUnits)
{
    auto set = parseTi3(kDispreadTi3, "d.ti3");
    ASSERT_TRUE(set.has_value()) << set.error().message;
    ASSERT_EQ(set->rows.size(), 4u);
    EXPECT_EQ(set->bitDepth, 8);
    // White: 100 % -> 255 counts, Y 100 -> the LUMINANCE_XYZ_CDM2 white, 125.380126 cd/m^2.
    EXPECT_EQ(set->rows[0].counts, glm::dvec3(255.0));
    EXPECT_NEAR(set->rows[0].xyz.y, 125.380126, 1e-9);
    EXPECT_NEAR(set->rows[0].xyz.x, 92.51826 * 1.25380126, 1e-9);
    // 50.196 % of 255 is 128.0 (to 0.0002); tab-separated rows read the same.
    EXPECT_EQ(set->rows[2].counts, glm::dvec3(128.0, 0.0, 0.0));
    EXPECT_EQ(set->rows[3].counts, glm::dvec3(64.0, 128.0, 191.0)); // 63.75, 127.5, 191.25 rounded
    EXPECT_NEAR(set->rows[3].xyz.z, 30.0 * 1.25380126, 1e-9);
    EXPECT_EQ(set->rows[2].line, 26);
    // At 10 bits the same percentages are other counts.
    auto ten = parseTi3(kDispreadTi3, "d.ti3", 10);
    ASSERT_TRUE(ten.has_value());
    EXPECT_EQ(ten->rows[2].counts.x, std::round(0.50196 * 1023.0));
    // Readings already in cd/m^2.
    auto abs = parseTi3(
            withLine(kDispreadTi3, "NORMALIZED_TO_Y_100 \"YES\"", "NORMALIZED_TO_Y_100 \"NO\""),
            "d.ti3");
    ASSERT_TRUE(abs.has_value());
    EXPECT_DOUBLE_EQ(abs->rows[0].xyz.y, 100.0);
}

// fakeread's layout (and dispread's without -Y): relative XYZ, white Y = 100, neither
// LUMINANCE_XYZ_CDM2 nor NORMALIZED_TO_Y_100.
const char* kFakereadTi3 = R"(CTI3   

DESCRIPTOR "Argyll Calibration Target chart information 3"
ORIGINATOR "Argyll fakeread"
CREATED "Sun Dec  6 09:02:17 2026"
DEVICE_CLASS "DISPLAY"
COLOR_REP "RGB_XYZ"

NUMBER_OF_FIELDS 7
BEGIN_DATA_FORMAT
SAMPLE_ID RGB_R RGB_G RGB_B XYZ_X XYZ_Y XYZ_Z 
END_DATA_FORMAT

NUMBER_OF_SETS 2
BEGIN_DATA
1 100 100 100 95.0455 100 108.905 
2 12.871 13.5316 33.7491 2.89009 2.16636 9.08295 
END_DATA
)";

TEST(Cgats, RelativeReadingsTakeWhitesLuminanceFromTheCaller)
{
    auto none = parseTi3(kFakereadTi3, "f.ti3");
    ASSERT_FALSE(none.has_value());
    EXPECT_NE(none.error().message.find("f.ti3: XYZ normalised to white Y = 100 and no usable "
                                        "LUMINANCE_XYZ_CDM2"),
              std::string::npos);
    EXPECT_NE(none.error().message.find("--white-cdm2 VALUE"), std::string::npos)
            << none.error().message;
    auto set = parseTi3(kFakereadTi3, "f.ti3", 8, 250.0);
    ASSERT_TRUE(set.has_value()) << set.error().message;
    EXPECT_DOUBLE_EQ(set->rows[0].xyz.y, 250.0);
    EXPECT_DOUBLE_EQ(set->rows[1].xyz.z, 9.08295 * 2.5);
    // Given both, the caller's luminance wins over the file's keyword.
    auto both = parseTi3(kDispreadTi3, "d.ti3", 8, 250.0);
    ASSERT_TRUE(both.has_value());
    EXPECT_DOUBLE_EQ(both->rows[0].xyz.y, 250.0);
    // Readings in cd/m^2 are not scaled again.
    auto abs = parseTi3(
            withLine(kDispreadTi3, "NORMALIZED_TO_Y_100 \"YES\"", "NORMALIZED_TO_Y_100 \"NO\""),
            "d.ti3", 8, 250.0);
    ASSERT_TRUE(abs.has_value());
    EXPECT_DOUBLE_EQ(abs->rows[0].xyz.y, 100.0);
}

TEST(Cgats, MalformedFilesFailNamingTheLine)
{
    auto err = [](const std::string& text) {
        auto s = parseTi3(text, "d.ti3");
        EXPECT_FALSE(s.has_value());
        return s ? std::string() : s.error().message;
    };
    EXPECT_EQ(err(""), "d.ti3: empty file");
    EXPECT_NE(err("R,G,B,X,Y,Z\n0,0,0,1,1,1\n").find("d.ti3:1: not a CGATS file"),
              std::string::npos);
    EXPECT_EQ(err(withLine(kDispreadTi3, "END_DATA\n", "")),
              "d.ti3:23: BEGIN_DATA without END_DATA (the file is cut short)");
    EXPECT_EQ(err(withLine(kDispreadTi3, "3 50.196 0.0000 0.0000 9.7393 5.5060 1.4095",
                           "3 50.196 0.0000 0.0000 9.7393 5.5060")),
              "d.ti3:26: 6 values, expected 7 (SAMPLE_ID RGB_R RGB_G RGB_B XYZ_X XYZ_Y XYZ_Z)");
    EXPECT_EQ(err(withLine(kDispreadTi3, "9.7393 5.5060", "9.7393 abc")),
              "d.ti3:26: XYZ_Y 'abc' is not a finite number");
    EXPECT_EQ(err(withLine(kDispreadTi3, "3 50.196", "3 150.2")),
              "d.ti3:26: RGB_R '150.2' is not a number in 0-100");
    EXPECT_EQ(err(withLine(kDispreadTi3, "NUMBER_OF_SETS 4", "NUMBER_OF_SETS 5")),
              "d.ti3:28: NUMBER_OF_SETS is 5 but the data has 4 rows");
    EXPECT_EQ(err(withLine(kDispreadTi3, "NUMBER_OF_FIELDS 7", "NUMBER_OF_FIELDS 6")),
              "d.ti3:18: NUMBER_OF_FIELDS is 6 but the format lists 7 fields");
    EXPECT_NE(err(withLine(kDispreadTi3, "LUMINANCE_XYZ_CDM2 \"115.999513 125.380126 138.006230\"",
                           ""))
                      .find("d.ti3: XYZ normalised to white Y = 100 and no usable "
                            "LUMINANCE_XYZ_CDM2"),
              std::string::npos);
    EXPECT_EQ(err(withLine(kDispreadTi3, "COLOR_REP \"RGB_XYZ\"", "COLOR_REP \"CMYK_XYZ\"")),
              "d.ti3: COLOR_REP is 'CMYK_XYZ', a display's readings are RGB_XYZ");
    EXPECT_EQ(err(withLine(kDispreadTi3, "DEVICE_CLASS \"DISPLAY\"", "DEVICE_CLASS \"DISPLAY")),
              "d.ti3:7: unterminated quoted string");
    // A patch set is not a set of readings.
    const std::string ti1 = ti1Text({glm::dvec3(0.0), glm::dvec3(255.0)}, 8, "test");
    EXPECT_NE(err(ti1).find("no XYZ_X, XYZ_Y and XYZ_Z fields"), std::string::npos);
}

TEST(Cgats, WritesWhatItAndArgyllRead)
{
    const auto rows = syntheticMeasurements(wideIpsGroundTruth(), MeterNoise{}, 1);
    const std::string text = ti3Text(rows, 8, "Replica test");
    EXPECT_EQ(text.rfind("CTI3\n", 0), 0u);
    EXPECT_NE(text.find("NORMALIZED_TO_Y_100 \"YES\""), std::string::npos);
    auto back = parseTi3(text, "w.ti3");
    ASSERT_TRUE(back.has_value()) << back.error().message;
    ASSERT_EQ(back->rows.size(), rows.size());
    for (std::size_t i = 0; i < rows.size(); ++i) {
        EXPECT_EQ(back->rows[i].counts, rows[i].counts);
        for (int k = 0; k < 3; ++k) {
            EXPECT_NEAR(back->rows[i].xyz[k], rows[i].xyz[k],
                        1e-6 * std::abs(rows[i].xyz[k]) + 1e-9);
        }
    }
}

TEST(Cgats, ReadsTargenPatchSetsFirstTableOnly)
{
    // targen's layout: keywords without KEYWORD lines, then two more tables that are not patches.
    const std::string ti1 = R"(CTI1   

DESCRIPTOR "Argyll Calibration Target chart information 1"
ORIGINATOR "Argyll targen"
APPROX_WHITE_POINT "95.106486 100.000000 108.844025"
COLOR_REP "RGB"

NUMBER_OF_FIELDS 7
BEGIN_DATA_FORMAT
SAMPLE_ID RGB_R RGB_G RGB_B XYZ_X XYZ_Y XYZ_Z 
END_DATA_FORMAT

NUMBER_OF_SETS 3
BEGIN_DATA
1 100 100 100 95.1065 100 108.844 
2 19.6364 82.5733 50.7752 29.216 49.1596 29.5425 
3 0.00000 25 0.00000 2.80128 4.60205 1.60043 
END_DATA
CTI1   

DESCRIPTOR "Argyll Calibration Target chart information 1"
COLOR_REP "RGB"
NUMBER_OF_FIELDS 4
BEGIN_DATA_FORMAT
INDEX RGB_R RGB_G RGB_B 
END_DATA_FORMAT
NUMBER_OF_SETS 1
BEGIN_DATA
0 0.1 0.1 0.1
END_DATA
)";
    auto p = parseTi1(ti1, "t.ti1");
    ASSERT_TRUE(p.has_value()) << p.error().message;
    ASSERT_EQ(p->size(), 3u);
    EXPECT_EQ((*p)[0], glm::dvec3(255.0));
    // 19.6364 % of 255 = 50.07, 82.5733 % = 210.56, 50.7752 % = 129.48.
    EXPECT_EQ((*p)[1], glm::dvec3(50.0, 211.0, 129.0));
    EXPECT_EQ((*p)[2], glm::dvec3(0.0, 64.0, 0.0));
    auto back = parseTi1(ti1Text(*p, 8, "Replica test"), "w.ti1");
    ASSERT_TRUE(back.has_value()) << back.error().message;
    EXPECT_EQ(*back, *p);
    auto cmyk = parseTi1(withLine(ti1, "COLOR_REP \"RGB\"", "COLOR_REP \"CMYK\""), "t.ti1");
    ASSERT_FALSE(cmyk.has_value());
    EXPECT_EQ(cmyk.error().message, "t.ti1: COLOR_REP is 'CMYK', a display patch set is RGB");
}

// targen 2.3.1's own output ('targen -d3 -f200', its first table cut to 3 rows; the two more
// tables as written), read through lcms2's IT8 parser.
const char* kTargenTi1 = R"(CTI1   

DESCRIPTOR "Argyll Calibration Target chart information 1"
ORIGINATOR "Argyll targen"
CREATED "Sun Dec  6 09:02:14 2026"
APPROX_WHITE_POINT "95.106486 100.000000 108.844025"
COLOR_REP "RGB"
WHITE_COLOR_PATCHES "4"
BLACK_COLOR_PATCHES "4"
OFPS_PATCHES "192"

NUMBER_OF_FIELDS 7
BEGIN_DATA_FORMAT
SAMPLE_ID RGB_R RGB_G RGB_B XYZ_X XYZ_Y XYZ_Z 
END_DATA_FORMAT

NUMBER_OF_SETS 3
BEGIN_DATA
1 100 100 100 95.1065 100 108.844 
2 12.871 13.5316 33.7491 3.86155 3.14471 9.99463 
3 74.6785 11.7314 48.1323 26.1118 14.2192 20.7011 
END_DATA
CTI1   

DESCRIPTOR "Argyll Calibration Target chart information 1"
ORIGINATOR "Argyll targen"
DENSITY_EXTREME_VALUES "8"
CREATED "December 6, 2026"

NUMBER_OF_FIELDS 7
BEGIN_DATA_FORMAT
INDEX RGB_R RGB_G RGB_B XYZ_X XYZ_Y XYZ_Z 
END_DATA_FORMAT

NUMBER_OF_SETS 8
BEGIN_DATA
0 100 100 100 95.1065 100 108.844 
1 0.00000 47.3607 100 25.613 21.6292 97.3763 
2 100 0.00000 79.3514 52.4258 26.2898 58.7215 
3 0.00000 0.00000 58.9971 6.48583 3.19399 29.8945 
4 100 66.6593 0.00000 56.0588 50.5054 7.65614 
5 0.00000 35.6011 0.00000 4.68562 8.37021 2.22855 
6 84.4444 0.00000 0.00000 28.8428 15.3558 2.30466 
7 0.00000 0.00000 0.00000 1 1 1 
END_DATA
CTI1   

DESCRIPTOR "Argyll Calibration Target chart information 1"
ORIGINATOR "Argyll targen"
DEVICE_COMBINATION_VALUES "9"
CREATED "December 6, 2026"

NUMBER_OF_FIELDS 7
BEGIN_DATA_FORMAT
INDEX RGB_R RGB_G RGB_B XYZ_X XYZ_Y XYZ_Z 
END_DATA_FORMAT

NUMBER_OF_SETS 9
BEGIN_DATA
0 100 100 100 95.1065 100 108.844 
1 0.00000 100 100 54.2763 78.9478 106.931 
2 100 0.00000 100 59.7013 29.1995 97.0422 
3 0.00000 0.00000 100 18.8711 8.14731 95.129 
4 100 100 0.00000 77.2354 92.8527 14.7151 
5 0.00000 100 0.00000 36.4052 71.8005 12.8018 
6 100 0.00000 0.00000 41.8302 22.0522 2.91323 
7 0.00000 0.00000 0.00000 1 1 1 
8 50 50 50 21.1427 22.1901 24.0831 
END_DATA
)";

TEST(Cgats, ReadsTargensThreeTableFileThroughLcms)
{
    auto p = parseTi1(kTargenTi1, "t.ti1");
    ASSERT_TRUE(p.has_value()) << p.error().message;
    ASSERT_EQ(p->size(), 3u);
    EXPECT_EQ((*p)[0], glm::dvec3(255.0));
    // 12.871, 13.5316, 33.7491 % of 255.
    EXPECT_EQ((*p)[1], glm::dvec3(33.0, 35.0, 86.0));
    auto t = parseCgats(kTargenTi1, "t.ti1");
    ASSERT_TRUE(t.has_value());
    EXPECT_EQ(t->identifier, "CTI1");
    ASSERT_NE(t->keyword("APPROX_WHITE_POINT"), nullptr);
    EXPECT_EQ(*t->keyword("APPROX_WHITE_POINT"), "95.106486 100.000000 108.844025");
    EXPECT_EQ(t->keyword("NUMBER_OF_SETS"), nullptr); // the layout, not a keyword
    EXPECT_EQ(t->field("XYZ_Z"), 6);
    EXPECT_EQ(t->rowLines, (std::vector<int>{19, 20, 21}));
    // What lcms2 itself refuses comes back with its line: a later table's count (lcms2 names the
    // line after that table's END_DATA, 69).
    auto later = parseTi1(withLine(kTargenTi1, "NUMBER_OF_SETS 9", "NUMBER_OF_SETS 10"), "t.ti1");
    ASSERT_FALSE(later.has_value());
    EXPECT_EQ(later.error().message, "t.ti1:70: Count mismatch. NUMBER_OF_SETS was 10, found 9");
    // lcms2 follows .INCLUDE to another file: refused, wherever it is.
    auto include = parseTi1(
            withLine(kTargenTi1, "DEVICE_COMBINATION_VALUES \"9\"", ".INCLUDE \"/etc/passwd\""),
            "t.ti1");
    ASSERT_FALSE(include.has_value());
    EXPECT_EQ(include.error().message,
              "t.ti1:50: .INCLUDE is not followed: give the readings in one file");
    // And what it writes, it and Argyll read back (fakeread in interop.argyll_profile).
    auto back = parseTi1(ti1Text(*p, 8, "Replica test"), "w.ti1");
    ASSERT_TRUE(back.has_value()) << back.error().message;
    EXPECT_EQ(*back, *p);
}

TEST(IccProfile, BradfordMatchesThePublishedMatrix)
{
    // Lindbloom's Bradford D65 -> D50 matrix (brucelindbloom.com, chromatic adaptation).
    const glm::dmat3 m = bradfordToD50(glm::dvec3(0.95047, 1.0, 1.08883));
    const double want[3][3] = {{1.0478112, 0.0228866, -0.0501270},
                               {0.0295424, 0.9904844, -0.0170491},
                               {-0.0092345, 0.0150436, 0.7521316}};
    // Lindbloom's D50 is (0.96422, 1, 0.82521), the ICC PCS's (0.9642, 1, 0.8249): entries agree
    // to the 4e-4 that difference makes.
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) {
            EXPECT_NEAR(m[c][r], want[r][c], 6e-4) << r << "," << c;
        }
    }
    const glm::dvec3 white = m * glm::dvec3(0.95047, 1.0, 1.08883);
    EXPECT_NEAR(white.x, 0.9642, 1e-12);
    EXPECT_NEAR(white.y, 1.0, 1e-12);
    EXPECT_NEAR(white.z, 0.8249, 1e-12);
}

TEST(IccProfile, ReadsBackAsTheModelThroughLittleCms)
{
    // The synthetic IPS panel's fit has a crosstalk term (0.5 % loss at white), which a
    // matrix/TRC profile cannot hold: the profile is the model's additive part, and says so.
    const DisplayModel& fitted = test::fittedSyntheticIps();
    ASSERT_TRUE(fitted.hasCrosstalk());
    DisplayModel model = fitted;
    model.crosstalk = glm::dmat3(0.0);
    const auto path = std::filesystem::temp_directory_path() /
                      ("replica_icc_" + std::to_string(::getpid()) + ".icc");
    auto withCrosstalk = writeIccProfile(fitted, path);
    ASSERT_TRUE(withCrosstalk.has_value()) << withCrosstalk.error().message;
    EXPECT_TRUE(withCrosstalk->crosstalkOmitted);
    // v2.4 by default (ArgyllCMS 2.3 refuses v4): wtpt is the display's own white (Y = 1), not
    // D50, and relative colorimetric reads the same as from v4.
    auto written = writeIccProfile(model, path);
    ASSERT_TRUE(written.has_value()) << written.error().message;
    EXPECT_FALSE(written->blackClipped);
    EXPECT_FALSE(written->crosstalkOmitted);
    auto info = readIccInfo(path);
    ASSERT_TRUE(info.has_value()) << info.error().message;
    EXPECT_DOUBLE_EQ(info->version, 2.4);
    EXPECT_TRUE(info->displayClass);
    EXPECT_TRUE(info->rgbToXyz);
    EXPECT_NEAR(info->luminanceCdM2, model.whiteXyz().y, 1e-3 * model.whiteXyz().y);
    EXPECT_EQ(info->description, model.name);
    const glm::dvec3 ownWhite = model.whiteXyz() / model.whiteXyz().y;
    for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(info->mediaWhite[k], ownWhite[k], 1e-4) << k; // s15Fixed16
    }
    const auto v4path = path.string() + ".v4.icc";
    ASSERT_TRUE(writeIccProfile(model, v4path, IccVersion::V4_3).has_value());
    auto v4 = readIccInfo(v4path);
    ASSERT_TRUE(v4.has_value()) << v4.error().message;
    EXPECT_GE(v4->version, 4.0);
    EXPECT_NEAR(v4->mediaWhite.x, 0.9642, 1e-4); // v4: the PCS's D50
    EXPECT_NEAR(v4->mediaWhite.z, 0.8249, 1e-4);
    EXPECT_EQ(v4->description, model.name);

    std::vector<glm::dvec3> counts{glm::dvec3(0.0), glm::dvec3(255.0)};
    std::mt19937_64 rng(5);
    for (int i = 0; i < 2000; ++i) {
        counts.emplace_back(rng() % 256, rng() % 256, rng() % 256);
    }
    for (int v = 1; v < 256; v += 2) {
        counts.emplace_back(v, 0, 0);
        counts.emplace_back(0, v, 0);
        counts.emplace_back(0, 0, v);
    }
    auto xyz = iccForward(path, counts, 8);
    auto xyz4 = iccForward(v4path, counts, 8);
    std::filesystem::remove(path);
    std::filesystem::remove(v4path);
    ASSERT_TRUE(xyz.has_value()) << xyz.error().message;
    ASSERT_TRUE(xyz4.has_value()) << xyz4.error().message;
    const glm::dvec3 white = model.whiteXyz();
    const glm::dmat3 adapt = bradfordToD50(white);
    const glm::dvec3 d50(0.9642, 1.0, 0.8249);
    double worstDe = 0.0;
    double worstY = 0.0;
    for (std::size_t i = 0; i < counts.size(); ++i) {
        const glm::dvec3 want = adapt * (model.forward(counts[i]) / white.y);
        for (const auto* got : {&*xyz, &*xyz4}) {
            worstDe = std::max(worstDe, deltaE2000Xyz((*got)[i], want, d50));
            worstY = std::max(worstY, std::abs((*got)[i].y - want.y));
        }
    }
    // The curv tags hold 16-bit values and the colorants s15Fixed16 numbers: 1/65535 of white.
    RecordProperty("icc_max_de00", std::to_string(worstDe));
    EXPECT_LT(worstDe, 0.05);
    EXPECT_LT(worstY, 5e-5);
}

} // namespace
} // namespace replica::pipeline::display
