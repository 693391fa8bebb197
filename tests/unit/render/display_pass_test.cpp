// The GPU display pass against the CPU display model, with the shipped profile: flare subtraction
// and viewing-angle compensation per pixel, both inverse methods, and the per-frame gamut counts.
// Pass 1's frame is made here as the booth pass leaves it: XYZ, the illuminance in alpha.
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include <glm/geometric.hpp>

#include <pipeline/base/data_dir.h>
#include <pipeline/colour/channel_basis.h>
#include <pipeline/display/display_inverse.h>
#include <pipeline/display/display_profile.h>
#include <pipeline/render/display_pass.h>
#include <pipeline/render/gl_program.h>
#include <pipeline/render/renderer.h>
#include <pipeline/scene/booth.h>

#include <gtest/gtest.h>

#include "../support/headless_gl.h"

namespace replica::pipeline::render {
namespace {

constexpr int kPassW = 64;
constexpr int kPassH = 40;

class DisplayPassTest : public tests::HeadlessGlTest
{
protected:
    void SetUp() override
    {
        tests::HeadlessGlTest::SetUp();
        if (IsSkipped()) {
            return;
        }
        auto profile = display::loadProfile(dataDir() / "displays" / "wide-ips-synthetic.json");
        ASSERT_TRUE(profile) << profile.error().message;
        profile_ = *profile;
        auto booth = scene::loadDefaultBooth(dataDir().string());
        auto observer = colour::loadCie1931(dataDir());
        ASSERT_TRUE(booth && observer) << "shipped booth and observer";
        light_ = booth->lights[0].referenceSpectrum;
        observer_ = *observer;
    }

    // The illuminance on the panel (lux) at pixel (x, y): rising across the panel, at a level
    // where the grey below is well inside the profile's gamut.
    double illuminance(int x, int y) const
    {
        const double u = (x + 0.5) / kPassW;
        const double v = (y + 0.5) / kPassH;
        return 0.5 * std::numbers::pi * profile_.whiteXyz().y * (1.0 + 0.5 * u + 0.3 * v);
    }

    // Pass 1's frame as the booth pass leaves it: XYZ (cd/m^2) with the illuminance on the panel
    // in alpha. Left half a grey of 'reflectance', right half a saturated red (out of gamut at the
    // booth's light level), both in the box basis under the booth's first lamp (paper eq. 2).
    std::vector<float> pass1(double reflectance) const
    {
        const colour::ChannelToXyz m = colour::channelToXyz(colour::boxBasis(), observer_, light_);
        const std::array<double, colour::kChannels> grey{reflectance, reflectance, reflectance,
                                                         reflectance, reflectance, reflectance};
        const std::array<double, colour::kChannels> red{0.0, 0.0, 0.0, 0.02, 0.6, 0.9};
        std::vector<float> px;
        for (int y = 0; y < kPassH; ++y) {
            for (int x = 0; x < kPassW; ++x) {
                const double e = illuminance(x, y);
                const auto& c = x < kPassW / 2 ? grey : red;
                glm::dvec3 xyz(0.0);
                for (std::size_t k = 0; k < colour::kChannels; ++k) {
                    xyz += c[k] * m[k];
                }
                xyz *= e / std::numbers::pi;
                px.insert(px.end(), {static_cast<float>(xyz.x), static_cast<float>(xyz.y),
                                     static_cast<float>(xyz.z), static_cast<float>(e)});
            }
        }
        return px;
    }

    // Pass 2 of pass1(reflectance) with the display set-up 'setup_' (the profile, 'method'):
    // the XYZ it read and the counts it drove.
    RenderedFrame draw(InverseMethod method, double reflectance)
    {
        RenderedFrame f;
        f.width = kPassW;
        f.height = kPassH;
        f.xyz = pass1(reflectance);
        GLuint tex = 0;
        glGenTextures(1, &tex);
        glBindTexture(GL_TEXTURE_2D, tex);
        glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, kPassW, kPassH);
        glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, kPassW, kPassH, GL_RGBA, GL_FLOAT, f.xyz.data());
        DisplayPassSetup setup = setup_;
        setup.model = profile_;
        setup.method = method;
        DisplayPass pass;
        auto ok = pass.init(setup, kPassW, kPassH);
        EXPECT_TRUE(ok) << (ok ? "" : ok.error().message);
        if (ok) {
            auto counts = pass.draw(tex, frame());
            EXPECT_TRUE(counts);
            f.gamut = counts ? *counts : display::GamutCounters{};
            f.rgba.assign(static_cast<std::size_t>(kPassW * kPassH * 4), 0);
            glBindFramebuffer(GL_FRAMEBUFFER, pass.framebuffer());
            glReadBuffer(GL_COLOR_ATTACHMENT0);
            glPixelStorei(GL_PACK_ALIGNMENT, 1);
            glReadPixels(0, 0, kPassW, kPassH, GL_RGBA, GL_UNSIGNED_BYTE, f.rgba.data());
        }
        glDeleteTextures(1, &tex);
        return f;
    }

