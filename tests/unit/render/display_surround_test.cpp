// The display pass's cleared surround: shading only the rectangle pass 1 can light, and clearing
// the black panel around it, must give the very pixels and gamut counts of shading the whole frame.
// Every draw also checks the gamut counts against its class image, counted here.
#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include <GLES3/gl31.h>

#include <pipeline/base/data_dir.h>
#include <pipeline/display/display_profile.h>
#include <pipeline/display/nominal_display.h>
#include <pipeline/render/display_pass.h>

#include <gtest/gtest.h>

#include "../support/headless_gl.h"

namespace replica::pipeline::render {
namespace {

constexpr int kW = 64;
constexpr int kH = 40;
constexpr PixelRect kInside{11, 7, 37, 23};

// XYZ (cd/m^2) and illuminance (lux, alpha): the surround black with a flare that varies over the
// panel, the inside a spread of colours from black through in-gamut to beyond the display's peak
// and chroma.
std::vector<float> xyzFrame()
{
    std::vector<float> px(static_cast<std::size_t>(kW) * kH * 4, 0.0f);
    for (int y = 0; y < kH; ++y) {
        for (int x = 0; x < kW; ++x) {
            float* p = &px[(static_cast<std::size_t>(y) * kW + static_cast<std::size_t>(x)) * 4];
            p[3] = 150.0f + 12.0f * static_cast<float>(x) + 5.0f * static_cast<float>(y);
            const bool inside = x >= kInside.x && x < kInside.x + kInside.width && y >= kInside.y &&
                                y < kInside.y + kInside.height;
            if (inside) {
                const float u = static_cast<float>(x - kInside.x) / kInside.width;
                const float v = static_cast<float>(y - kInside.y) / kInside.height;
                p[0] = 1800.0f * u * (0.3f + v);
                p[1] = 1700.0f * u * u;
                p[2] = 700.0f * v * (1.2f - u);
            }
        }
    }
    return px;
}

struct Drawn {
    std::vector<std::uint8_t> rgba;
    display::GamutCounters counts;
};

class DisplaySurroundTest : public tests::HeadlessGlTest
{
protected:
    void SetUp() override
    {
        tests::HeadlessGlTest::SetUp();
        if (IsSkipped()) {
            return;
        }
        const std::vector<float> px = xyzFrame();
        glGenTextures(1, &xyz_);
        glBindTexture(GL_TEXTURE_2D, xyz_);
        glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, kW, kH);
        glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, kW, kH, GL_RGBA, GL_FLOAT, px.data());
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    }
    void TearDown() override
    {
        if (output_) {
            glDeleteTextures(1, &xyz_);
        }
    }

    Drawn draw(DisplayPass& pass, bool blackOutside) const
    {
        DisplayPassFrame f;
        f.pose = scene::panelPose(scene::StandModel{}, 0.3);
        f.eyeM = {0.2, 0.5, 0.4};
        f.lightXyzUnitY = {0.96, 1.0, 0.82};
        if (blackOutside) {
            f.blackOutside = kInside;
        }
        auto counts = pass.draw(xyz_, f);
        EXPECT_TRUE(counts) << counts.error().message;
        Drawn d;
        d.counts = counts ? *counts : display::GamutCounters{};
        d.rgba.resize(static_cast<std::size_t>(kW) * kH * 4);
        glBindFramebuffer(GL_FRAMEBUFFER, pass.framebuffer());
        glPixelStorei(GL_PACK_ALIGNMENT, 1);
        glReadPixels(0, 0, kW, kH, GL_RGBA, GL_UNSIGNED_BYTE, d.rgba.data());
        // The counters are the class image counted: read it back (attachment 1, class / 255 in
        // red) and count it here, pixel by pixel.
        std::vector<std::uint8_t> classes(static_cast<std::size_t>(kW) * kH * 4);
        glReadBuffer(GL_COLOR_ATTACHMENT1);
        glReadPixels(0, 0, kW, kH, GL_RGBA, GL_UNSIGNED_BYTE, classes.data());
        glReadBuffer(GL_COLOR_ATTACHMENT0);
        std::array<std::uint64_t, 4> tally{};
        for (std::size_t i = 0; i < classes.size(); i += 4) {
            EXPECT_LT(classes[i], 4) << "pixel " << i / 4;
            ++tally[std::min<std::size_t>(classes[i], 3)];
        }
        EXPECT_EQ(d.counts.pixels, static_cast<std::uint64_t>(kW) * kH);
        EXPECT_EQ(d.counts.chroma, tally[1]);
        EXPECT_EQ(d.counts.overPeak, tally[2]);
        EXPECT_EQ(d.counts.belowBlack, tally[3]);
        return d;
    }

