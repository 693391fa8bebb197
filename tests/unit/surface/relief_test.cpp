// Normal and horizon maps against closed forms; scene folder round trip and its error messages.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

#include <pipeline/image/exr.h>
#include <pipeline/surface/relief.h>
#include <pipeline/surface/surface_scene.h>

#include <gtest/gtest.h>

#include "../render/render_fixtures.h"

namespace replica::pipeline::surface {
namespace {

HeightField field(int w, int h, double pitch)
{
    HeightField f;
    f.width = w;
    f.height = h;
    f.pitchM = pitch;
    f.m.assign(static_cast<std::size_t>(w) * h, 0.0);
    return f;
}

TEST(NormalMap, InclinedPlaneGivesItsExactNormal)
{
    HeightField f = field(16, 12, 0.001);
    for (int y = 0; y < 12; ++y) {
        for (int x = 0; x < 16; ++x) {
            f.m[static_cast<std::size_t>(y) * 16 + x] =
                    0.5 * x * 0.001 - 0.25 * y * 0.001; // rises along +x and +y(up)
        }
    }
    const auto n = normalMap(f);
    const double len = std::sqrt(0.25 + 0.0625 + 1.0);
    for (const auto& v : n) {
        EXPECT_NEAR(v.x, -0.5 / len, 1e-12);
        EXPECT_NEAR(v.y, -0.25 / len, 1e-12);
        EXPECT_NEAR(v.z, 1.0 / len, 1e-12);
    }
}

TEST(NormalMap, VerticalCliffStaysFinite)
{
    HeightField f = field(8, 4, 1e-4);
    for (int y = 0; y < 4; ++y) {
        for (int x = 4; x < 8; ++x) {
            f.m[static_cast<std::size_t>(y) * 8 + x] = 1.0; // 1 m step over 0.1 mm
        }
    }
    for (const auto& v : normalMap(f)) {
        EXPECT_TRUE(std::isfinite(v.x) && std::isfinite(v.z));
        EXPECT_NEAR(v.x * v.x + v.y * v.y + v.z * v.z, 1.0, 1e-12);
        EXPECT_GT(v.z, 0.0);
    }
}

// A cylinder of radius R across the rows: its normal turns by d(theta)/dv = 1 / sqrt(R^2 - v^2)
// radians per metre of height v from its crest, fastest at the rows furthest out.
HeightField cylinder(double radiusM, int w, int h, double pitch)
{
    HeightField f = field(w, h, pitch);
    for (int y = 0; y < h; ++y) {
        const double v = (y + 0.5 - 0.5 * h) * pitch;
        for (int x = 0; x < w; ++x) {
            f.m[static_cast<std::size_t>(y) * w + x] = std::sqrt(radiusM * radiusM - v * v);
        }
    }
    return f;
}

TEST(NormalTurn, APlaneFlatOrTiltedTurnsNowhere)
{
    HeightField f = field(20, 10, 0.001);
    EXPECT_EQ(largestNormalTurn(f), 0.0);
    for (int y = 0; y < 10; ++y) {
        for (int x = 0; x < 20; ++x) {
            f.m[static_cast<std::size_t>(y) * 20 + x] = 0.3 * x * 0.001 - 0.7 * y * 0.001;
        }
    }
    EXPECT_LT(largestNormalTurn(f), 1e-12);
}

TEST(NormalTurn, ACylinderTurnsAsItsCurvatureSays)
{
    for (const double radius : {0.15, 0.5, 0.09}) {
        const double pitch = 0.001;
        const int rows = 160;
        // The fastest turn is between the two outermost interior rows, whose central differences
        // stand for heights v = (rows / 2 - 1.5) pitch and (rows / 2 - 2.5) pitch from the crest.
        const double v = (rows / 2 - 2.0) * pitch;
        const double expected = pitch / std::sqrt(radius * radius - v * v);
        const double turn = largestNormalTurn(cylinder(radius, 24, rows, pitch));
        EXPECT_NEAR(turn, expected, 0.02 * expected) << "radius " << radius;
    }
    // Turned by 90 degrees (its rows become columns) it turns as fast; along its axis not at
    // all, so a one-row strip of it does not turn.
    const HeightField rows = cylinder(0.15, 24, 160, 0.001);
    HeightField columns = field(160, 24, 0.001);
    for (int y = 0; y < 24; ++y) {
        for (int x = 0; x < 160; ++x) {
            columns.m[static_cast<std::size_t>(y) * 160 + x] =
                    rows.m[static_cast<std::size_t>(x) * 24 + y];
        }
    }
    EXPECT_NEAR(largestNormalTurn(columns), largestNormalTurn(rows), 1e-15);
    EXPECT_LT(largestNormalTurn(cylinder(0.15, 24, 1, 0.001)), 1e-12);
}

TEST(NormalTurn, OneRaisedTexelTurnsItsNeighboursSharply)
{
    HeightField f = field(9, 9, 0.001);
    f.m[4 * 9 + 4] = 0.001; // one pitch high: its neighbours' central slopes are 1/2
    // A normal (0, 0, 1) beside one of slope 1/2: atan(1/2).
    EXPECT_NEAR(largestNormalTurn(f), std::atan(0.5), 1e-12);
}

TEST(HorizonMap, FlatFieldHasZeroHorizonsEverywhere)
{
    const HorizonMap m = horizonMap(field(10, 10, 0.001), 8, 0.01);
    for (float v : m.sinBeta) {
        EXPECT_EQ(v, 0.0f);
    }
}

TEST(HorizonMap, EverySlotIsItsTexelsOwnMarchWhateverThreadMadeIt)
{
    // The map's rows are made on every core: each slot must still be the march from its own
    // texel centre in its own direction, bit for bit (a row or direction written to another's
    // slot, or left unwritten, fails). A bumpy field of more rows than threads, not square.
    HeightField f = field(23, 37, 0.0005);
    for (int y = 0; y < f.height; ++y) {
        for (int x = 0; x < f.width; ++x) {
            f.m[static_cast<std::size_t>(y) * f.width + x] =
                    0.0004 * std::sin(0.9 * x + 0.3 * y) * std::cos(0.5 * y - 0.2 * x);
        }
    }
    const int dirs = 8;
    const HorizonMap m = horizonMap(f, dirs, 0.004);
    ASSERT_EQ(m.sinBeta.size(), static_cast<std::size_t>(f.width) * f.height * dirs);
    int nonZero = 0;
    for (int y = 0; y < f.height; ++y) {
        for (int x = 0; x < f.width; ++x) {
            for (int k = 0; k < dirs; ++k) {
                const double phi = 2.0 * std::numbers::pi * k / dirs;
                const float want =
                        static_cast<float>(exactSinHorizon(f, x + 0.5, y + 0.5, phi, 0.004));
                const float got = m.sinBeta[(static_cast<std::size_t>(y) * f.width + x) * dirs + k];
                ASSERT_EQ(got, want) << "texel " << x << "," << y << " direction " << k;
                nonZero += got > 0.0f;
            }
        }
    }
    EXPECT_GT(nonZero, 100); // the field casts horizons: the comparison is not of zeros
}

TEST(HorizonMap, HalfPrecisionRoundsEachSineToTheNearestHalfFloat)
{
    HorizonMap m;
    m.width = 2;
    m.height = 1;
    m.directions = 4;
    // 0.1: binary16 0x2E66 = 1638 / 16384; 0.5 and 0 are exact; 0.999: nearest 2046 / 2048;
    // 1/3: 0x3555 = 1365 / 4096; 1e-5: a subnormal half, 168 / 2^24.
    m.sinBeta = {0.1f, 0.5f, 0.0f, 0.999f, 1.0f / 3.0f, 1e-5f, 0.75f, 0.2f};
    const HorizonMap h = halfPrecision(m);
    ASSERT_EQ(h.sinBeta.size(), m.sinBeta.size());
    EXPECT_EQ(h.directions, 4);
    EXPECT_EQ(h.sinBeta[0], 1638.0f / 16384.0f);
    EXPECT_EQ(h.sinBeta[1], 0.5f);
    EXPECT_EQ(h.sinBeta[2], 0.0f);
    EXPECT_EQ(h.sinBeta[3], 2046.0f / 2048.0f);
    EXPECT_EQ(h.sinBeta[4], 1365.0f / 4096.0f);
    EXPECT_EQ(h.sinBeta[5], 168.0f / 16777216.0f);
    for (std::size_t i = 0; i < m.sinBeta.size(); ++i) {
        EXPECT_LE(std::abs(h.sinBeta[i] - m.sinBeta[i]), 1.0f / 4096.0f) << i;
    }
}

TEST(HorizonMap, WallGivesItsElevationInItsDirectionOnly)
{
    // A 2 mm wall 5 mm to the right (+x) of the texel: sin(atan(2/5)) towards +x, nothing towards
    // -x.
    HeightField f = field(40, 9, 0.001);
    for (int y = 0; y < 9; ++y) {
        for (int x = 25; x < 27; ++x) {
            f.m[static_cast<std::size_t>(y) * 40 + x] = 0.002;
        }
    }
    const HorizonMap m = horizonMap(f, 8, 0.02);
    const int x = 20,
              y = 4; // texel centre 20.5: the wall's face is at 25 - 0.5 pitch of bilinear ramp
    const float* b = &m.sinBeta[(static_cast<std::size_t>(y) * 40 + x) * 8];
    const double peak = std::sin(std::atan(0.002 / 0.005)); // top reached 5 texels away
    EXPECT_NEAR(b[0], peak, 0.03);
    EXPECT_EQ(b[4], 0.0f);
    // Interpolation between directions is linear in azimuth.
    EXPECT_NEAR(m.sinHorizon(x, y, Vec3(1.0, 0.0, 0.5)), b[0], 1e-6);
    const Vec3 halfway(std::cos(M_PI / 8), std::sin(M_PI / 8), 0.3);
    EXPECT_NEAR(m.sinHorizon(x, y, halfway), 0.5 * (b[0] + b[1]), 1e-6);
    // Bilinear between texel centres: a centre gives the texel's own, halfway to the next
    // column the mean of the two, and past the last centre the edge texel's (clamped).
    const Vec3 east(1.0, 0.0, 0.5);
    EXPECT_DOUBLE_EQ(m.sinHorizonBilinear(x + 0.5, y + 0.5, east), m.sinHorizon(x, y, east));
    EXPECT_NEAR(m.sinHorizonBilinear(x + 1.0, y + 0.5, east),
                0.5 * (m.sinHorizon(x, y, east) + m.sinHorizon(x + 1, y, east)), 1e-12);
    EXPECT_NEAR(m.sinHorizonBilinear(x + 0.75, y + 1.0, east),
                0.25 * 0.5 * (m.sinHorizon(x + 1, y, east) + m.sinHorizon(x + 1, y + 1, east)) +
                        0.75 * 0.5 * (m.sinHorizon(x, y, east) + m.sinHorizon(x, y + 1, east)),
                1e-12);
    EXPECT_DOUBLE_EQ(m.sinHorizonBilinear(40.0, 0.0, east), m.sinHorizon(39, 0, east));
    // A cliff face: horizons approach 90 degrees but stay finite.
    HeightField cliff = field(10, 3, 1e-4);
    for (int y2 = 0; y2 < 3; ++y2) {
        cliff.m[static_cast<std::size_t>(y2) * 10 + 6] = 1.0;
    }
    const double s = exactSinHorizon(cliff, 5.5, 1.5, 0.0, 0.01);
    EXPECT_TRUE(std::isfinite(s));
    EXPECT_GT(s, 0.999);
    EXPECT_LE(s, 1.0);
}

std::filesystem::path freshDir(const std::string& name)
{
    auto d = std::filesystem::temp_directory_path() / ("replica_scene_test_" + name);
    std::filesystem::remove_all(d);
    return d;
}

TEST(SceneFolder, RoundTrips)
{
    const SurfaceScene s = test::testScene(20, 10, true, true);
    const auto dir = freshDir("roundtrip");
    ASSERT_TRUE(saveScene(dir, s));
    auto r = loadScene(dir);
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_EQ(r->width, 20);
    EXPECT_EQ(r->palette.size(), 2u);
    EXPECT_DOUBLE_EQ(r->alpha, 0.1);
    EXPECT_EQ(r->model, brdf::WardModel::WardDurGuarded);
    EXPECT_TRUE(r->glossy());
    EXPECT_FALSE(r->flat());
    for (int x : {0, 15}) {
        const auto a = r->reflectance(x, 3);
        const auto b = s.reflectance(x, 3);
        for (std::size_t k = 0; k < colour::kBands; ++k) {
            EXPECT_DOUBLE_EQ(a[k], b[k]);
        }
    }
    EXPECT_FLOAT_EQ(static_cast<float>(r->relief.m[33]), static_cast<float>(s.relief.m[33]));
    // channels.exr holds the box6 projection of each texel's spectrum.
    auto ch = image::readExr(dir / "channels.exr", {"c0", "c5"});
    ASSERT_TRUE(ch) << ch.error().message;
    const auto c = colour::projectReflectance(colour::boxBasis(), s.reflectance(15, 3));
    EXPECT_NEAR((*ch->plane("c5"))[3 * 20 + 15], c[5], 1e-6);
}

TEST(SceneFolder, ErrorsNameTheFileAndTheProblem)
{
    SurfaceScene s = test::testScene(20, 10, false, false);
    auto dir = freshDir("badindex");
    ASSERT_TRUE(saveScene(dir, s));
    {
        // saveScene refuses such a scene, so damage the file on disk: no such palette entry.
        auto bad = s;
        bad.pigmentB[47] = 5;
        auto refused = saveScene(freshDir("refused"), bad);
        ASSERT_FALSE(refused);
        EXPECT_NE(refused.error().message.find("texel (7, 2)"), std::string::npos)
                << refused.error().message;
        auto mat = image::readExr(dir / "material.exr", {"A", "B", "mix", "shade"});
        ASSERT_TRUE(mat) << mat.error().message;
        mat->planes[1][47] = 5.0f;
        ASSERT_TRUE(image::writeExr(dir / "material.exr", *mat));
    }
    auto r = loadScene(dir);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("material.exr: texel (7, 2): pigment index"),
              std::string::npos)
            << r.error().message;