    // The panel tilted 0.3 rad, the eye off to one side and close: angles up to ~40 deg.
    DisplayPassFrame frame() const
    {
        DisplayPassFrame df;
        df.pose = scene::panelPose(scene::StandModel{}, 0.3);
        df.eyeM = {0.25, 0.55, 0.35};
        const colour::Xyz light = colour::spectrumToXyz(observer_, light_);
        df.lightXyzUnitY = light / light.y;
        return df;
    }

    // What the pass should drive, from the CPU model: (XYZ - flare) / viewing gain, inverted; the
    // flare from the illuminance pass 1 left in alpha.
    display::InverseResult
    expected(const display::DisplayInverse& inv, const RenderedFrame& f, int x, int y) const
    {
        const DisplayPassFrame df = frame();
        const auto& pose = df.pose;
        const glm::dvec3 p = pose.cornerM() + (x + 0.5) / f.width * pose.rightEdgeM() +
                             (y + 0.5) / f.height * pose.upEdgeM();
        const double e = f.xyz[(static_cast<std::size_t>(y) * static_cast<std::size_t>(f.width) +
                                static_cast<std::size_t>(x)) *
                                       4 +
                               3];
        const glm::dvec3 flare = display::frontSurfaceFlareXyz(profile_, e, df.lightXyzUnitY);
        const double angle = display::viewingAngleDeg(p, pose.normal, df.eyeM);
        const glm::dvec3 gain = display::viewingGain(profile_.viewing, profile_.whiteXyz(), angle);
        const std::size_t i = (static_cast<std::size_t>(y) * static_cast<std::size_t>(f.width) +
                               static_cast<std::size_t>(x)) *
                              4;
        const glm::dvec3 xyz{f.xyz[i], f.xyz[i + 1], f.xyz[i + 2]};
        return inv.invert((xyz - flare) / gain);
    }

    // Every pixel of `f` drives what `inv` says (within the dither's one count); `moved` counts
    // the pixels where `other` would drive a channel more than two counts differently, so that a
    // test can show its setting changes the frame at all.
    void expectDrivenBy(const display::DisplayInverse& inv,
                        const display::DisplayInverse& other,
                        const RenderedFrame& f,
                        int& moved) const
    {
        moved = 0;
        for (int y = 0; y < f.height; ++y) {
            for (int x = 0; x < f.width; ++x) {
                const auto want = expected(inv, f, x, y);
                const auto without = expected(other, f, x, y);
                bool differs = false;
                const std::size_t i =
                        (static_cast<std::size_t>(y) * static_cast<std::size_t>(f.width) +
                         static_cast<std::size_t>(x)) *
                        4;
                for (int c = 0; c < 3; ++c) {
                    differs = differs || std::abs(want.counts[c] - without.counts[c]) > 2.0;
                    const double got = f.rgba[i + static_cast<std::size_t>(c)];
                    ASSERT_GE(got, std::floor(want.counts[c] - 0.02) - 1e-9) << x << "," << y;
                    ASSERT_LE(got, std::ceil(want.counts[c] + 0.02) + 1e-9) << x << "," << y;
                }
                moved += differs ? 1 : 0;
            }
        }
    }

    display::DisplayModel profile_;
    colour::Spectrum light_;
    colour::Observer observer_;
    DisplayPassSetup setup_; // what draw() passes on, with the profile and the method
};

