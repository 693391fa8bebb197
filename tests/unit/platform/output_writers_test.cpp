// Every writer of a file goes through writeOutputFile (pipeline/base/output_file.h), issue 32: the
// render plan (on the kiosk's start-up path), the site file's rewrite, PFM frames, channel bases,
// six-channel models and metamer pairs. Each one, against a symbolic link (its target untouched), a
// FIFO (no hang) and a directory, fails with one message naming the file; a good write leaves the
// file whole and no temporary file beside it. The booth and scene writers are covered through
// their commands by tests/replay/hostile_input.sh, with the full disk.
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include <sys/stat.h>

#include <pipeline/base/data_dir.h>
#include <pipeline/colour/channel_basis.h>
#include <pipeline/offline/spectral/metamers.h>
#include <pipeline/spectral/six_channel_model.h>
#include <platform/image/pfm.h>
#include <platform/render_plan.h>
#include <platform/site_file.h>

#include <gtest/gtest.h>

#include "../support/files.h"

namespace replica::tests {
namespace {
namespace fs = std::filesystem;

struct Writer {
    std::string name;
    std::string ext;
    std::function<Expected<void>(const fs::path&)> write;
};

std::vector<Writer> writers()
{
    platform::FloatImage image;
    image.width = 2;
    image.height = 1;
    image.rgba = {1, 2, 3, 1, 4, 5, 6, 1};
    platform::RenderPlan plan;
    plan.sceneDigest = "0123456789abcdef";
    plan.boothDigest = "fedcba9876543210";
    plan.basis = "adaptive_k6";
    plan.lamps["tungsten"] = {16, 8, 8, 0.886, 1.981, true};
    return {
            {"render plan", "json",
             [plan](const fs::path& p) { return platform::writeRenderPlan(p, plan); }},
            {"site file", "toml",
             [](const fs::path& p) {
                 return platform::writeSiteSection(p, "render", "error_probe = 0\n");
             }},
            {"PFM image", "pfm",
             [image](const fs::path& p) { return platform::writePfm(p, image); }},
            {"channel basis", "csv",
             [](const fs::path& p) -> Expected<void> {
                 auto basis = pipeline::colour::loadDefaultChannelBasis(dataDir());
                 if (!basis) {
                     return tl::unexpected(basis.error());
                 }
                 return pipeline::colour::saveChannelBasis(*basis, p, "a test");
             }},
            {"metamer pairs", "csv",
             [](const fs::path& p) {
                 return pipeline::spectral::saveMetamerPairs({}, p, "a test");
             }},
            {"six-channel model", "csv",
             [](const fs::path& p) {
                 return pipeline::spectral::saveSixChannelModel({}, p, "a test");
             }},
    };
}

class OutputWriters : public ::testing::Test
{
protected:
    void SetUp() override
    {
        dir_ = fs::temp_directory_path() /
               ("replica-writers-" +
                std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "-" +
                ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }
    // Only the names the test made: no temporary file left behind.
    std::vector<std::string> leftovers() const
    {
        std::vector<std::string> names;
        for (const auto& e : fs::directory_iterator(dir_)) {
            const auto n = e.path().filename().string();
            if (n.find(".tmp") != std::string::npos) {
                names.push_back(n);
            }
        }
        return names;
    }
    fs::path dir_;
};

TEST_F(OutputWriters, NeverThroughALinkNorIntoAFifoOrADirectory)
{
    for (const auto& w : writers()) {
        SCOPED_TRACE(w.name);
        const fs::path target = dir_ / ("target." + w.ext);
        const fs::path link = dir_ / ("link." + w.ext);
        const std::string precious = "# precious\n"; // a valid site file too
        std::ofstream(target) << precious;
        fs::create_symlink(target, link);
        auto viaLink = w.write(link);
        ASSERT_FALSE(viaLink);
        EXPECT_NE(viaLink.error().message.find(link.string() + ": is a symbolic link"),
                  std::string::npos)
                << viaLink.error().message;
        EXPECT_EQ(slurp(target), precious) << "written through the link";
        EXPECT_TRUE(fs::is_symlink(link));

        const fs::path fifo = dir_ / ("fifo." + w.ext);
        ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
        auto intoFifo = w.write(fifo); // before, a hang: nobody reads the FIFO
        ASSERT_FALSE(intoFifo);
        EXPECT_NE(intoFifo.error().message.find(fifo.string() + ": is a FIFO"), std::string::npos)
                << intoFifo.error().message;

        const fs::path adir = dir_ / ("adir." + w.ext);
        fs::create_directories(adir);
        auto intoDir = w.write(adir);
        ASSERT_FALSE(intoDir);
        EXPECT_NE(intoDir.error().message.find(adir.string() + ": is a directory"),
                  std::string::npos)
                << intoDir.error().message;

        const fs::path good = dir_ / ("good." + w.ext);
        auto ok = w.write(good);
        ASSERT_TRUE(ok) << ok.error().message;
        EXPECT_TRUE(fs::is_regular_file(good));
        EXPECT_GT(fs::file_size(good), 0u);
        EXPECT_EQ(leftovers(), std::vector<std::string>{});
        for (const auto& p : {target, link, fifo, adir, good}) {
            fs::remove_all(p);
        }
    }
}

} // namespace
} // namespace replica::tests
