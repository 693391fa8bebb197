// Tests of 'replica color de2000' and 'replica spectral eval' run as the built binary, and of the
// channel-data file formats: bad files must fail naming file, line and problem.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <pipeline/base/data_dir.h>
#include <pipeline/colour/channel_basis.h>
#include <pipeline/colour/spectral_table.h>
#include <pipeline/offline/spectral/accuracy.h>
#include <pipeline/spectral/representation_catalogue.h>
#include <pipeline/spectral/six_channel_model.h>

#include <gtest/gtest.h>

#include "../support/cli.h"
#include "../support/temp_dir.h"

namespace replica::pipeline::spectral {
namespace {

using CliFiles = tests::TempDirTest;
using tests::runReplica;

TEST_F(CliFiles, De2000PrintsRowsWithTheirDifference)
{
    const auto f = write("pairs.csv", "L1,a1,b1,L2,a2,b2\n50,2.6772,-79.7751,50,0,-82.7485\n"
                                      "50,2.5,0,73,25,-18\n");
    const auto r = runReplica("color de2000 " + f, dir_);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    // Sharma et al. 2005 pairs 1 and 17: the rows come back as given, with de00 appended.
    const std::string head = "L1,a1,b1,L2,a2,b2,de00\n50,2.6772,-79.7751,50,0,-82.7485,";
    ASSERT_EQ(r.out.substr(0, head.size()), head);
    const auto row2 = r.out.find("50,2.5,0,73,25,-18,");
    ASSERT_NE(row2, std::string::npos);
    EXPECT_NEAR(std::stod(r.out.substr(head.size())), 2.0425, 1e-4);
    EXPECT_NEAR(std::stod(r.out.substr(row2 + 19)), 27.1492, 1e-4);
    const auto j = runReplica("color de2000 --json " + f, dir_);
    ASSERT_EQ(j.exitCode, 0);
    const auto doc = nlohmann::json::parse(j.out);
    EXPECT_NEAR(doc["pairs"][1]["de00"].get<double>(), 27.1492, 1e-4);
}

TEST_F(CliFiles, De2000BadFilesNameFileLineAndProblem)
{
    const auto cell = write("cell.csv", "L1,a1,b1,L2,a2,b2\n50,1,1,50,1,1\n50,x,1,50,1,1\n");
    auto r = runReplica("color de2000 " + cell, dir_);
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_EQ(r.err, "replica color de2000: " + cell +
                             ":3: column 'a1' value 'x' is not a finite number\n");
    const auto header = write("header.csv", "# pairs\nL1,a1,b1,L2,a2\n");
    r = runReplica("color de2000 " + header, dir_);
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find(header + ":2: header has no column 'b2'"), std::string::npos) << r.err;
    const auto shortRow = write("short.csv", "L1,a1,b1,L2,a2,b2\n50,1,1,50,1\n");
    r = runReplica("color de2000 " + shortRow, dir_);
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find(shortRow + ":2: 5 cells, expected 6"), std::string::npos) << r.err;
    r = runReplica("color de2000 " + (dir_ / "missing.csv").string(), dir_);
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find("missing.csv: cannot open"), std::string::npos) << r.err;
}

// Values the formula cannot take (L* = 1e200 printed -nan, exit 0) are refused naming the file,
// line and column; L* a little above 100 is a highlight, not an error.
TEST_F(CliFiles, De2000RefusesValuesOutOfRangeNamingLineAndColumn)
{
    const std::string head = "L1,a1,b1,L2,a2,b2\n50,1,1,50,1,1\n";
    const auto ok = write("ok.csv", "L1,a1,b1,L2,a2,b2\n100.5,0,0,0,-999,999\n");
    EXPECT_EQ(runReplica("color de2000 " + ok, dir_).exitCode, 0);
    struct Case {
        const char* row;
        const char* expect;
    };
    for (const auto& c :
         {Case{"1e200,0,0,50,0,0", ":3: column 'L1' value '1e200' is outside [0, 1000]"},
          Case{"50,0,0,-1,0,0", ":3: column 'L2' value '-1' is outside [0, 1000]"},
          Case{"50,0,1001,50,0,0", ":3: column 'b1' value '1001' is outside [-1000, 1000]"}}) {
        const auto f = write("range.csv", head + c.row + "\n");
        for (const char* json : {"", "--json "}) {
            const auto r = runReplica(std::string("color de2000 ") + json + f, dir_);
            EXPECT_EQ(r.exitCode, 1) << c.row;
            EXPECT_NE(r.err.find(f + c.expect), std::string::npos) << r.err;
            EXPECT_EQ(r.out.find("nan"), std::string::npos) << r.out;
        }
    }
}

