// The KMS output's decisions that need no display: the mode request and choice, the physical
// size an EDID gives, the panel-size rule, and that the frame then shows a surface at its
// physical size.
#include <array>
#include <cmath>
#include <vector>

#include <pipeline/render/booth_shading_pass.h>
#include <platform/appliance.h>
#include <platform/output/display_geometry.h>

#include <gtest/gtest.h>

namespace replica::tests {
namespace {

using platform::chooseMode;
using platform::DisplayMode;
using platform::edidPhysicalSize;
using platform::ModeRequest;
using platform::parseModeRequest;

TEST(ModeRequest, ParsesSizeAndRateAndRejectsTheRest)
{
    auto a = parseModeRequest("1920x1200");
    ASSERT_TRUE(a);
    EXPECT_EQ(a->width, 1920);
    EXPECT_EQ(a->height, 1200);
    EXPECT_EQ(a->refreshHz, 0);
    auto b = parseModeRequest("1280X800@75");
    ASSERT_TRUE(b);
    EXPECT_EQ(b->width, 1280);
    EXPECT_EQ(b->height, 800);
    EXPECT_EQ(b->refreshHz, 75);
    auto none = parseModeRequest("");
    ASSERT_TRUE(none);
    EXPECT_EQ(none->width, 0);
    for (const char* bad :
         {"1920", "1920x", "0x600", "1920x1200@", "1920x1200@60Hz", "big", "1920x1200 ", "-5x4"}) {
        auto r = parseModeRequest(bad);
        ASSERT_FALSE(r) << bad;
        EXPECT_NE(r.error().message.find(bad), std::string::npos) << r.error().message;
    }
}

// The one WxH parser reads each side whole: a side past 2^32 is a large number, never wrapped to a
// small one (sscanf's %d turned 4294967392 into 96).
TEST(ModeRequest, SidesAndRatesPast32BitsAreRefusedNotWrapped)
{
    const auto big = platform::parsePixelSize("4294967392x60");
    ASSERT_TRUE(big);
    EXPECT_EQ(big->first, 4294967392LL);
    EXPECT_EQ(big->second, 60);
    EXPECT_FALSE(platform::parsePixelSize("99999999999999999999x60"));
    for (const char* bad : {"4294967392x60", "1920x4294968496", "1920x1200@4294967356"}) {
        auto r = parseModeRequest(bad);
        EXPECT_FALSE(r) << bad;
    }
}

TEST(ModeChoice, PreferredElseFirstAndTheRequestedSizeAtItsHighestRate)
{
    const std::vector<DisplayMode> modes{{1920, 1080, 60, false},
                                         {1280, 800, 60, true},
                                         {1920, 1080, 75, false},
                                         {1920, 1080, 50, false}};
    EXPECT_EQ(*chooseMode(modes, {}), 1u);
    const std::vector<DisplayMode> unmarked{{1024, 768, 60, false}, {800, 600, 60, false}};
    EXPECT_EQ(*chooseMode(unmarked, {}), 0u);
    EXPECT_EQ(*chooseMode(modes, ModeRequest{1920, 1080, 0}), 2u); // 75 Hz, the highest
    EXPECT_EQ(*chooseMode(modes, ModeRequest{1920, 1080, 50}), 3u);
    auto missing = chooseMode(modes, ModeRequest{2560, 1440, 0});
    ASSERT_FALSE(missing);
    EXPECT_NE(missing.error().message.find("2560x1440"), std::string::npos);
    EXPECT_NE(missing.error().message.find("1280x800@60 (preferred)"), std::string::npos);
    EXPECT_FALSE(chooseMode(modes, ModeRequest{1920, 1080, 144}));
    EXPECT_FALSE(chooseMode({}, {}));
}

// An EDID 1.4 base block with a detailed timing for 1920x1200 whose image size is w x h mm, and
// basic parameters of wcm x hcm; the checksum made right.
std::array<std::uint8_t, 128> edidBlock(int wmm, int hmm, int wcm, int hcm)
{
    std::array<std::uint8_t, 128> e{};
    const std::uint8_t header[8] = {0x00, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0x00};
    std::copy(std::begin(header), std::end(header), e.begin());
    e[18] = 1; // version 1.4
    e[19] = 4;
    e[21] = static_cast<std::uint8_t>(wcm);
    e[22] = static_cast<std::uint8_t>(hcm);
    // Descriptor 1: 154.00 MHz (15400 in 10 kHz units, little-endian), 1920x1200.
    e[54] = 15400 & 0xff;
    e[55] = 15400 >> 8;
    e[56] = 1920 & 0xff;
    e[58] = static_cast<std::uint8_t>((1920 >> 8) << 4);
    e[59] = 1200 & 0xff;
    e[61] = static_cast<std::uint8_t>((1200 >> 8) << 4);
    e[66] = static_cast<std::uint8_t>(wmm & 0xff);
    e[67] = static_cast<std::uint8_t>(hmm & 0xff);
    e[68] = static_cast<std::uint8_t>(((wmm >> 8) << 4) | (hmm >> 8));
    unsigned sum = 0;
    for (int i = 0; i < 127; ++i) {
        sum += e[static_cast<std::size_t>(i)];
    }
    e[127] = static_cast<std::uint8_t>((256 - sum % 256) % 256);
    return e;
}

TEST(Edid, PhysicalSizeFromTheDetailedTimingInMillimetres)
{
    // A 24-inch 16:10 panel's active area, 518 x 324 mm: its diagonal is 24.06 inches.
    const auto e = edidBlock(518, 324, 52, 32);
    const auto size = edidPhysicalSize(e);
    ASSERT_TRUE(size);
    EXPECT_DOUBLE_EQ(size->width, 518.0);
    EXPECT_DOUBLE_EQ(size->height, 324.0);
    EXPECT_NEAR(std::hypot(size->width, size->height) / 25.4, 24.0, 0.1);
    // Past 255 mm a side needs the high nibbles of byte 68: a 65-inch 16:9 TV, 1429 x 804 mm.
    const auto tv = edidPhysicalSize(edidBlock(1429, 804, 143, 80));
    ASSERT_TRUE(tv);
    EXPECT_DOUBLE_EQ(tv->width, 1429.0);
    EXPECT_DOUBLE_EQ(tv->height, 804.0);
    EXPECT_NEAR(std::hypot(tv->width, tv->height) / 25.4, 64.5, 0.2);
}

TEST(Edid, FallsBackToCentimetresAndRejectsWhatIsNotAnEdid)
{
    // No size in the timing, or centimetres written where millimetres belong: bytes 21-22.
    auto cm = edidPhysicalSize(edidBlock(0, 0, 52, 32));
    ASSERT_TRUE(cm);
    EXPECT_DOUBLE_EQ(cm->width, 520.0);
    EXPECT_DOUBLE_EQ(cm->height, 320.0);
    auto wrongUnit = edidPhysicalSize(edidBlock(52, 32, 52, 32));
    ASSERT_TRUE(wrongUnit);
    EXPECT_DOUBLE_EQ(wrongUnit->width, 520.0);
    // A projector (no size at all) and an aspect ratio in place of a size.
    EXPECT_FALSE(edidPhysicalSize(edidBlock(0, 0, 0, 0)));
    EXPECT_FALSE(edidPhysicalSize(edidBlock(0, 0, 0, 0x4f)));
    auto badSum = edidBlock(518, 324, 52, 32);
    badSum[127] ^= 1;
    EXPECT_FALSE(edidPhysicalSize(badSum));
    auto badHeader = edidBlock(518, 324, 52, 32);
    badHeader[0] = 0x01;
    EXPECT_FALSE(edidPhysicalSize(badHeader));
    EXPECT_FALSE(edidPhysicalSize(std::span(badHeader).first(100)));
}

TEST(PanelSize, ConfiguredThenEdidThenDefault)
{
    const platform::SizeMm site{600.0, 340.0};
    const platform::SizeMm edid{518.0, 324.0};
    auto a = platform::resolvePanelSize(site, edid, 0.518, 0.324);
    EXPECT_DOUBLE_EQ(a.widthM, 0.6);
    EXPECT_EQ(a.source, "configured");
    auto b = platform::resolvePanelSize(std::nullopt, edid, 0.4, 0.3);
    EXPECT_DOUBLE_EQ(b.heightM, 0.324);
    EXPECT_EQ(b.source, "edid");
    auto c = platform::resolvePanelSize(std::nullopt, std::nullopt, 0.4, 0.3);
    EXPECT_DOUBLE_EQ(c.widthM, 0.4);
    EXPECT_EQ(c.source, "default");

    auto mm = platform::parseSizeMm("518x324");
    ASSERT_TRUE(mm);
    EXPECT_DOUBLE_EQ(mm->width, 518.0);
    EXPECT_DOUBLE_EQ(mm->height, 324.0);
    for (const char* bad : {"0.518x0.324", "518", "518x324mm", "x", "518x99999"}) {
        EXPECT_FALSE(platform::parseSizeMm(bad)) << bad;
    }
}

TEST(PanelSize, PixelAspect)
{
    // 1920x1200 on 518 x 324 mm: 0.26979 mm across, 0.27000 down.
    const platform::PanelSize u2412{0.518, 0.324, "edid"};
    EXPECT_NEAR(platform::pixelAspectError(u2412, 1920, 1200),
                std::abs((518.0 / 1920.0) / (324.0 / 1200.0) - 1.0), 1e-12);
    EXPECT_LT(platform::pixelAspectError(u2412, 1920, 1200), 0.001);
    // A 16:9 mode on a 16:10 panel: the pixels are 10 % narrower than tall (the panel's aspect
    // 1.5988 over the mode's 16/9).
    EXPECT_NEAR(platform::pixelAspectError(u2412, 1920, 1080), 1.0 - (518.0 / 324.0) / (16.0 / 9.0),
                1e-12);
    EXPECT_GT(platform::pixelAspectError(u2412, 1920, 1080), 0.1);
    EXPECT_TRUE(std::isinf(platform::pixelAspectError(u2412, 0, 1080)));
}

TEST(PanelSize, TheSurfaceShowsAtItsPhysicalSizeOnAnyPanel)
{
    // A 0.2 x 0.15 m surface on the frame: its width in pixels is 0.2 m over the panel's metres
    // per pixel, the same surface showing larger on a smaller panel with the same pixels.
    pipeline::surface::SurfaceScene scene;
    scene.widthM = 0.2;
    scene.heightM = 0.15;
    for (const auto& [wM, hM, px, py] :
         {std::tuple{0.518, 0.324, 1920, 1200}, std::tuple{0.325, 0.203, 1280, 800},
          std::tuple{1.429, 0.804, 3840, 2160}}) {
        platform::RunConfig config;
        config.stand.panelWidthM = wM;
        config.stand.panelHeightM = hM;
        const auto layout = pipeline::render::layoutOnPanel(scene, config.stand);
        // Surface u spans 1 / scale.x of the frame's width.
        EXPECT_NEAR(px / layout.scale.x, 0.2 / (wM / px), 1e-9) << wM;
        EXPECT_NEAR(py / layout.scale.y, 0.15 / (hM / py), 1e-9) << hM;
    }
    // The panel size is recorded; recordings without it replay on the 24-inch stand.
    platform::RunConfig c;
    c.stand.panelWidthM = 0.325;
    c.stand.panelHeightM = 0.203;
    auto back = platform::RunConfig::fromJson(c.toJson());
    ASSERT_TRUE(back);
    EXPECT_DOUBLE_EQ(back->stand.panelWidthM, 0.325);
    EXPECT_DOUBLE_EQ(back->stand.panelHeightM, 0.203);
    std::string old = c.toJson();
    for (const char* key : {"\"panel_width_m\":0.325,", "\"panel_height_m\":0.203,"}) {
        const auto at = old.find(key);
        ASSERT_NE(at, std::string::npos) << old;
        old.erase(at, std::string(key).size());
    }
    auto legacy = platform::RunConfig::fromJson(old);
    ASSERT_TRUE(legacy) << legacy.error().message;
    EXPECT_DOUBLE_EQ(legacy->stand.panelWidthM, 0.518);
    EXPECT_DOUBLE_EQ(legacy->stand.panelHeightM, 0.324);
    c.stand.panelWidthM = -0.5;
    EXPECT_FALSE(platform::RunConfig::fromJson(c.toJson()));
}

} // namespace
} // namespace replica::tests