TEST_F(DisplayPassTest, AnalyticPassMatchesTheCpuModelWithFlareAndViewingAngle)
{
    const RenderedFrame f = draw(InverseMethod::Analytic, 0.35);
    auto inv = display::DisplayInverse::build(profile_);
    ASSERT_TRUE(inv);
    std::uint64_t cpuOut = 0;
    for (int y = 0; y < f.height; ++y) {
        for (int x = 0; x < f.width; ++x) {
            const auto want = expected(*inv, f, x, y);
            cpuOut += want.inGamut() ? 0 : 1;
            const std::size_t i =
                    (static_cast<std::size_t>(y) * 64 + static_cast<std::size_t>(x)) * 4;
            for (int c = 0; c < 3; ++c) {
                // Dither adds [0, 1) before the floor; float vs double adds a little more.
                const double got = f.rgba[i + static_cast<std::size_t>(c)];
                ASSERT_GE(got, std::floor(want.counts[c] - 0.02) - 1e-9) << x << "," << y;
                ASSERT_LE(got, std::ceil(want.counts[c] + 0.02) + 1e-9) << x << "," << y;
            }
        }
    }
    // The red half is out of gamut, the grey half in: the GPU count agrees with the CPU's.
    EXPECT_GT(cpuOut, 64u * 40u / 4u);
    EXPECT_EQ(f.gamut.pixels, 64u * 40u);
    EXPECT_NEAR(static_cast<double>(f.gamut.outOfGamut()), static_cast<double>(cpuOut), 4.0);
}

// A profile fitted from noisy readings carries a gamut-edge tolerance (display_fit.cpp): colours
// within it of the fitted gamut are clamped per channel, not hue-mapped. The GL pass must apply
// the same tolerance as the CPU inverse (it is two uniforms the pass uploads), so a wide
// tolerance, which changes what the CPU drives for many of the red half's pixels, is checked
// pixel by pixel as above.
TEST_F(DisplayPassTest, AnalyticPassAppliesTheProfilesGamutEdgeTolerance)
{
    profile_.gamutEdgeTolerance = 0.4;
    profile_.gamutEdgeFloor = 0.05;
    const RenderedFrame f = draw(InverseMethod::Analytic, 0.35);
    auto inv = display::DisplayInverse::build(profile_);
    ASSERT_TRUE(inv);
    display::DisplayModel strict = profile_;
    strict.gamutEdgeTolerance = 0.0;
    strict.gamutEdgeFloor = 0.0;
    auto strictInv = display::DisplayInverse::build(strict);
    ASSERT_TRUE(strictInv);
    int changed = 0; // pixels the tolerance moves by more than the dither's one count
    ASSERT_NO_FATAL_FAILURE(expectDrivenBy(*inv, *strictInv, f, changed));
    EXPECT_GT(changed, 0) << "the tolerance changes no pixel: the test cannot tell";
}

// A profile with channel interaction (DisplayModel::crosstalk): the GL pass undoes it with the same
// fixed-point steps as the CPU inverse (two uniforms), pixel by pixel as above. The crosstalk is
// ten times a real panel's (each product takes 5 % of r from every channel), so that it moves
// many pixels by several counts; and the fixed point must invert the model's own forward.
TEST_F(DisplayPassTest, AnalyticPassUndoesTheProfilesCrosstalk)
{
    profile_.crosstalk = glm::dmat3(glm::dvec3(-0.05), glm::dvec3(-0.05), glm::dvec3(-0.05));
    const RenderedFrame f = draw(InverseMethod::Analytic, 0.35);
    auto inv = display::DisplayInverse::build(profile_);
    ASSERT_TRUE(inv);
    display::DisplayModel additive = profile_;
    additive.crosstalk = glm::dmat3(0.0);
    auto additiveInv = display::DisplayInverse::build(additive);
    ASSERT_TRUE(additiveInv);
    int changed = 0; // pixels the crosstalk moves by more than the dither's one count
    ASSERT_NO_FATAL_FAILURE(expectDrivenBy(*inv, *additiveInv, f, changed));
    EXPECT_GT(changed, 64 * 40 / 4) << "the crosstalk changes too few pixels: the test cannot tell";
}

TEST_F(DisplayPassTest, CompensationChangesWhatIsDrivenInTheRightDirection)
{
    const RenderedFrame on = draw(InverseMethod::Analytic, 0.35);
    setup_.viewingCompensation = false;
    setup_.flareSubtraction = false;
    const RenderedFrame off = draw(InverseMethod::Analytic, 0.35);
    // On the grey half: off axis the panel is dimmer, so compensation drives harder, even after
    // taking the reflection away.
    long sumOn = 0;
    long sumOff = 0;
    for (int y = 0; y < 40; ++y) {
        for (int x = 0; x < 30; ++x) {
            const std::size_t i =
                    (static_cast<std::size_t>(y) * 64 + static_cast<std::size_t>(x)) * 4;
            sumOn += on.rgba[i + 1];
            sumOff += off.rgba[i + 1];
        }
    }
    EXPECT_GT(sumOn, sumOff);
}

