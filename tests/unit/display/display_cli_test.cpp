// 'replica display fit|inverse|forward|study' and the appliance's display-profile rules, run as the
// built binary: exit codes, JSON shapes, round trips and the one-line error messages.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include <pipeline/base/data_dir.h>
#include <pipeline/colour/xyz.h>
#include <pipeline/offline/display/cgats.h>
#include <pipeline/offline/spectral/accuracy.h>
#include <pipeline/spectral/reference_sets.h>
#include <pipeline/spectral/representation_catalogue.h>

#include <gtest/gtest.h>

#include "../support/cli.h"
#include "../support/temp_dir.h"

namespace replica::pipeline::display {
namespace {

class DisplayCli : public tests::TempDirTest
{
protected:
    tests::CliResult run(const std::string& args) const
    {
        return tests::runReplica("--log-level warn " + args, dir_);
    }

    static std::string shippedMeasurements()
    {
        return (dataDir() / "displays" / "wide-ips-synthetic-measurements.csv").string();
    }
    static std::string shippedProfile()
    {
        return (dataDir() / "displays" / "wide-ips-synthetic.json").string();
    }
};

TEST_F(DisplayCli, FitThenForwardThenInverseRoundTrips)
{
    const std::string profile = (dir_ / "p.json").string();
    const auto fit = run("display fit " + shippedMeasurements() + " --out " + profile + " --json");
    ASSERT_EQ(fit.exitCode, 0) << fit.err;
    const auto report = nlohmann::json::parse(fit.out);
    EXPECT_GT(report.at("held_out_colours").get<int>(), 20);
    // The synthetic meter's noise is 0.2 %: held-out errors of that order, not of a bad model.
    EXPECT_LT(report.at("held_out_mean_de00").get<double>(), 0.5);

    const auto fwd = run("display forward " + profile + " --rgb 120,80,200 --json");
    ASSERT_EQ(fwd.exitCode, 0) << fwd.err;
    const auto xyz = nlohmann::json::parse(fwd.out).at("xyz");
    ASSERT_EQ(xyz.size(), 3u);
    const auto inv =
            run(fmt::format("display inverse {} --xyz {},{},{} --json", profile,
                            xyz[0].get<double>(), xyz[1].get<double>(), xyz[2].get<double>()));
    ASSERT_EQ(inv.exitCode, 0) << inv.err;
    const auto j = nlohmann::json::parse(inv.out);
    EXPECT_TRUE(j.at("in_gamut").get<bool>());
    EXPECT_NEAR(j.at("rgb")[0].get<double>(), 120.0, 1e-3);
    EXPECT_NEAR(j.at("rgb")[1].get<double>(), 80.0, 1e-3);
    EXPECT_NEAR(j.at("rgb")[2].get<double>(), 200.0, 1e-3);
}

TEST_F(DisplayCli, FitAttachesAMeasuredViewingAngleTable)
{
    // White at 0, 15 and 25 deg: the paper's 90 % and 75 %, and a slight shift towards blue.
    const std::string table = write("angles.csv", "# goniometer\nangle_deg,X,Y,Z\n"
                                                  "0,950,1000,1089\n15,850,900,1000\n"
                                                  "25,700,750,850\n");
    const std::string profile = (dir_ / "p.json").string();
    const auto fit = run("display fit " + shippedMeasurements() + " --out " + profile +
                         " --viewing-table " + table);
    ASSERT_EQ(fit.exitCode, 0) << fit.err;
    std::ifstream f(profile);
    const auto j = nlohmann::json::parse(f);
    const auto& v = j.at("viewing_angle");
    EXPECT_EQ(v.at("angle_deg").size(), 3u);
    EXPECT_NEAR(v.at("luminance_ratio")[1].get<double>(), 0.90, 1e-12);
    EXPECT_NEAR(v.at("luminance_ratio")[2].get<double>(), 0.75, 1e-12);
    // x of white at 25 deg: 700 / 2300 against 950 / 3039 on axis.
    EXPECT_NEAR(v.at("dx")[2].get<double>(), 700.0 / 2300.0 - 950.0 / 3039.0, 1e-12);

    const auto bad = run("display fit " + shippedMeasurements() + " --out " + profile +
                         " --viewing-table " + write("b.csv", "angle_deg,X,Y,Z\n10,1,1,1\n"));
    EXPECT_EQ(bad.exitCode, 1);
    EXPECT_NE(bad.err.find("b.csv:2: the first row must be on axis (angle_deg 0)"),
              std::string::npos)
            << bad.err;
    const auto dark =
            run("display fit " + shippedMeasurements() + " --out " + profile + " --viewing-table " +
                write("d.csv", "angle_deg,X,Y,Z\n0,1,1,1\n30,0,0,0\n"));
    EXPECT_EQ(dark.exitCode, 1);
    EXPECT_NE(dark.err.find("d.csv:3: white must have Y > 0"), std::string::npos) << dark.err;
}

TEST_F(DisplayCli, ReplayRefusesAChangedProfile)
{
    // A recording made with a copy of the shipped profile replays while the copy is unchanged
    // and fails, saying so, once it is edited.
    const auto copy = dir_ / "panel.json";
    std::filesystem::copy_file(shippedProfile(), copy);
    const std::string rec = (dir_ / "r.mcap").string();
    const auto made = run("run --fast --frames 3 --size 32x20 --display-profile " + copy.string() +
                          " --record " + rec);
    ASSERT_EQ(made.exitCode, 0) << made.err;
    // A recording is untrusted: it names files outside the data folder only under --data-root.
    const auto outside = run("replay " + rec + " --clock fast");
    EXPECT_EQ(outside.exitCode, 1);
    EXPECT_NE(outside.err.find("outside the data folders"), std::string::npos) << outside.err;
    const std::string root = " --data-root " + dir_.string();
    const auto same = run("replay " + rec + " --clock fast" + root);
    EXPECT_EQ(same.exitCode, 0) << same.err;
    std::ofstream(copy, std::ios::app) << "\n";
    const auto changed = run("replay " + rec + " --clock fast" + root);
    EXPECT_EQ(changed.exitCode, 1);
    EXPECT_NE(changed.err.find("has changed since it was recorded"), std::string::npos)
            << changed.err;
}

TEST_F(DisplayCli, InverseReportsOutOfGamutAndRejectsBadInput)
{
    // Spectral 520 nm green is far outside any three-primary gamut.
    const auto out = run("display inverse " + shippedProfile() + " --xyz 6.3,71,7.8 --json");
    ASSERT_EQ(out.exitCode, 0) << out.err;
    EXPECT_FALSE(nlohmann::json::parse(out.out).at("in_gamut").get<bool>());

    const auto bad = run("display inverse " + shippedProfile() + " --xyz 1,2");
    EXPECT_EQ(bad.exitCode, 2);
    EXPECT_NE(bad.err.find("--xyz 1,2: expected three numbers X,Y,Z in cd/m^2"), std::string::npos)
            << bad.err;
    const auto range = run("display forward " + shippedProfile() + " --rgb 0,0,300");
    EXPECT_EQ(range.exitCode, 2);
    EXPECT_NE(range.err.find("counts must lie in [0, 255]"), std::string::npos) << range.err;
    const auto missing = run("display forward /nonexistent/p.json --rgb 1,2,3");
    EXPECT_EQ(missing.exitCode, 1);
    EXPECT_NE(missing.err.find("/nonexistent/p.json: cannot open the display profile"),
              std::string::npos)
            << missing.err;
}

TEST_F(DisplayCli, FitFailsClearlyOnDegenerateSets)
{
    // Black and a red ramp only: green and blue were never measured.
    std::string csv = "R,G,B,X,Y,Z\n0,0,0,0.5,0.5,0.6\n";
    for (int d = 32; d <= 255; d += 32) {
        csv += fmt::format("{},0,0,{},{},0.6\n", d, 0.5 + d, 0.5 + d * 0.5);
    }
    csv += "255,0,0,256,128,0.6\n";
    const auto r =
            run("display fit " + write("m.csv", csv) + " --out " + (dir_ / "p.json").string());
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find("missing ramp: channel G has 0 non-zero levels"), std::string::npos)
            << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir_ / "p.json")); // nothing half-written

    const auto header = run("display fit " + write("h.csv", "R,G,B,X,Y\n") + " --out " +
                            (dir_ / "p.json").string());
    EXPECT_EQ(header.exitCode, 1);
    EXPECT_NE(header.err.find("h.csv:1: header must be R,G,B,X,Y,Z"), std::string::npos)
            << header.err;
}

