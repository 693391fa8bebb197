// Capture path: a synthetic bracketed series made from a known HDR image, a known camera response
// and a known homography must come back as the same luminance image on the ceiling.
#include <algorithm>
#include <cmath>

#include <pipeline/base/data_dir.h>
#include <pipeline/offline/booth/booth_generator.h>
#include <pipeline/offline/booth/hdr_capture.h>

#include <gtest/gtest.h>

namespace replica::pipeline::booth {
namespace {

// A camera with an S-shaped response: z = 255 * (x / (x + 1))^(1/1.8) of exposure x, quantised.
std::uint8_t camera(double exposure)
{
    const double x = std::max(exposure, 0.0);
    return static_cast<std::uint8_t>(
            std::clamp(std::lround(255.0 * std::pow(x / (x + 1.0), 1.0 / 1.8)), 0L, 255L));
}

struct Synthetic {
    LuminanceImage truth; // on the ceiling, cd/m^2
    Homography toImage;
    std::vector<Exposure> series;
    int imageW = 320, imageH = 240;
};

Synthetic makeSeries()
{
    Synthetic s;
    CeilingGeometry g;
    g.texelsX = 64;
    g.texelsZ = 32;
    s.truth = generateShippedBooth(dataDir(), g)->lights[1].luminance; // the striped D50 light
    s.toImage = *homographyFromCorners(
            {glm::dvec2(40, 30), glm::dvec2(290, 45), glm::dvec2(280, 200), glm::dvec2(50, 215)});
    // Render the camera's view: for each image pixel, invert the homography numerically (2x2
    // Newton).
    LuminanceImage scene = LuminanceImage::filled(s.imageW, s.imageH, 0.0);
    for (int y = 0; y < s.imageH; ++y) {
        for (int x = 0; x < s.imageW; ++x) {
            double u = 0.5, v = 0.5;
            for (int it = 0; it < 20; ++it) {
                const auto p = s.toImage.apply(u, v);
                const auto pu = s.toImage.apply(u + 1e-6, v);
                const auto pv = s.toImage.apply(u, v + 1e-6);
                const double a = (pu.x - p.x) / 1e-6, b = (pv.x - p.x) / 1e-6;
                const double c = (pu.y - p.y) / 1e-6, d = (pv.y - p.y) / 1e-6;
                const double ex = x + 0.5 - p.x, ey = y + 0.5 - p.y;
                const double det = a * d - b * c;
                u += (d * ex - b * ey) / det;
                v += (-c * ex + a * ey) / det;
            }
            if (u >= 0 && u < 1 && v >= 0 && v < 1) {
                scene.at(x, y) = s.truth.at(static_cast<int>(u * s.truth.width),
                                            static_cast<int>(v * s.truth.height));
            } else {
                scene.at(x, y) = 5.0; // dim booth wall around the diffuser
            }
        }
    }
    for (double t : {1.0 / 4000, 1.0 / 1000, 1.0 / 250, 1.0 / 60, 1.0 / 15, 1.0 / 4}) {
        Exposure e;
        e.width = s.imageW;
        e.height = s.imageH;
        e.seconds = t;
        for (double l : scene.cdM2) {
            e.z.push_back(
                    camera(l * t * 0.5)); // 0.5: the unknown sensor gain the calibration removes
        }
        s.series.push_back(std::move(e));
    }
    return s;
}

TEST(HdrCapture, RecoversTheResponseAndTheCalibratedCeilingImage)
{
    const Synthetic s = makeSeries();
    auto curve = recoverResponse(s.series);
    ASSERT_TRUE(curve) << curve.error().message;
    // The recovered curve is the log inverse of the camera up to a constant: compare slopes.
    const auto inv = [](double z) {
        const double y = std::pow(z / 255.0, 1.8);
        return std::log(y / (1.0 - y));
    };
    for (int z : {40, 80, 160, 220}) {
        EXPECT_NEAR(curve->g[static_cast<std::size_t>(z)] - curve->g[128], inv(z) - inv(128), 0.05)
                << z;
    }
    auto hdr = mergeHdr(s.series, *curve);
    ASSERT_TRUE(hdr) << hdr.error().message;
    // Calibrate with a spot reading in the middle of the ceiling (a luminance meter on texel
    // 32,16).
    const auto spotPx = s.toImage.apply(32.5 / 64, 16.5 / 32);
    const double rel = hdr->at(static_cast<int>(spotPx.x), static_cast<int>(spotPx.y));
    const double scale = s.truth.at(32, 16) / rel;
    for (double& v : hdr->cdM2) {
        v *= scale;
    }
    auto warped = warpToCeiling(*hdr, s.toImage, 64, 32);
    ASSERT_TRUE(warped) << warped.error().message;
    // Away from sharp stripe edges (where resampling blurs), texels come back within a few percent.
    std::vector<double> errs;
    for (int y = 2; y < 30; ++y) {
        for (int x = 2; x < 62; ++x) {
            errs.push_back(std::abs(warped->at(x, y) / s.truth.at(x, y) - 1.0));
        }
    }
    std::sort(errs.begin(), errs.end());
    EXPECT_LT(errs[errs.size() / 2], 0.03);                // median
    EXPECT_LT(errs[errs.size() * 9 / 10], 0.12);           // 90th percentile (stripe edges)
    EXPECT_NEAR(warped->sum() / s.truth.sum(), 1.0, 0.03); // power
}

TEST(HdrCapture, RejectsBadSeries)
{
    Synthetic s = makeSeries();
    std::vector<Exposure> one(s.series.begin(), s.series.begin() + 1);
    EXPECT_FALSE(recoverResponse(one));
    auto bad = s.series;
    bad[2].seconds = 0.0;
    auto r = recoverResponse(bad);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("exposure 2: time must be > 0"), std::string::npos);
    // Saturated everywhere in every exposure at one pixel: named.
    auto curve = recoverResponse(s.series);
    auto sat = s.series;
    for (auto& e : sat) {
        e.z[5 * 320 + 7] = 255;
    }
    auto m = mergeHdr(sat, *curve);
    ASSERT_FALSE(m);
    EXPECT_NE(m.error().message.find("pixel (7, 5) is saturated in every exposure"),
              std::string::npos);
    // Collinear corners cannot define a homography; a corner outside the capture is refused.
    EXPECT_FALSE(homographyFromCorners(
            {glm::dvec2(0, 0), glm::dvec2(1, 1), glm::dvec2(2, 2), glm::dvec2(3, 3)}));
    const auto far = *homographyFromCorners(
            {glm::dvec2(0, 0), glm::dvec2(900, 0), glm::dvec2(900, 900), glm::dvec2(0, 900)});
    auto w = warpToCeiling(LuminanceImage::filled(320, 240, 1.0), far, 8, 8);
    ASSERT_FALSE(w);
    EXPECT_NE(w.error().message.find("outside the 320x240 capture"), std::string::npos);
}

TEST(HomographyFromCorners, MapsTheCornersExactly)
{
    const std::array<glm::dvec2, 4> c{glm::dvec2(12, 7), glm::dvec2(300, 20), glm::dvec2(280, 190),
                                      glm::dvec2(5, 170)};
    const auto h = *homographyFromCorners(c);
    const double uv[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (int k = 0; k < 4; ++k) {
        const auto p = h.apply(uv[k][0], uv[k][1]);
        EXPECT_NEAR(p.x, c[static_cast<std::size_t>(k)].x, 1e-9);
        EXPECT_NEAR(p.y, c[static_cast<std::size_t>(k)].y, 1e-9);
    }
}

} // namespace
} // namespace replica::pipeline::booth
