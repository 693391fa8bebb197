// The site file: a calibration replaces only its own keys (every other key, comment and section
// stays byte for byte), reads back to the transform written, and a broken file or a missing
// folder is refused naming it.
#include <filesystem>
#include <fstream>
#include <sstream>

#include <glm/geometric.hpp>
#include <unistd.h>

#include <platform/site_config.h>
#include <platform/site_file.h>

#include <gtest/gtest.h>

#include "../support/files.h"

namespace replica::tests {
namespace {

using namespace platform;

class CalibrationSiteFile : public ::testing::Test
{
protected:
    void SetUp() override
    {
        dir_ = std::filesystem::temp_directory_path() /
               ("replica-site-" + std::to_string(::getpid()));
        std::filesystem::remove_all(dir_);
        std::filesystem::create_directories(dir_);
    }
    void TearDown() override { std::filesystem::remove_all(dir_); }
    std::filesystem::path dir_;
};

pipeline::scene::RigidFit quarterTurn(double x)
{
    pipeline::scene::RigidFit fit;
    // A quarter turn about y and a translation.
    fit.T_booth_tracker.rotation = glm::dmat3(glm::dvec3{0.0, 0.0, -1.0}, glm::dvec3{0.0, 1.0, 0.0},
                                              glm::dvec3{1.0, 0.0, 0.0});
    fit.T_booth_tracker.translation = {x, 0.42, -0.05};
    fit.residualsM = {0.001, 0.002, 0.0015};
    fit.rmsM = 0.0016;
    fit.worst = 1;
    return fit;
}

TEST_F(CalibrationSiteFile, TrackerCalibrationReplacesOnlyItsKeysAndReadsBack)
{
    const auto file = dir_ / "replica.toml";
    // The kiosk's tracker settings (a port and bind address that are not the defaults, a
    // multi-line array whose line starts like a header) must survive the calibration byte for
    // byte: a lost port is a kiosk listening where opentrack does not send.
    const std::string head = "# site of booth 7\n[display]\nprofile = \"panel.json\" # measured\n\n"
                             "[tracker]\n# opentrack on the booth's PC\nold = 1\n"
                             "port = 5555                         # opentrack's UDP output\n"
                             "bind = \"0.0.0.0\"\nlist = [\n[1, 2],\n]\n";
    const std::string tail = "\n[tracker.extra]\nx = 2\n\n[sources]\ntracker = \"hid\"\n";
    spit(file, head + tail);
    const auto fit = quarterTurn(0.1);
    const std::string body = trackerSection(fit, 3);
    ASSERT_TRUE(writeSiteSection(file, "tracker", body));
    EXPECT_EQ(slurp(file), head + body + tail);
    auto t = readTrackerTransform(file);
    ASSERT_TRUE(t) << t.error().message;
    const glm::dvec3 p{0.3, -0.2, 0.7};
    EXPECT_LT(glm::length(t->apply(p) - fit.T_booth_tracker.apply(p)), 1e-8);
    // Calibrated again: the keys and the comments the first calibration wrote are replaced where
    // they stand, not added again.
    const std::string again = trackerSection(quarterTurn(0.2), 4);
    ASSERT_TRUE(writeSiteSection(file, "tracker", again));
    EXPECT_EQ(slurp(file), head + again + tail);
}

TEST_F(CalibrationSiteFile, SpectrometerCalibrationKeepsTheLevelAndTheNotes)
{
    const auto file = dir_ / "replica.toml";
    const std::string head = "[spectrometer]\n# metered 2024-05-01\ndirect_cdm2_per_y = 7.1e-05\n";
    spit(file, head + "stray_light_fraction = 0.0004 # from the maker\n\n[log]\nlevel = \"info\"");
    const std::string body = "# 'replica calibrate spectrometer' from lamp.mcap\n"
                             "stray_light_fraction = 0.0005\nwavelength_offset_nm = 0.1000\n";
    ASSERT_TRUE(writeSiteSection(file, "spectrometer", body));
    // The file's last line had no newline: it still has none.
    EXPECT_EQ(slurp(file), head + body + "\n[log]\nlevel = \"info\"");
}

TEST_F(CalibrationSiteFile, AKeyItCannotReplaceInPlaceAndAMissingFolderAreRefused)
{
    const auto file = dir_ / "dotted.toml";
    const std::string dotted = "[tracker]\nport = 5555\nT_booth_tracker.translation = [0, 0, 0]\n";
    spit(file, dotted);
    auto w = writeSiteSection(file, "tracker", trackerSection(quarterTurn(0.1), 3));
    ASSERT_FALSE(w);
    EXPECT_NE(w.error().message.find("dotted.toml:3: tracker.T_booth_tracker"), std::string::npos)
            << w.error().message;
    EXPECT_EQ(slurp(file), dotted);
    // A mistyped --site: no folder is made, nothing is written.
    const auto nowhere = dir_ / "no-such-folder" / "replica.toml";
    w = writeSiteSection(nowhere, "tracker", "a = 1\n");
    ASSERT_FALSE(w);
    EXPECT_NE(w.error().message.find("there is no folder"), std::string::npos) << w.error().message;
    EXPECT_FALSE(std::filesystem::exists(nowhere.parent_path()));
    // A new file in a folder that exists is the documented first calibration.
    ASSERT_TRUE(writeSiteSection(dir_ / "new.toml", "tracker", "port = 5555\n"));
    EXPECT_EQ(slurp(dir_ / "new.toml"), "[tracker]\nport = 5555\n");
}

// What a calibration writes, the site reader takes: the stand's section with its figures for
// people checks as written, and a key the reader would refuse (unknown, out of range) is not
// written, the file left as it was, so that the next start does not stop on it (exit 78).
TEST_F(CalibrationSiteFile, WhatACalibrationWritesTheSiteReaderTakes)
{
    const auto file = dir_ / "replica.toml";
    // A technician's own mistake elsewhere in the section is not the calibration's to refuse.
    const std::string head = "[stand]\nmy_note = 1\n[tracker]\nport = 5555\n";
    spit(file, head);
    pipeline::scene::StandFit fit;
    fit.stand.hingeM = {0.0, 0.18, -0.07};
    fit.stand.hingeToPanelM = 0.035;
    fit.hingeAxisPanel = {0.999, 0.03, -0.02};
    fit.axisAngleRad = 0.036;
    fit.tiltsRad = {0.0, 0.35, 0.7};
    fit.rmsM = 0.0004;
    ASSERT_TRUE(writeSiteSection(file, "stand", standSection(fit)));
    auto load = loadSiteConfig(file);
    ASSERT_TRUE(load) << load.error().message;
    for (const auto& p : load->problems) {
        EXPECT_EQ(p.key, "stand.my_note") << formatProblem(file, p);
    }
    EXPECT_NEAR(load->config.stand.hingeM.y, 0.18, 1e-9);
    EXPECT_NEAR(load->config.stand.hingeToPanelM, 0.035, 1e-9);

    const std::string before = slurp(file);
    for (const char* body : {"port = 70000\n", "porrt = 5556\n"}) {
        auto w = writeSiteSection(file, "tracker", body);
        ASSERT_FALSE(w) << body;
        EXPECT_NE(w.error().message.find("replica.toml:"), std::string::npos) << w.error().message;
        EXPECT_NE(w.error().message.find(": tracker.por"), std::string::npos) << w.error().message;
        EXPECT_NE(w.error().message.find("is unchanged"), std::string::npos) << w.error().message;
        EXPECT_EQ(slurp(file), before);
    }
    fit.stand.hingeM.y = 18.0; // a tape read in centimetres
    auto w = writeSiteSection(file, "stand", standSection(fit));
    ASSERT_FALSE(w);
    EXPECT_NE(w.error().message.find("stand.hinge_m"), std::string::npos) << w.error().message;
    EXPECT_EQ(slurp(file), before);
}

TEST_F(CalibrationSiteFile, SourcesAreReadWhenPresent)
{
    const auto file = dir_ / "sources.toml";
    std::ofstream(file) << "[sources]\ntracker = \"hid\"\nlamp_selector = \"gpio\"\n";
    auto s = readSiteSources(file);
    ASSERT_TRUE(s) << s.error().message;
    EXPECT_EQ(s->at("tracker"), "hid");
    EXPECT_EQ(s->at("lamp_selector"), "gpio");
    EXPECT_EQ(s->count("spectrometer"), 0u);
    std::ofstream(file) << "[sources]\ntracker = 3\n";
    s = readSiteSources(file);
    ASSERT_FALSE(s);
    EXPECT_NE(s.error().message.find("[sources] tracker must be a string"), std::string::npos);
}

TEST_F(CalibrationSiteFile, BrokenFilesAreRefusedWithTheirLineAndMissingTablesSaidSo)
{
    const auto file = dir_ / "broken.toml";
    std::ofstream(file) << "[display]\nprofile = \"x\"\n[tracker\n";
    auto w = writeSiteSection(file, "tracker", "a = 1\n");
    ASSERT_FALSE(w);
    EXPECT_NE(w.error().message.find("broken.toml:3"), std::string::npos) << w.error().message;
    const auto plain = dir_ / "plain.toml";
    std::ofstream(plain) << "[display]\nprofile = \"x\"\n";
    auto t = readTrackerTransform(plain);
    ASSERT_FALSE(t);
    EXPECT_EQ(t.error().code, ErrorCode::NotFound);
    EXPECT_NE(t.error().message.find("replica calibrate tracker"), std::string::npos);
}

} // namespace
} // namespace replica::tests

namespace replica::tests {
namespace {

TEST(SiteProblemText, ATerminalEscapeFromTheFileIsShownNotRun)
{
    // The hostile-files probe: booth.id = "\x1b[31mRED\x1b[0m" reached the terminal raw from
    // 'config check' (the run log escaped it).
    const platform::SiteProblem p{"booth.id", 9, "\"\x1b[31mRED\x1b[0m\": unknown booth"};
    const auto text = platform::formatProblem("site.toml", p);
    EXPECT_EQ(text.find('\x1b'), std::string::npos) << text;
    EXPECT_EQ(text, "site.toml:9: booth.id: \"\\x1b[31mRED\\x1b[0m\": unknown booth");
}

} // namespace
} // namespace replica::tests