// A reading no display can give (1e308 cd/m^2 overflowed the fit into a profile of nulls, exit 0)
// is refused naming its line, like a NaN or a negative Y, and nothing is written.
TEST_F(DisplayCli, FitRefusesAReadingBeyondAnyDisplayNamingItsLine)
{
    std::ifstream in(shippedMeasurements());
    std::string csv;
    std::string line;
    for (int n = 1; std::getline(in, line); ++n) {
        csv += (n == 9 ? std::string("255,255,255,1e308,1e308,1e308") : line) + "\n";
    }
    const auto file = write("m.csv", csv);
    const auto r = run("display fit " + file + " --out " + (dir_ / "p.json").string());
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find(file + ":9: X = 1e+308 cd/m^2 is beyond any display"), std::string::npos)
            << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir_ / "p.json"));
}

TEST_F(DisplayCli, FitsArgyllReadingsAndWritesAnIccProfile)
{
    // The shipped set as dispread would have written it: the same fit as from the CSV.
    auto set = loadMeasurementCsv(shippedMeasurements());
    ASSERT_TRUE(set.has_value());
    const std::string ti3 = write("m.ti3", ti3Text(set->rows, 8, "test"));
    const std::string fromTi3 = (dir_ / "a.json").string();
    const std::string fromCsv = (dir_ / "b.json").string();
    const std::string icc = (dir_ / "a.icc").string();
    const auto a = run("display fit " + ti3 + " --out " + fromTi3 + " --icc " + icc);
    ASSERT_EQ(a.exitCode, 0) << a.err;
    // The shipped panel has 0.5 % channel interaction, which the check now tells from noise.
    EXPECT_NE(a.out.find("NOT additive: channel interaction beyond the noise"), std::string::npos)
            << a.out;
    EXPECT_NE(a.out.find("meter noise (from the ramps' residuals)"), std::string::npos) << a.out;
    const auto b = run("display fit " + shippedMeasurements() + " --out " + fromCsv + " --json");
    ASSERT_EQ(b.exitCode, 0) << b.err;
    const auto j = nlohmann::json::parse(b.out);
    EXPECT_TRUE(j.at("additive_within_noise").is_boolean());
    EXPECT_GT(j.at("noise_percent").get<double>(), 0.1);
    EXPECT_LT(j.at("noise_percent").get<double>(), 0.4);
    const auto fa = run("display forward " + fromTi3 + " --rgb 120,80,200 --json");
    const auto fb = run("display forward " + fromCsv + " --rgb 120,80,200 --json");
    ASSERT_EQ(fa.exitCode, 0) << fa.err;
    const auto xa = nlohmann::json::parse(fa.out).at("xyz");
    const auto xb = nlohmann::json::parse(fb.out).at("xyz");
    for (int k = 0; k < 3; ++k) {
        // The .ti3 carries XYZ to 8 significant digits, the CSV to 6 decimals.
        EXPECT_NEAR(xa[k].get<double>(), xb[k].get<double>(), 1e-4 * xb[k].get<double>());
    }
    EXPECT_TRUE(std::filesystem::exists(icc));
    EXPECT_GT(std::filesystem::file_size(icc), 1000u);

    // A cut-short .ti3 names its line.
    std::string text = ti3Text(set->rows, 8, "test");
    text.resize(text.find("END_DATA\n"));
    const auto bad = run("display fit " + write("cut.ti3", text) + " --out " + fromTi3);
    EXPECT_EQ(bad.exitCode, 1);
    EXPECT_NE(bad.err.find("cut.ti3:"), std::string::npos) << bad.err;
    EXPECT_NE(bad.err.find("BEGIN_DATA without END_DATA"), std::string::npos) << bad.err;
}