// A cell quoted in an error message is escaped and cut (pipeline/csv/csv_cells.h, shownCell):
// a terminal escape in the file is shown, never run; a NUL does not cut the message short; a
// 1 MB cell is not a 1 MB message.
TEST_F(CliFiles, De2000QuotesABadCellEscapedAndCut)
{
    const std::string head = "L1,a1,b1,L2,a2,b2\n";
    auto f = write("esc.csv", head + "\x1b[2J\x1b]0;pwned\x07,0,0,50,0,0\n");
    auto r = runReplica("color de2000 " + f, dir_);
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_EQ(r.err.find('\x1b'), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(":2: column 'L1' value '\\x1b[2J\\x1b]0;pwned\\x07' is not a finite"),
              std::string::npos)
            << r.err;
    static const char kNul[] = "5\0"
                               "0,0,0,50,0,0\n";
    f = write("nul.csv", head + std::string(kNul, sizeof kNul - 1));
    r = runReplica("color de2000 " + f, dir_);
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find("value '5\\x000' is not a finite number\n"), std::string::npos) << r.err;
    f = write("long.csv", head + std::string(1 << 20, '7') + "x,0,0,50,0,0\n");
    r = runReplica("color de2000 " + f, dir_);
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_LT(r.err.size(), 400u) << r.err.size();
    EXPECT_NE(r.err.find("7777...' is not a finite number"), std::string::npos)
            << r.err.substr(0, 400);
}

std::string lightCsv(const std::string& name)
{
    // The CIE table's column as 'wavelength_nm,value' on its own 5 nm grid.
    auto table = colour::loadSpectralCsv(dataDir() / "spectra" /
                                         "cie_illuminants_F1_F12_5nm_380_780.csv");
    std::string text = "# " + name + " from the CIE 5 nm table\nwavelength_nm,value\n";
    std::size_t c = 0;
    while (table->columns[c] != name) {
        ++c;
    }
    for (std::size_t i = 0; i < table->wavelengthNm.size(); ++i) {
        text += std::to_string(table->wavelengthNm[i]) + "," + std::to_string(table->rows[i][c]) +
                "\n";
    }
    return text;
}

TEST_F(CliFiles, EvalJsonMatchesTheLibrary)
{
    const auto light = write("f11.csv", lightCsv("F11"));
    const auto set =
            (dataDir() / "spectra" / "colorchecker24_babelcolor_avg_10nm_380_730.csv").string();
    const auto r = runReplica("spectral eval --illuminant " + light + " --reflectances " + set +
                                      " --representation paper6 --json",
                              dir_);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto doc = nlohmann::json::parse(r.out);
    ASSERT_EQ(doc["samples"].size(), 24u);
    EXPECT_EQ(doc["samples"][0]["name"], "dark_skin");
    EXPECT_EQ(doc["samples"][0]["lab_reference"].size(), 3u);
    EXPECT_EQ(doc["white"], "white_9.5");

    auto obs = colour::loadCie1931(dataDir());
    auto d65 = loadCieIlluminant(dataDir(), "D65");
    auto f11 = loadCieIlluminant(dataDir(), "F11");
    auto cc = loadReflectanceSet(dataDir(), "colorchecker");
    auto rep = makeRepresentation(dataDir(), *obs, *d65, "paper6");
    ASSERT_TRUE(obs && d65 && f11 && cc && rep);
    auto lib = evaluateRepresentation(*obs, *d65, **rep, *f11, *cc);
    ASSERT_TRUE(lib);
    // The CLI's light went through std::to_string (6 decimals); F11's table has 2, so it is exact.
    EXPECT_NEAR(doc["stats"]["mean"].get<double>(), lib->stats.mean, 1e-12);
    EXPECT_NEAR(doc["stats"]["max"].get<double>(), lib->stats.max, 1e-12);
    EXPECT_NEAR(doc["samples"][14]["de00"].get<double>(), lib->samples[14].de00, 1e-12);
}