TEST_F(DisplayPassTest, FilteredViewingGainDrivesWhatTheTableRowsDo)
{
    // The gain resampled every half degree and interpolated by the sampler (where the GL filters
    // float textures). The shipped table's rows lie on whole degrees, so it is the rows' function
    // (display::viewingGain, in double) to float rounding. An eye 3 cm in front of the panel near
    // its lower-left corner sees the pixels at 0 to about 86 degrees; a mid grey is driven within
    // the dither's one count of what the CPU inverse says for the rows' gain, on every pixel.
    if (!hasExtension("GL_OES_texture_float_linear")) {
        GTEST_SKIP() << "this GL does not filter float textures: the pass keeps the rows";
    }
    const int w = 96, h = 60;
    const scene::PanelPose pose = scene::panelPose(scene::StandModel{}, 0.3);
    DisplayPassFrame frame;
    frame.pose = pose;
    frame.eyeM =
            pose.cornerM() + 0.1 * pose.rightEdgeM() + 0.1 * pose.upEdgeM() + 0.03 * pose.normal;
    const glm::dvec3 grey = 0.1 * profile_.whiteXyz(); // in gamut at every angle
    std::vector<float> xyz;
    for (int i = 0; i < w * h; ++i) {
        xyz.insert(xyz.end(), {static_cast<float>(grey.x), static_cast<float>(grey.y),
                               static_cast<float>(grey.z), 0.0f});
    }
    GLuint tex = 0;
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_2D, tex);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, w, h);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, w, h, GL_RGBA, GL_FLOAT, xyz.data());
    DisplayPassSetup setup;
    setup.model = profile_;
    setup.flareSubtraction = false;
    DisplayPass pass;
    ASSERT_TRUE(pass.init(setup, w, h));
    EXPECT_TRUE(pass.viewingFiltered());
    ASSERT_TRUE(pass.draw(tex, frame));
    std::vector<std::uint8_t> out(static_cast<std::size_t>(w * h * 4), 0);
    glBindFramebuffer(GL_FRAMEBUFFER, pass.framebuffer());
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, out.data());
    glDeleteTextures(1, &tex);
    auto inv = display::DisplayInverse::build(profile_);
    ASSERT_TRUE(inv);
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            const glm::dvec3 p = pose.cornerM() + (x + 0.5) / w * pose.rightEdgeM() +
                                 (y + 0.5) / h * pose.upEdgeM();
            const double angle = display::viewingAngleDeg(p, pose.normal, frame.eyeM);
            const glm::dvec3 gain =
                    display::viewingGain(profile_.viewing, profile_.whiteXyz(), angle);
            const auto want = inv->invert(grey / gain);
            const std::size_t i = static_cast<std::size_t>(y * w + x) * 4;
            for (int c = 0; c < 3; ++c) {
                const double got = out[i + static_cast<std::size_t>(c)];
                ASSERT_GE(got, std::floor(want.counts[c] - 0.02) - 1e-9) << x << "," << y;
                ASSERT_LE(got, std::ceil(want.counts[c] + 0.02) + 1e-9) << x << "," << y;
            }
        }
    }
    // The compensation is at work across the frame: the far corner is driven harder than the
    // pixel under the eye (green, in the first and last pixel rows read back).
    const std::size_t nearEye = static_cast<std::size_t>((h / 6) * w + w / 5) * 4 + 1;
    const std::size_t far = static_cast<std::size_t>((h - 1) * w + w - 1) * 4 + 1;
    EXPECT_GT(int(out[far]), int(out[nearEye]) + 10);
}

TEST_F(DisplayPassTest, LutPassAgreesWithTheAnalyticPass)
{
    const RenderedFrame fa = draw(InverseMethod::Analytic, 0.2);
    const RenderedFrame fl = draw(InverseMethod::Lut3d, 0.2);
    int worst = 0;
    for (int y = 0; y < 40; ++y) {
        for (int x = 0; x < 30; ++x) { // the in-gamut grey half
            const std::size_t i =
                    (static_cast<std::size_t>(y) * 64 + static_cast<std::size_t>(x)) * 4;
            for (std::size_t c = 0; c < 3; ++c) {
                worst = std::max(worst, std::abs(fa.rgba[i + c] - fl.rgba[i + c]));
            }
        }
    }
    EXPECT_LE(worst, 2); // a 33^3 lattice is within a count or so of the analytic inverse
    EXPECT_EQ(fa.gamut.outOfGamut(), fl.gamut.outOfGamut()); // same classification
}

} // namespace
} // namespace replica::pipeline::render