// A stand-in for ArgyllCMS spotread: its prompt, and for each key press a " Result is XYZ: X Y Z,
// Yxy: ..." line (the format of spotread 2.3's emissive readings), of a linear panel reading the
// counts the headless display shows; FAKE_STOP ends it after that many readings, as a pulled cable.
constexpr const char* kFakeSpotread = R"(#!/bin/bash
echo "Place instrument on spot to be measured,"
printf "Hit ESC or Q to exit, instrument switch or any other key to take a reading: "
n=0
while IFS= read -r -n1 key; do
  case "$key" in q|Q) echo; exit 0;; esac
  n=$((n+1))
  if [ -n "$FAKE_STOP" ] && [ "$n" -gt "$FAKE_STOP" ]; then exit 3; fi
  read -r r g b < "$SHOW_DIR/patch.txt"
  awk -v r="$r" -v g="$g" -v b="$b" 'BEGIN { x = 0.5 + 1.6*r + 1.4*g + 0.7*b; y = 0.6 + 0.8*r + 2.8*g + 0.3*b; z = 0.8 + 0.05*r + 0.4*g + 3.5*b; printf "\n Result is XYZ: %.6f %.6f %.6f, Yxy: %.6f 0.3 0.3\n\n", x, y, z, y }'
  echo "Place instrument on spot to be measured,"
  printf "Hit ESC or Q to exit, instrument switch or any other key to take a reading: "
