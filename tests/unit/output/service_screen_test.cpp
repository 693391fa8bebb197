// The service screen's text: the built-in font's letters where the layout puts them.
#include <platform/output/service_screen.h>

#include <gtest/gtest.h>

namespace replica::platform {
namespace {

// Whether the pixel at column x, row y (top-down) differs from the background (the top-left one).
bool lit(const ServiceImage& img, int x, int y)
{
    const auto at = [&img](int px, int py) {
        return (static_cast<std::size_t>(img.height - 1 - py) *
                        static_cast<std::size_t>(img.width) +
                static_cast<std::size_t>(px)) *
               4;
    };
    return img.rgba[at(x, y)] != img.rgba[at(0, 0)];
}

TEST(ServiceScreen, AnHIsTwoUprightsAndABar)
{
    // A small frame: scale 1, a margin of one 6-pixel cell, the title's first letter at (6, 6).
    const auto img = renderServiceScreen(120, 60, "H", {});
    ASSERT_EQ(img.rgba.size(), 120u * 60u * 4u);
    for (int y = 0; y < 7; ++y) {
        EXPECT_TRUE(lit(img, 6, 6 + y)) << y;           // left upright
        EXPECT_TRUE(lit(img, 6 + 4, 6 + y)) << y;       // right upright
        EXPECT_EQ(lit(img, 6 + 2, 6 + y), y == 3) << y; // the bar, in the middle row only
    }
    EXPECT_FALSE(lit(img, 6 + 5, 9)); // the gap between letters
    EXPECT_FALSE(lit(img, 6, 13));    // the leading under the line
}

TEST(ServiceScreen, LinesFollowTheTitleAndWrapAtTheWidth)
{
    // 120 pixels: 18 columns of text. The title, a blank line, then a line that wraps once.
    const auto img = renderServiceScreen(120, 80, "T", {"I2345678901234567 I"});
    const int lineH = 9;
    const int firstText = 6 + 2 * lineH;
    EXPECT_TRUE(lit(img, 6 + 2, firstText));         // the I's top bar
    EXPECT_TRUE(lit(img, 6 + 2, firstText + lineH)); // the wrapped "I" on the next line
    EXPECT_FALSE(lit(img, 6 + 2, 6 + lineH + 3));    // the blank line under the title
    // Characters the font lacks show as '?'.
    for (int x = 0; x < 5; ++x) {
        for (int y = 0; y < 7; ++y) {
            EXPECT_EQ(fontPixel('\x01', x, y), fontPixel('?', x, y));
        }
    }
}

} // namespace
} // namespace replica::platform