    dir = freshDir("noheight");
    s = test::testScene(20, 10, false, false);
    ASSERT_TRUE(saveScene(dir, s));
    std::filesystem::remove(dir / "height.exr");
    r = loadScene(dir);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("height.exr: no such file"), std::string::npos)
            << r.error().message;

    dir = freshDir("nanheight");
    ASSERT_TRUE(saveScene(dir, s));
    image::ChannelImage h;
    h.width = 20;
    h.height = 10;
    h.names = {"H"};
    h.planes.assign(1, std::vector<float>(200, 0.0f));
    h.planes[0][3 * 20 + 4] = INFINITY;
    ASSERT_TRUE(image::writeExr(dir / "height.exr", h));
    r = loadScene(dir);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("pixel (4, 3) is inf"), std::string::npos)
            << r.error().message;

    dir = freshDir("badjson");
    ASSERT_TRUE(saveScene(dir, s));
    std::ofstream(dir / "scene.json")
            << R"({"format":"replica-scene/1","size_m":[0.2,0.1],"palette":[{"reflectance":[1,2]}]})";
    r = loadScene(dir);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find(
                      "scene.json: /palette/0/reflectance: expected an array of 36 items"),
              std::string::npos)
            << r.error().message;
}

} // namespace
} // namespace replica::pipeline::surface