done
)";

TEST_F(DisplayCli, PatchesDriveSpotreadAndResumeAfterAnInterruption)
{
    const std::string set = (dir_ / "set.ti1").string();
    const std::string out = (dir_ / "r.ti3").string();
    const std::string show = (dir_ / "show").string();
    const std::string fake = write("spotread.sh", kFakeSpotread);
    const auto made =
            run("display patches --make-set " + set + " --step 32 --full-repeats 1 --colours 6");
    ASSERT_EQ(made.exitCode, 0) << made.err;
    EXPECT_NE(made.out.find("35 patches"), std::string::npos) << made.out; // 3 + 3 x 8 + 2 + 6
    // The default set: 3 blacks, ramps every 3 counts (84 levels below full drive) and full drive
    // read 10 times per channel, 2 whites, 60 colours.
    const auto byDefault = run("display patches --make-set " + (dir_ / "default.ti1").string());
    ASSERT_EQ(byDefault.exitCode, 0) << byDefault.err;
    EXPECT_NE(byDefault.out.find("347 patches"), std::string::npos) << byDefault.out;
    const auto stopped = run("display patches " + set + " --out " + out + " --show-dir " + show +
                             " --spotread 'FAKE_STOP=5 SHOW_DIR=" + show + " bash " + fake + "'");
    EXPECT_EQ(stopped.exitCode, 1);
    EXPECT_NE(stopped.err.find("the meter ended before reading patch 6 of 35"), std::string::npos)
            << stopped.err;
    auto partial = loadMeasurements(out);
    ASSERT_TRUE(partial.has_value()) << partial.error().message;
    EXPECT_EQ(partial->rows.size(), 5u);
    const auto resumed = run("display patches " + set + " --out " + out + " --show-dir " + show +
                             " --spotread 'SHOW_DIR=" + show + " bash " + fake + "'");
    ASSERT_EQ(resumed.exitCode, 0) << resumed.err;
    EXPECT_NE(resumed.out.find("resuming at patch 6 of 35"), std::string::npos) << resumed.out;
    auto all = loadMeasurements(out);
    ASSERT_TRUE(all.has_value()) << all.error().message;
    ASSERT_EQ(all->rows.size(), 35u);
    for (const auto& m : all->rows) {
        const glm::dvec3 c = m.counts;
        const glm::dvec3 want{0.5 + 1.6 * c.x + 1.4 * c.y + 0.7 * c.z,
                              0.6 + 0.8 * c.x + 2.8 * c.y + 0.3 * c.z,
                              0.8 + 0.05 * c.x + 0.4 * c.y + 3.5 * c.z};
        for (int k = 0; k < 3; ++k) {
            EXPECT_NEAR(m.xyz[k], want[k], 1e-5 * want[k]) << m.line;
        }
    }
    // The readings of a linear panel fit exactly.
    const auto fit = run("display fit " + out + " --out " + (dir_ / "p.json").string() + " --json");
    ASSERT_EQ(fit.exitCode, 0) << fit.err;
    EXPECT_LT(nlohmann::json::parse(fit.out).at("held_out_max_de00").get<double>(), 1e-3);

    // Typed readings: two, then end of input (resumable), then a malformed line.
    std::filesystem::remove(out);
    const auto typed = run("display patches " + set + " --out " + out + " --show-dir " + show +
                           " < " + write("in.txt", "0.5 0.6 0.8\n0.5 0.6 0.8\n"));
    EXPECT_EQ(typed.exitCode, 0) << typed.err;
    EXPECT_NE(typed.out.find("stopped: 2 of 35 readings"), std::string::npos) << typed.out;
    const auto bad = run("display patches " + set + " --out " + out + " --show-dir " + show +
                         " < " + write("bad.txt", "1 2 x\n"));
    EXPECT_EQ(bad.exitCode, 1);
    EXPECT_NE(bad.err.find("patch 3: '1 2 x' is not three numbers X Y Z"), std::string::npos)
            << bad.err;
}