TEST_F(CliFiles, EvalSaysHowEachLightWasAdapted)
{
    // A light of one 10 nm band: at 450 nm CAT02 cannot adapt it but XYZ scaling can; at 700 nm
    // z-bar is 0, the white has no Z and nothing adapts it (it was reported as scaled onto D65
    // while its white came out at a* 206, b* 164).
    const auto set =
            (dataDir() / "spectra" / "colorchecker24_babelcolor_avg_10nm_380_730.csv").string();
    auto band = [](int nm) {
        std::string text = "wavelength_nm,value\n";
        for (int w = 380; w <= 730; w += 10) {
            text += fmt::format("{},{}\n", w, w == nm ? 1.0 : 0.0);
        }
        return text;
    };
    const std::pair<int, std::string> cases[] = {{450, "XYZ scaling to D65"},
                                                 {700, "none (the light has no Z)"}};
    for (const auto& [nm, adaptation] : cases) {
        const auto light = write(fmt::format("band{}.csv", nm), band(nm));
        const auto r = runReplica(
                "spectral eval --illuminant " + light + " --reflectances " + set + " --json", dir_);
        ASSERT_EQ(r.exitCode, 0) << r.err;
        const auto doc = nlohmann::json::parse(r.out);
        EXPECT_EQ(doc["adaptation"], adaptation) << nm;
        const auto& white = doc["samples"][18]["lab_reference"];
        ASSERT_EQ(doc["samples"][18]["name"], "white_9.5");
        if (nm == 450) {
            EXPECT_NEAR(white[1].get<double>(), 0.0, 1e-6); // scaled onto D65: neutral
            EXPECT_NEAR(white[2].get<double>(), 0.0, 1e-6);
        } else {
            EXPECT_GT(white[1].get<double>(), 100.0); // unadapted: the light's own red
        }
        const auto text =
                runReplica("spectral eval --illuminant " + light + " --reflectances " + set, dir_);
        ASSERT_EQ(text.exitCode, 0) << text.err;
        EXPECT_NE(text.out.find(nm == 450 ? "scaled onto D65's in XYZ" : "cannot be adapted"),
                  std::string::npos)
                << text.out;
    }
    const auto f11 = write("f11.csv", lightCsv("F11"));
    const auto r = runReplica(
            "spectral eval --illuminant " + f11 + " --reflectances " + set + " --json", dir_);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["adaptation"], "CAT02 to D65");
}

TEST_F(CliFiles, EvalRefusesANegativeLightButNotItsNoise)
{
    // The colour probe's light: D65-like, -5 at 430 nm, evaluated with no word. A dip of 0.3 % of
    // the peak (a dark-subtracted measurement's noise) still evaluates.
    const auto set =
            (dataDir() / "spectra" / "colorchecker24_babelcolor_avg_10nm_380_730.csv").string();
    auto light = [](double at430) {
        std::string text = "wavelength_nm,value\n";
        for (int w = 380; w <= 730; w += 10) {
            text += fmt::format("{},{}\n", w, w == 430 ? at430 : 100.0);
        }
        return text;
    };
    const auto bad = write("negative.csv", light(-5.0));
    const auto r = runReplica("spectral eval --illuminant " + bad + " --reflectances " + set, dir_);
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.err.find("negative.csv: the light's band at 430 nm is -5"), std::string::npos)
            << r.err;
    EXPECT_NE(r.err.find("cannot be negative"), std::string::npos) << r.err;
    const auto noise = write("noise.csv", light(-0.3));
    const auto ok =
            runReplica("spectral eval --illuminant " + noise + " --reflectances " + set, dir_);
    EXPECT_EQ(ok.exitCode, 0) << ok.err;
}

