// The KMS output's pixel path (GL's bottom-up RGBA into top-down XRGB8888 with a pitch, centred
// or cropped) and its error when there is no display device.
#include <vector>

#include <platform/output/output.h>
#include <platform/output/scanout_copy.h>

#include <gtest/gtest.h>

namespace replica::tests {
namespace {

using platform::copyToScanout;
using platform::ScanoutBuffer;

// A w x h RGBA frame whose pixel (x, y), y counted from the bottom, is (x, y, 7, 255).
std::vector<std::uint8_t> frame(int w, int h)
{
    std::vector<std::uint8_t> f(static_cast<std::size_t>(w * h * 4));
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            auto* p = &f[static_cast<std::size_t>((y * w + x) * 4)];
            p[0] = static_cast<std::uint8_t>(x);
            p[1] = static_cast<std::uint8_t>(y);
            p[2] = 7;
            p[3] = 255;
        }
    }
    return f;
}

struct Pixel {
    int b, g, r, x;
};

Pixel at(const std::vector<std::uint8_t>& buf, std::size_t pitch, int x, int y)
{
    const auto* p = &buf[static_cast<std::size_t>(y) * pitch + static_cast<std::size_t>(x) * 4];
    return {p[0], p[1], p[2], p[3]};
}

TEST(ScanoutCopy, SameSizeFlipsRowsAndSwizzles)
{
    const int w = 5, h = 3;
    const std::size_t pitch = 32; // wider than 4 * w, as drivers align rows
    std::vector<std::uint8_t> buf(pitch * h, 0xAB);
    copyToScanout(w, h, frame(w, h), {w, h, pitch, buf});
    // Top row of the buffer is GL's last row (y = h - 1).
    const Pixel p = at(buf, pitch, 4, 0);
    EXPECT_EQ(p.r, 4);
    EXPECT_EQ(p.g, h - 1);
    EXPECT_EQ(p.b, 7);
    EXPECT_EQ(p.x, 255);
    EXPECT_EQ(at(buf, pitch, 0, h - 1).g, 0);
    // Padding past the row is left alone.
    EXPECT_EQ(buf[4 * w], 0xAB);
}

TEST(ScanoutCopy, SmallerFrameIsCentredOnBlackLargerIsCropped)
{
    std::vector<std::uint8_t> buf(10 * 4 * 6);
    copyToScanout(4, 2, frame(4, 2), {10, 6, 40, buf});
    EXPECT_EQ(at(buf, 40, 0, 0).r, 0);
    EXPECT_EQ(at(buf, 40, 2, 2).x, 0);   // border stays black
    EXPECT_EQ(at(buf, 40, 3, 2).x, 255); // frame starts at (3, 2)
    EXPECT_EQ(at(buf, 40, 3, 2).r, 0);
    EXPECT_EQ(at(buf, 40, 6, 3).r, 3);
    EXPECT_EQ(at(buf, 40, 3, 2).g, 1); // top of buffer area = top (last GL) row
    EXPECT_EQ(at(buf, 40, 7, 2).x, 0);

    std::vector<std::uint8_t> small(2 * 4 * 2);
    copyToScanout(6, 4, frame(6, 4), {2, 2, 8, small});
    // Centre crop: columns 2..3, GL rows 2..1 (top-down).
    EXPECT_EQ(at(small, 8, 0, 0).r, 2);
    EXPECT_EQ(at(small, 8, 1, 0).r, 3);
    EXPECT_EQ(at(small, 8, 0, 0).g, 2);
    EXPECT_EQ(at(small, 8, 0, 1).g, 1);
}

TEST(ScanoutCopy, NoPixelsMeansBlackNotGarbage)
{
    std::vector<std::uint8_t> buf(4 * 4 * 4, 0xCD);
    copyToScanout(4, 4, {}, {4, 4, 16, buf});
    for (const auto b : buf) {
        ASSERT_EQ(b, 0);
    }
}

TEST(KmsOutput, AMissingCardIsAClearError)
{
    platform::KmsOptions options;
    options.device = "/dev/dri/no-such-card";
    auto out = platform::createKmsOutput(options);
    ASSERT_FALSE(out);
    EXPECT_EQ(out.error().code, ErrorCode::NotFound);
    EXPECT_NE(out.error().message.find("/dev/dri/no-such-card"), std::string::npos);
    EXPECT_NE(out.error().message.find("--output headless"), std::string::npos);
}

} // namespace
} // namespace replica::tests