TEST_F(DisplayCli, PatchesOnThePanelThroughKms)
{
    const std::string set = (dir_ / "set.ti1").string();
    const std::string out = (dir_ / "r.ti3").string();
    ASSERT_EQ(run("display patches --make-set " + set + " --step 32 --full-repeats 1 --colours 6")
                      .exitCode,
              0);
    // Argument handling: an unknown output, and the headless display's folder with kms.
    const auto unknown = run("display patches " + set + " --out " + out + " --output x11");
    EXPECT_EQ(unknown.exitCode, 2);
    EXPECT_NE(unknown.err.find("--output is 'headless' (with --show-dir DIR) or 'kms', not 'x11'"),
              std::string::npos)
            << unknown.err;
    const auto both = run("display patches " + set + " --out " + out + " --output kms --show-dir " +
                          (dir_ / "show").string());
    EXPECT_EQ(both.exitCode, 2);
    EXPECT_NE(both.err.find("--show-dir is the headless display's"), std::string::npos) << both.err;
    const auto neither = run("display patches " + set + " --out " + out);
    EXPECT_EQ(neither.exitCode, 2);
    EXPECT_NE(neither.err.find("--show-dir DIR or --output kms"), std::string::npos) << neither.err;
    // No DRM device: one line naming it and what to do instead, nothing read, no readings file.
    const std::string card = (dir_ / "no-such-card").string();
    const auto none = run("display patches " + set + " --out " + out +
                          " --output kms --kms-device " + card + " < /dev/null");
    EXPECT_EQ(none.exitCode, 1);
    EXPECT_NE(none.err.find(card + ": cannot show patches on the panel: "), std::string::npos)
            << none.err;
    EXPECT_NE(none.err.find("without the panel: --output headless --show-dir DIR"),
              std::string::npos)
            << none.err;
    EXPECT_FALSE(std::filesystem::exists(out));
}

TEST_F(DisplayCli, StudyNamesThePapersOutOfGamutPatchesUnderTungsten)
{
    const auto r = run("display study --json");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    ASSERT_EQ(j.at("lights").size(), 3u);
    for (const auto& l : j.at("lights")) {
        const auto oog = l.at("out_of_gamut").get<std::vector<std::string>>();
        if (l.at("light").get<std::string>().find("Ill. A") == std::string::npos) {
            // Daylight simulators: the chain is nearly exact for in-gamut patches.
            EXPECT_LT(l.at("screen_mapped_in_gamut").at("mean").get<double>(), 0.5);
            continue;
        }
        // The paper: orange, yellow, orange-yellow, yellow-green and red fall outside the panel's
        // primaries under tungsten. This panel's gamut differs, but the yellows must be among them.
        for (const char* name : {"orange", "yellow", "orange_yellow"}) {
            EXPECT_NE(std::find(oog.begin(), oog.end(), name), oog.end()) << name;
        }
        // Hue-keeping mapping beats per-channel clipping on the worst patch.
        EXPECT_LT(l.at("screen_mapped_absolute").at("max").get<double>(),
                  l.at("screen_clipped_absolute").at("max").get<double>());
    }
}