    // Draws the frame both ways and requires the same bytes and counts; returns whether the pass
    // took the shortcut.
    bool sameBothWays(const DisplayPassSetup& setup) const
    {
        DisplayPass pass;
        auto ok = pass.init(setup, kW, kH);
        EXPECT_TRUE(ok) << ok.error().message;
        const Drawn whole = draw(pass, false);
        const Drawn cleared = draw(pass, true);
        EXPECT_EQ(whole.rgba, cleared.rgba);
        EXPECT_EQ(whole.counts.pixels, cleared.counts.pixels);
        EXPECT_EQ(whole.counts.chroma, cleared.counts.chroma);
        EXPECT_EQ(whole.counts.overPeak, cleared.counts.overPeak);
        EXPECT_EQ(whole.counts.belowBlack, cleared.counts.belowBlack);
        // The frame is not trivial: the inside holds colours of every class but in gamut ...
        EXPECT_GT(whole.counts.chroma, 0u);
        EXPECT_GT(whole.counts.overPeak, 0u);
        // ... and the surround is all below black.
        EXPECT_GE(whole.counts.belowBlack,
                  static_cast<std::uint64_t>(kW * kH - kInside.width * kInside.height));
        return pass.surroundConstant();
    }

    GLuint xyz_ = 0;
};

display::DisplayModel shippedProfile()
{
    auto profile = display::loadProfile(dataDir() / "displays" / "wide-ips-synthetic.json");
    EXPECT_TRUE(profile) << profile.error().message;
    return profile ? *profile : display::DisplayModel{};
}

TEST_F(DisplaySurroundTest, ClearedSurroundIsTheShadedSurroundAnalytic)
{
    DisplayPassSetup s;
    s.model = shippedProfile();
    EXPECT_TRUE(sameBothWays(s)) << "the shipped profile's surround should be cleared";
}

TEST_F(DisplaySurroundTest, ClearedSurroundIsTheShadedSurroundLut3d)
{
    DisplayPassSetup s;
    s.model = shippedProfile();
    s.method = InverseMethod::Lut3d;
    EXPECT_TRUE(sameBothWays(s));
}

TEST_F(DisplaySurroundTest, ClearedSurroundIsTheShadedSurroundNominalModel)
{
    DisplayPassSetup s;
    s.model = display::nominalDisplayModel("nominal", 800.0, 0.4);
    EXPECT_TRUE(sameBothWays(s));
}

TEST_F(DisplaySurroundTest, ClippingAndFalseColourShadeTheWholeFrame)
{
    // Per-channel clipping maps each surround pixel's flare-lowered XYZ on its own, and the
    // false-colour overlay stripes the surround: neither may be cleared.
    DisplayPassSetup clip;
    clip.model = shippedProfile();
    clip.gamut = display::GamutMode::Clip;
    EXPECT_FALSE(sameBothWays(clip));
    DisplayPassSetup overlay;
    overlay.model = shippedProfile();
    overlay.falseColour = true;
    EXPECT_FALSE(sameBothWays(overlay));
}

} // namespace
} // namespace replica::pipeline::render
