// The site file: a calibration section replaces only itself (comments and other sections stay),
// reads back to the transform written, and a broken file is refused naming its line.
#include <filesystem>
#include <fstream>
#include <sstream>

#include <glm/geometric.hpp>
#include <unistd.h>

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

TEST_F(CalibrationSiteFile, TrackerSectionReplacesOnlyItselfAndReadsBack)
{
    const auto file = dir_ / "replica.toml";
    std::ofstream(file) << "# site of booth 7\n[display]\nprofile = \"panel.json\" # measured\n\n"
                           "[tracker]\nold = 1\n\n[tracker.extra]\nx = 2\n\n[sources]\n"
                           "tracker = \"hid\"\n";
    pipeline::scene::RigidFit fit;
    // A quarter turn about y and a translation.
    fit.T_booth_tracker.rotation = glm::dmat3(glm::dvec3{0.0, 0.0, -1.0}, glm::dvec3{0.0, 1.0, 0.0},
                                              glm::dvec3{1.0, 0.0, 0.0});
    fit.T_booth_tracker.translation = {0.1, 0.42, -0.05};
    fit.residualsM = {0.001, 0.002, 0.0015};
    fit.rmsM = 0.0016;
    fit.worst = 1;
    ASSERT_TRUE(writeSiteSection(file, "tracker", trackerSection(fit, 3)));
    const std::string text = slurp(file);
    EXPECT_NE(text.find("# site of booth 7"), std::string::npos);
    EXPECT_NE(text.find("profile = \"panel.json\" # measured"), std::string::npos);
    EXPECT_NE(text.find("[sources]\ntracker = \"hid\""), std::string::npos);
    EXPECT_EQ(text.find("old = 1"), std::string::npos);
    EXPECT_EQ(text.find("[tracker.extra]"), std::string::npos);
    auto t = readTrackerTransform(file);
    ASSERT_TRUE(t) << t.error().message;
    const glm::dvec3 p{0.3, -0.2, 0.7};
    EXPECT_LT(glm::length(t->apply(p) - fit.T_booth_tracker.apply(p)), 1e-8);
    // Written twice: still one [tracker] table.
    ASSERT_TRUE(writeSiteSection(file, "tracker", trackerSection(fit, 3)));
    const std::string again = slurp(file);
    EXPECT_EQ(again.find("[tracker]"), again.rfind("[tracker]"));
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