TEST_F(DisplayCli, StudyShowsThePapersSixChannelConstructionBesideReplicas)
{
    const auto r = run("display study --json --panel truth");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    // The paper6 column against spectral eval's library path on the same light (CIE F7 for the
    // D65 booth): both relative to the white patch, CAT02 to D65; the study's white sits at the
    // spectral white's Y rather than 1/1.13, so they agree to a few hundredths, not exactly.
    auto obs = pipeline::colour::loadCie1931(dataDir());
    auto d65 = pipeline::spectral::loadCieIlluminant(dataDir(), "D65");
    auto f7 = pipeline::spectral::loadCieIlluminant(dataDir(), "F7");
    auto cc = pipeline::spectral::loadReflectanceSet(dataDir(), "colorchecker");
    ASSERT_TRUE(obs && d65 && f7 && cc);
    auto rep = pipeline::spectral::makeRepresentation(dataDir(), *obs, *d65, "paper6");
    ASSERT_TRUE(rep);
    auto lib = pipeline::spectral::evaluateRepresentation(*obs, *d65, **rep, *f7, *cc);
    ASSERT_TRUE(lib);
    const auto& f7Row = j.at("lights").at(0);
    EXPECT_NE(f7Row.at("light").get<std::string>().find("F7"), std::string::npos);
    EXPECT_NEAR(f7Row.at("paper6").at("mean").get<double>(), lib->stats.mean, 0.03);
    EXPECT_NEAR(f7Row.at("paper6").at("max").get<double>(), lib->stats.max, 0.1);
    for (const auto& l : j.at("lights")) {
        // Replica's basis is several times closer than the paper's construction...
        EXPECT_LT(3.0 * l.at("six_channel").at("mean").get<double>(),
                  l.at("paper6").at("mean").get<double>());
        // The screen column through paper6 is filled in.
        EXPECT_GT(l.at("screen_paper6_mapped").at("n").get<int>(), 0);
    }
}

TEST_F(DisplayCli, ApplianceNeedsAProfileAndRecordsWhichOne)
{
    const std::string common = "run --fast --frames 2 --size 32x20 ";
    const auto refused = run(common + "--display-profile /nonexistent/panel.json");
    EXPECT_EQ(refused.exitCode, 1);
    EXPECT_NE(refused.err.find("no display profile at /nonexistent/panel.json"), std::string::npos)
            << refused.err;
    EXPECT_NE(refused.err.find("--uncalibrated"), std::string::npos) << refused.err;

    const std::string rec = (dir_ / "r.mcap").string();
    const auto ok = run(common + "--record " + rec);
    ASSERT_EQ(ok.exitCode, 0) << ok.err;
    auto info = run("inspect " + rec + " --json");
    ASSERT_EQ(info.exitCode, 0) << info.err;
    const std::string id = nlohmann::json::parse(info.out).at("display_profile").get<std::string>();
    EXPECT_NE(id.find("wide-ips-synthetic"), std::string::npos) << id;
    EXPECT_NE(id.find("fnv1a64"), std::string::npos) << id;

    // The same file again: an existing recording is overwritten only when asked.
    const auto unc = run(common + "--uncalibrated --force --record " + rec);
    ASSERT_EQ(unc.exitCode, 0) << unc.err;
    info = run("inspect " + rec + " --json");
    EXPECT_NE(nlohmann::json::parse(info.out)
                      .at("display_profile")
                      .get<std::string>()
                      .find("uncalibrated"),
              std::string::npos);
}

} // namespace
} // namespace replica::pipeline::display