TEST_F(CliFiles, EvalSensedAblatesEachImpairmentAndIsReproducible)
{
    const auto light = write("f7.csv", lightCsv("F7"));
    const auto set =
            (dataDir() / "spectra" / "colorchecker24_babelcolor_avg_10nm_380_730.csv").string();
    const std::string cmd =
            "spectral eval --sensed --draws 2 --sensed-seed 4 --json --illuminant " + light +
            " --reflectances " + set;
    const auto r = runReplica(cmd, dir_);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto doc = nlohmann::json::parse(r.out);
    const auto& rows = doc.at("rows");
    // Unimpaired, all, five ablations, two corrected, and the appliance's own chain, named.
    ASSERT_EQ(rows.size(), 10u);
    EXPECT_EQ(rows[0].at("light"), "f7");
    for (std::size_t i = 0; i < rows.size(); ++i) {
        EXPECT_EQ(rows[i].at("appliance").get<bool>(), i == 9) << i;
    }
    EXPECT_EQ(rows[9].at("instrument"), "appliance: live chain (the kiosk's)");
    // The unimpaired instrument renders the real colours; the data-sheet one does not.
    EXPECT_LT(rows[0].at("render").at("max").get<double>(), 0.02);
    EXPECT_GT(rows[1].at("render").at("mean").get<double>(),
              rows[0].at("render").at("mean").get<double>());
    EXPECT_EQ(rows[1].at("render").at("n").get<int>(), 2 * 24);
    // Seeded: a second run prints the same figures.
    const auto again = runReplica(cmd, dir_);
    ASSERT_EQ(again.exitCode, 0) << again.err;
    EXPECT_EQ(again.out, r.out);
    const auto wrong = runReplica(cmd + " --representation paper6", dir_);
    EXPECT_EQ(wrong.exitCode, 1);
    EXPECT_NE(wrong.err.find("--sensed renders as the appliance does"), std::string::npos)
            << wrong.err;
}

TEST_F(CliFiles, EvalAdaptiveIsExactForItsLightAndEncodedForAnotherMatchesTheLibrary)
{
    const auto f11 = write("f11.csv", lightCsv("F11"));
    const auto f7 = write("f7.csv", lightCsv("F7"));
    const auto set =
            (dataDir() / "spectra" / "colorchecker24_babelcolor_avg_10nm_380_730.csv").string();
    const std::string base = "spectral eval --illuminant " + f11 + " --reflectances " + set;
    auto r = runReplica(base + " --representation adaptive_k6 --json", dir_);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    auto doc = nlohmann::json::parse(r.out);
    EXPECT_EQ(doc["representation"], "adaptive_k6");
    EXPECT_LT(doc["stats"]["max"].get<double>(), 1e-6);

    // Encoded for F7, rendered under F11: the library's figure, and clearly not exact.
    r = runReplica(base + " --representation adaptive_k6 --encoded-for " + f7 + " --json", dir_);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    doc = nlohmann::json::parse(r.out);
    EXPECT_EQ(doc["encoded_for"], f7);
    auto obs = colour::loadCie1931(dataDir());
    auto d65 = loadCieIlluminant(dataDir(), "D65");
    auto cc = loadReflectanceSet(dataDir(), "colorchecker");
    auto rep = makeRepresentation(dataDir(), *obs, *d65, "adaptive_k6");
    ASSERT_TRUE(obs && d65 && cc && rep);
    auto forF7 = (*rep)->adaptedTo(*loadCieIlluminant(dataDir(), "F7"));
    ASSERT_TRUE(forF7 && *forF7);
    auto lib =
            evaluateRepresentation(*obs, *d65, **forF7, *loadCieIlluminant(dataDir(), "F11"), *cc);
    ASSERT_TRUE(lib);
    EXPECT_GT(lib->stats.max, 0.1);
    EXPECT_NEAR(doc["stats"]["mean"].get<double>(), lib->stats.mean, 1e-12);
    EXPECT_NEAR(doc["stats"]["max"].get<double>(), lib->stats.max, 1e-12);

    // --encoded-for needs an adaptive representation and a light with luminance.
    r = runReplica(base + " --representation replica_k6 --encoded-for " + f7, dir_);
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_EQ(r.err, "replica spectral eval: --encoded-for applies to a light-adaptive "
                     "representation (adaptive_k6); 'replica_k6' encodes the same for every "
                     "light\n");
    const auto dark = write("dark.csv", "wavelength_nm,value\n380,0\n730,0\n");
    r = runReplica(base + " --representation adaptive_k6 --encoded-for " + dark, dir_);
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_EQ(r.err, "replica spectral eval: " + dark +
                             ": adaptive encoding: the light has no luminance (Y <= 0); a dark or "
                             "all-zero spectrum cannot be encoded for, keep the previous "
                             "encoding\n");
}

