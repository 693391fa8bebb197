// 'replica render', 'replica booth' and 'replica scene' as a person runs them: exit codes, one-line
// errors, and EXR frames with no NaN/Inf that agree with the reference.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <sys/wait.h>
#include <unistd.h>

#include <pipeline/base/data_dir.h>
#include <pipeline/colour/ciede2000.h>
#include <pipeline/colour/cielab.h>
#include <pipeline/image/exr.h>

#include <gtest/gtest.h>

namespace replica {
namespace {

struct CliResult {
    int code = -1;
    std::string err;
};

CliResult run(const std::string& args)
{
    // One file per process and call: ctest runs this binary's tests side by side, and a shared
    // name let one test read another's (or a truncated) stderr.
    static int calls = 0;
    const auto errFile = std::filesystem::temp_directory_path() /
                         ("replica_render_cli_err_" + std::to_string(::getpid()) + "_" +
                          std::to_string(calls++) + ".txt");
    const std::string cmd =
            std::string(REPLICA_BINARY) + " " + args + " >/dev/null 2>" + errFile.string();
    const int status = std::system(cmd.c_str());
    CliResult r;
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    std::ifstream in(errFile);
    std::stringstream ss;
    ss << in.rdbuf();
    r.err = ss.str();
    std::filesystem::remove(errFile);
    return r;
}

const std::string kScenes = (dataDir() / "scenes").string();

TEST(RenderCli, RejectsBadArgumentsWithOneLine)
{
    CliResult r = run("render --scene " + kScenes + "/metamer --light neon --out /tmp/x.exr");
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("--light 'neon' is not in the booth; choose one of: tungsten, "
                         "d50-fluorescent, d65-fluorescent"),
              std::string::npos)
            << r.err;
    r = run("render --scene " + kScenes + "/metamer --light d65 --eye 1,2 --out /tmp/x.exr");
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("--eye '1,2' must be X,Y,Z"), std::string::npos) << r.err;
    r = run("render --scene /nonexistent --light d65 --out /tmp/x.exr");
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find("/nonexistent/scene.json: cannot open scene manifest"), std::string::npos)
            << r.err;
    r = run("render --scene " + kScenes + "/metamer --light d65 --size 0x5 --out /tmp/x.exr");
    EXPECT_EQ(r.code, 2);
    r = run("render --scene " + kScenes +
            "/painting --light d65 --specular-lod-bias 9 --out /tmp/x.exr");
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("--specular-lod-bias"), std::string::npos) << r.err;
    // More lights than the GL pass holds: refused with one line, not dropped silently.
    r = run("render --scene " + kScenes +
            "/metamer --light d65-fluorescent --gl --lights 257 --out /tmp/x.exr");
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("--lights 257: the GL pass holds at most 256 lights"), std::string::npos)
            << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    r = run("scene generate --kind teapot --out /tmp/replica_teapot");
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("unknown scene kind 'teapot'"), std::string::npos) << r.err;
    r = run("booth build --capture /nonexistent/capture.json --out /tmp/replica_booth_x");
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find("/nonexistent/capture.json: cannot open"), std::string::npos) << r.err;
}

// --basis: adaptive_k6 (the default) builds the basis for the light rendered. On the D65-matched
// metamer target under the D65 tube light, where the fixed replica_k6 basis misses (the shipped
// metamer's tungsten pairs were grown inside replica_k6's span, so it cannot tell the two apart),
// it lands far closer to the exact reference (CIEDE2000 against the reference's brightest pixel as
// white).
TEST(RenderCli, AdaptiveBasisIsTheDefaultAndCloserToTheReferenceOnTheMetamer)
{
    const auto dir = std::filesystem::temp_directory_path();
    const std::string common = "render --scene " + kScenes +
                               "/metamer-d65 --light d65-fluorescent --size 24x16 --lights 64 ";
    const std::string ref = (dir / "replica_cli_metamer_ref.exr").string();
    ASSERT_EQ(run(common + "--reference --out " + ref).code, 0);
    auto b = pipeline::image::readExr(ref, {"X", "Y", "Z"});
    ASSERT_TRUE(b) << b.error().message;
    std::size_t brightest = 0;
    for (std::size_t k = 0; k < b->planes[1].size(); ++k) {
        brightest = b->planes[1][k] > b->planes[1][brightest] ? k : brightest;
    }
    const auto xyz = [](const pipeline::image::ChannelImage& img, std::size_t k) {
        return pipeline::colour::Xyz(img.planes[0][k], img.planes[1][k], img.planes[2][k]);
    };
    const pipeline::colour::Xyz white = xyz(*b, brightest);
    const auto meanDe = [&](const std::string& basisArgs) {
        const std::string out = (dir / "replica_cli_metamer_basis.exr").string();
        const CliResult r = run(common + basisArgs + "--out " + out);
        EXPECT_EQ(r.code, 0) << r.err;
        auto a = pipeline::image::readExr(out, {"X", "Y", "Z"});
        EXPECT_TRUE(a);
        double sum = 0.0;
        for (std::size_t k = 0; a && k < a->planes[1].size(); ++k) {
            sum += pipeline::colour::ciede2000(pipeline::colour::xyzToLab(xyz(*a, k), white),
                                               pipeline::colour::xyzToLab(xyz(*b, k), white));
        }
        return a ? sum / static_cast<double>(a->planes[1].size()) : 1e9;
    };
    const double byDefault = meanDe("");
    const double adaptive = meanDe("--basis adaptive_k6 ");
    const double fixed = meanDe("--basis replica_k6 ");
    EXPECT_EQ(byDefault, adaptive);
    EXPECT_LT(adaptive, 0.5 * fixed) << adaptive << " vs " << fixed;
    const CliResult bad = run(common + "--basis k7 --out /tmp/x.exr");
    EXPECT_EQ(bad.code, 2);
    EXPECT_NE(bad.err.find("k7"), std::string::npos) << bad.err;
}

