// Replay comparison helpers: PFM frames round-trip bit-exactly, ΔE00 statistics are the order
// statistics of the input, and the ΔE00 image agrees with CIELAB/CIEDE2000 applied by hand.
#include <bit>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <limits>

#include <sys/stat.h>
#include <unistd.h>

#include <pipeline/colour/ciede2000.h>
#include <pipeline/colour/cielab.h>
#include <platform/cli/frame_compare.h>
#include <platform/image/pfm.h>

#include <gtest/gtest.h>

namespace replica::platform {
namespace {

std::filesystem::path temp(const std::string& name)
{
    return std::filesystem::temp_directory_path() / (name + std::to_string(::getpid()) + ".pfm");
}

TEST(Pfm, RoundTripsEveryFloatBitExactly)
{
    FloatImage a{3, 2, {}};
    const float values[] = {0.0f,     -0.0f,      1e-38f,
                            123.456f, 799.99994f, std::numeric_limits<float>::denorm_min()};
    for (int p = 0; p < 6; ++p) {
        a.rgba.insert(a.rgba.end(), {values[p], values[(p + 1) % 6], values[(p + 2) % 6], 1.0f});
    }
    const auto path = temp("roundtrip");
    ASSERT_TRUE(writePfm(path, a));
    auto b = readPfm(path);
    ASSERT_TRUE(b) << b.error().message;
    EXPECT_EQ(b->width, 3);
    EXPECT_EQ(b->height, 2);
    ASSERT_EQ(b->rgba.size(), a.rgba.size());
    for (std::size_t i = 0; i < a.rgba.size(); ++i) {
        EXPECT_EQ(std::bit_cast<std::uint32_t>(b->rgba[i]), std::bit_cast<std::uint32_t>(a.rgba[i]))
                << i;
    }
    std::filesystem::remove(path);
}

TEST(Pfm, TruncatedAndForeignFilesAreNamedErrors)
{
    const auto path = temp("bad");
    {
        std::ofstream out(path, std::ios::binary);
        out << "PF\n4 4\n-1.0\n" << std::string(10, '\0');
    }
    auto r = readPfm(path);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find(path.string()), std::string::npos);
    EXPECT_NE(r.error().message.find("truncated"), std::string::npos);
    {
        std::ofstream out(path, std::ios::binary);
        out << "P6\n4 4\n255\n";
    }
    r = readPfm(path);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("not a 3-channel PFM"), std::string::npos);
    std::filesystem::remove(path);
}

// A reference frame is opened once through the bounded reader: a FIFO, /dev/zero or a directory
// in its place is an error naming it at once (before, it was checked by name and then opened
// again with a stream: a FIFO put there in between hung it).
TEST(Pfm, AFifoADeviceAndADirectoryAreNamedErrorsAtOnce)
{
    const auto fifo = temp("fifo");
    std::filesystem::remove(fifo);
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    const auto t0 = std::chrono::steady_clock::now();
    auto r = readPfm(fifo);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("is a FIFO"), std::string::npos) << r.error().message;
    r = readPfm("/dev/zero");
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("/dev/zero: is a device"), std::string::npos)
            << r.error().message;
    r = readPfm(std::filesystem::temp_directory_path());
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("is a directory"), std::string::npos) << r.error().message;
    EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(5));
    std::filesystem::remove(fifo);
}

TEST(FrameCompare, StatisticsAreOrderStatistics)
{
    std::vector<double> d;
    for (int i = 1; i <= 100; ++i) {
        d.push_back(0.05 * i); // 0.05 .. 5.00
    }
    const auto s = summarise(d);
    EXPECT_EQ(s.pixels, 100u);
    EXPECT_DOUBLE_EQ(s.mean, 0.05 * 50.5);
    EXPECT_DOUBLE_EQ(s.median, 0.05 * 50);
    EXPECT_DOUBLE_EQ(s.p95, 0.05 * 95);
    EXPECT_DOUBLE_EQ(s.max, 5.0);
    EXPECT_DOUBLE_EQ(s.fractionAbove1, 0.80); // 1.05 .. 5.00
    EXPECT_DOUBLE_EQ(s.fractionAbove2, 0.60); // 2.05 .. 5.00
}

TEST(FrameCompare, DeltaEImageMatchesTheColourLibraryPixelByPixel)
{
    const pipeline::colour::Xyz white{760.4, 800.0, 871.1};
    FloatImage a{2, 1, {100.0f, 120.0f, 90.0f, 1.0f, 10.0f, 10.0f, 30.0f, 1.0f}};
    FloatImage b{2, 1, {100.0f, 120.0f, 90.0f, 1.0f, 12.0f, 10.0f, 25.0f, 1.0f}};
    auto de = deltaE00Image(a, b, white);
    ASSERT_TRUE(de);
    ASSERT_EQ(de->size(), 2u);
    EXPECT_EQ((*de)[0], 0.0);
    const double expected =
            pipeline::colour::ciede2000(pipeline::colour::xyzToLab({10.0, 10.0, 30.0}, white),
                                        pipeline::colour::xyzToLab({12.0, 10.0, 25.0}, white));
    EXPECT_GT(expected, 1.0);
    EXPECT_DOUBLE_EQ((*de)[1], expected);
    FloatImage c{1, 1, {1.0f, 1.0f, 1.0f, 1.0f}};
    auto mismatch = deltaE00Image(a, c, white);
    ASSERT_FALSE(mismatch);
    EXPECT_NE(mismatch.error().message.find("differ in size"), std::string::npos);
}

} // namespace
} // namespace replica::platform