TEST_F(CliFiles, EvalBadFilesNameFileLineAndProblem)
{
    const auto set =
            (dataDir() / "spectra" / "colorchecker24_babelcolor_avg_10nm_380_730.csv").string();
    struct Case {
        const char* file;
        const char* text;
        const char* expect;
    };
    const Case cases[] = {
            {"nocol.csv", "wavelength_nm,power\n380,1\n730,1\n", ":1: no column named 'value'"},
            {"cell.csv", "wavelength_nm,value\n380,1\n500,abc\n730,1\n",
             ":3: column 'value' value 'abc' is not a finite number"},
            {"order.csv", "wavelength_nm,value\n380,1\n600,1\n590,1\n730,1\n",
             ":4: wavelength 590 nm does not increase (previous 600 nm)"},
            {"narrow.csv", "# too short\nwavelength_nm,value\n400,1\n730,1\n",
             ":3: data start at 400 nm but must cover 380-730 nm"},
            {"narrow2.csv", "wavelength_nm,value\n380,1\n700,1\n", ":3: data end at 700 nm"},
            {"dark.csv", "wavelength_nm,value\n380,0\n730,0\n", ": the light has no luminance"},
            // Values at the ends of a double's range were blamed on the reflectance file.
            {"huge.csv", "wavelength_nm,value\n380,1e308\n730,1e308\n",
             ": the light's values overflow"},
            {"tiny.csv", "wavelength_nm,value\n380,1e-320\n730,1e-320\n",
             ": the light's values underflow"},
    };
    for (const auto& c : cases) {
        const auto light = write(c.file, c.text);
        const auto r =
                runReplica("spectral eval --illuminant " + light + " --reflectances " + set, dir_);
        EXPECT_EQ(r.exitCode, 1) << c.file;
        EXPECT_NE(r.err.find(light + c.expect), std::string::npos) << c.file << ": " << r.err;
        const auto rgb = runReplica("spectral eval --representation rgb3 --illuminant " + light +
                                            " --reflectances " + set,
                                    dir_);
        EXPECT_EQ(rgb.exitCode, 1) << c.file;
        EXPECT_NE(rgb.err.find(light + c.expect), std::string::npos) << c.file << ": " << rgb.err;
    }
    const auto light = write("ok.csv", lightCsv("F2"));
    // A reflectance below -0.05 is no measurement noise (-0.1 printed L* = -88.8).
    const auto negative =
            write("negative.csv", "wavelength_nm,a,b\n380,0.5,0.5\n550,0.5,-0.1\n730,0.5,0.5\n");
    auto neg =
            runReplica("spectral eval --illuminant " + light + " --reflectances " + negative, dir_);
    EXPECT_EQ(neg.exitCode, 1);
    EXPECT_NE(neg.err.find(negative + ":3: column 'b' value -0.1 is no reflectance"),
              std::string::npos)
            << neg.err;
    const auto noise =
            write("noise.csv", "wavelength_nm,a,b\n380,0.5,0.5\n550,0.5,-0.01\n730,0.5,0.5\n");
    EXPECT_EQ(runReplica("spectral eval --illuminant " + light + " --reflectances " + noise, dir_)
                      .exitCode,
              0);
    const auto badSet = write("set.csv", "wavelength_nm,a,b\n380,0.5,0.5\n730,0.5\n");
    auto r = runReplica("spectral eval --illuminant " + light + " --reflectances " + badSet, dir_);
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find(badSet + ":3: 2 cells, expected 3"), std::string::npos) << r.err;
    r = runReplica("spectral eval --illuminant " + light + " --reflectances " + set +
                           " --representation nine",
                   dir_);
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find("no representation named 'nine'"), std::string::npos) << r.err;
}

TEST_F(CliFiles, FitRejectsBadWeightsBeforeFitting)
{
    const std::string out = " --out " + (dir_ / "out").string();
    const std::pair<const char*, const char*> cases[] = {
            {"A30", "--weights: 'A30' is not NAME=WEIGHT"},
            {"=3", "--weights: '=3' is not NAME=WEIGHT"},
            {"A=x", "--weights: 'A=x' has no finite non-negative number after '='"},
            {"A=-1", "--weights: 'A=-1' has no finite non-negative number after '='"},
            {"A=3x", "--weights: 'A=3x' has no finite non-negative number after '='"},
            {"A=inf", "--weights: 'A=inf' has no finite non-negative number after '='"},
            {"NOPE=2", "--weights: "}};
    for (const auto& [arg, message] : cases) {
        const auto r = runReplica(std::string("spectral fit --weights ") + arg + out, dir_);
        EXPECT_EQ(r.exitCode, 1) << arg;
        EXPECT_NE(r.err.find(std::string("replica spectral fit: ") + message), std::string::npos)
                << arg << ": " << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
        EXPECT_FALSE(std::filesystem::exists(dir_ / "out" / "replica_k6.csv"));
    }
    // An unknown lamp is named.
    const auto r = runReplica("spectral fit --weights NOPE=2" + out, dir_);
    EXPECT_NE(r.err.find("NOPE"), std::string::npos) << r.err;
}