TEST(RenderCli, WritesFiniteAbsoluteXyzCloseToTheReference)
{
    const auto dir = std::filesystem::temp_directory_path();
    const std::string fast = (dir / "replica_cli_fast.exr").string();
    const std::string ref = (dir / "replica_cli_ref.exr").string();
    const std::string common = "render --scene " + kScenes +
                               "/colorchecker --light d50 --eye 0,0.45,0.7 --tilt 35 --size 24x16 ";
    ASSERT_EQ(run(common + "--lights 128 --samples 32 --out " + fast).code, 0);
    ASSERT_EQ(run(common + "--reference --out " + ref).code, 0);
    auto a = pipeline::image::readExr(fast, {"X", "Y", "Z"});
    auto b = pipeline::image::readExr(ref, {"X", "Y", "Z"});
    ASSERT_TRUE(a) << a.error().message; // readExr itself rejects NaN/Inf
    ASSERT_TRUE(b) << b.error().message;
    double sumA = 0.0, sumB = 0.0;
    for (std::size_t k = 0; k < a->planes[1].size(); ++k) {
        EXPECT_GE(a->planes[1][k], 0.0f);
        sumA += a->planes[1][k];
        sumB += b->planes[1][k];
    }
    EXPECT_GT(sumB, 0.0);
    EXPECT_NEAR(sumA / sumB, 1.0, 0.02); // mean luminance within 2 % of the reference

    // --gl: the same frame from the GLES pass the appliance runs (skipped without EGL).
    const std::string gl = (dir / "replica_cli_gl.exr").string();
    const CliResult g = run(common + "--lights 128 --samples 32 --gl --out " + gl);
    if (g.code != 0 && g.err.find("EGL") != std::string::npos) {
        GTEST_SKIP() << g.err;
    }
    ASSERT_EQ(g.code, 0) << g.err;
    auto c = pipeline::image::readExr(gl, {"X", "Y", "Z"});
    ASSERT_TRUE(c) << c.error().message;
    for (std::size_t k = 0; k < a->planes[1].size(); ++k) {
        EXPECT_NEAR(c->planes[1][k], a->planes[1][k], 1e-4 * a->planes[1][k] + 1e-3) << k;
    }
}

// --shading-only (the paper's Fig. 3): every texel a neutral white, so the ColorChecker's 24
// colours all take the light's chromaticity and only their shading differs; without it they spread.
TEST(RenderCli, ShadingOnlyLeavesOnlyTheLightsColour)
{
    const auto dir = std::filesystem::temp_directory_path();
    const auto spread = [&](const std::string& extra) {
        const std::string out =
                (dir / ("replica_cli_shading_" + std::to_string(::getpid()) + ".exr")).string();
        const CliResult r = run("render --scene " + kScenes +
                                "/colorchecker --light tungsten --tilt 10 --size 55x37 " + extra +
                                "--out " + out);
        EXPECT_EQ(r.code, 0) << r.err;
        auto img = pipeline::image::readExr(out, {"X", "Y", "Z"});
        EXPECT_TRUE(img);
        double lo = 1.0, hi = 0.0;
        for (std::size_t k = 0; img && k < img->planes[1].size(); ++k) {
            const double s = img->planes[0][k] + img->planes[1][k] + img->planes[2][k];
            if (s > 0.0) {
                lo = std::min(lo, img->planes[0][k] / s);
                hi = std::max(hi, img->planes[0][k] / s);
            }
        }
        std::filesystem::remove(out);
        return hi - lo; // the spread of chromaticity x over the frame
    };
    EXPECT_LT(spread("--shading-only "), 0.002);
    EXPECT_GT(spread(""), 0.1);
}

} // namespace
} // namespace replica
