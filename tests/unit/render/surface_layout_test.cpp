// The pixel rectangles of a surface layout against the bounds test the booth shader makes per
// pixel, in double: surfaceRect holds every pixel that can show the surface, surfaceInterior only
// pixels wholly on it (mode 0's surround program leaves those out, so a pixel of the interior
// that the shader's test put outside the surface would never get its E_geo).
#include <cmath>

#include <pipeline/render/surface_layout.h>

#include <gtest/gtest.h>

namespace replica::pipeline::render {
namespace {

bool contains(const PixelRect& r, int x, int y)
{
    return x >= r.x && x < r.x + r.width && y >= r.y && y < r.y + r.height;
}

// The shader's test (booth_main.glsl surfaceUv, GL's window rows up), at a point of the pixel.
bool onSurface(const SurfaceLayout& l, double fx, double fy, int width, int height)
{
    const double u = l.offset.x + l.scale.x * (fx / width);
    const double v = l.offset.y + l.scale.y * (1.0 - fy / height);
    return u >= 0.0 && u <= 1.0 && v >= 0.0 && v <= 1.0;
}

TEST(SurfaceLayout, TheInteriorIsWhollyOnTheSurfaceAndTheRectangleHoldsEveryPixelThatIs)
{
    struct Case {
        SurfaceLayout layout;
        int width, height;
    };
    const Case cases[] = {
            {{{-0.37, -0.21}, {1.9, 1.6}}, 960, 600},      // the surface smaller than the frame
            {{{-0.371, -0.2137}, {1.913, 1.617}}, 97, 61}, // fractional edges, odd sizes
            {{{0.25, 0.1}, {0.5, 0.7}}, 320, 200},         // larger than the frame: clipped
            {{{0.0, 0.0}, {1.0, 1.0}}, 64, 40},            // exactly the frame
            {{{-3.0, -2.0}, {7.0, 5.0}}, 200, 100},        // a few pixels across
    };
    for (const Case& c : cases) {
        const PixelRect rect = surfaceRect(c.layout, c.width, c.height);
        const PixelRect in = surfaceInterior(c.layout, c.width, c.height);
        long interior = 0;
        for (int y = 0; y < c.height; ++y) {
            for (int x = 0; x < c.width; ++x) {
                const bool centre = onSurface(c.layout, x + 0.5, y + 0.5, c.width, c.height);
                if (centre) {
                    ASSERT_TRUE(contains(rect, x, y)) << x << ", " << y;
                }
                if (contains(in, x, y)) {
                    ++interior;
                    ASSERT_TRUE(contains(rect, x, y)) << x << ", " << y;
                    // The whole pixel: its four corners on the surface.
                    for (const double dx : {0.0, 1.0}) {
                        for (const double dy : {0.0, 1.0}) {
                            ASSERT_TRUE(onSurface(c.layout, x + dx, y + dy, c.width, c.height))
                                    << x << ", " << y;
                        }
                    }
                }
            }
        }
        // Not empty where the surface spans pixels, and nearly all of it: the margin is about a
        // pixel on each side.
        ASSERT_GT(interior, 0);
        EXPECT_GE(in.width, rect.width - 4);
        EXPECT_GE(in.height, rect.height - 4);
    }
}

TEST(SurfaceLayout, NoInteriorForALayoutThatDoesNotScale)
{
    for (const SurfaceLayout l :
         {SurfaceLayout{{0.0, 0.0}, {0.0, 1.0}}, SurfaceLayout{{0.0, 0.0}, {-1.0, 1.0}},
          SurfaceLayout{{std::nan(""), 0.0}, {1.0, 1.0}}}) {
        const PixelRect in = surfaceInterior(l, 64, 40);
        EXPECT_EQ(in.width * in.height, 0);
    }
    // A surface narrower than a pixel has no pixel wholly on it.
    const PixelRect thin = surfaceInterior({{-100.0, 0.0}, {300.0, 1.0}}, 64, 40);
    EXPECT_EQ(thin.width * thin.height, 0);
}

} // namespace
} // namespace replica::pipeline::render