TEST_F(CliFiles, ChannelBasisRoundTripsAndRejectsOffGridFiles)
{
    auto basis = colour::loadDefaultChannelBasis(dataDir());
    ASSERT_TRUE(basis) << basis.error().message;
    const auto path = dir_ / "copy.csv";
    ASSERT_TRUE(colour::saveChannelBasis(*basis, path, "test copy"));
    auto back = colour::loadChannelBasis(path);
    ASSERT_TRUE(back) << back.error().message;
    EXPECT_EQ(back->name, "copy");
    for (std::size_t k = 0; k < colour::kChannels; ++k) {
        for (std::size_t l = 0; l < colour::kBands; ++l) {
            EXPECT_EQ(back->project[k][l], basis->project[k][l]);
            EXPECT_EQ(back->reconstruct[k][l], basis->reconstruct[k][l]);
        }
    }
    std::string header = "wavelength_nm";
    for (int k = 1; k <= 6; ++k) {
        header += ",project_" + std::to_string(k);
    }
    for (int k = 1; k <= 6; ++k) {
        header += ",reconstruct_" + std::to_string(k);
    }
    std::string rows;
    for (int i = 0; i < 36; ++i) {
        rows += std::to_string(i == 5 ? 435 : 380 + 10 * i);
        for (int c = 0; c < 12; ++c) {
            rows += ",0.5";
        }
        rows += "\n";
    }
    const auto bad = write("offgrid.csv", header + "\n" + rows);
    auto r = colour::loadChannelBasis(bad);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().message,
              bad + ": wavelength row 6 is 435 nm, expected 430 nm (the working grid)");
    const auto missing = write("missing.csv", "wavelength_nm,project_1\n380,1\n390,1\n");
    r = colour::loadChannelBasis(missing);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("has 2 wavelength rows, expected the 36"), std::string::npos);
}

TEST_F(CliFiles, SixChannelModelRoundTripsAndNamesItsMatrixFile)
{
    auto model = loadSixChannelModel(dataDir() / "channels" / "paper6.csv");
    ASSERT_TRUE(model) << model.error().message;
    const auto path = dir_ / "m.csv";
    ASSERT_TRUE(saveSixChannelModel(*model, path, "copy"));
    auto back = loadSixChannelModel(path);
    ASSERT_TRUE(back) << back.error().message;
    EXPECT_EQ(back->toXyz[5].z, model->toXyz[5].z);
    EXPECT_EQ(back->lightProject[2][17], model->lightProject[2][17]);
    std::ofstream(dir_ / "m_to_xyz.csv") << "channel,X,Y,Z\n1,1,2,3\n2,1,2\n";
    auto bad = loadSixChannelModel(path);
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error().message,
              (dir_ / "m_to_xyz.csv").string() + ":3: 3 cells, expected 4 (channel,X,Y,Z)");
    // A row with a trailing comma has a fifth, empty cell: refused, where it was once read as
    // the four before it.
    std::ofstream(dir_ / "m_to_xyz.csv") << "channel,X,Y,Z\n1,1,2,3,\n";
    bad = loadSixChannelModel(path);
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error().message,
              (dir_ / "m_to_xyz.csv").string() + ":2: 5 cells, expected 4 (channel,X,Y,Z)");
    // Blanks around a cell are trimmed as in every other CSV the project reads.
    std::ofstream(dir_ / "m_to_xyz.csv") << "channel,X,Y,Z\n";
    for (int k = 0; k < 6; ++k) {
        std::ofstream(dir_ / "m_to_xyz.csv", std::ios::app)
                << k + 1 << ", " << model->toXyz[static_cast<std::size_t>(k)].x << " ,"
                << model->toXyz[static_cast<std::size_t>(k)].y << ",\t"
                << model->toXyz[static_cast<std::size_t>(k)].z << "\n";
    }
    auto spaced = loadSixChannelModel(path);
    ASSERT_TRUE(spaced) << spaced.error().message;
    EXPECT_NEAR(spaced->toXyz[5].z, model->toXyz[5].z, 1e-5 * std::abs(model->toXyz[5].z));
}

} // namespace
} // namespace replica::pipeline::spectral
