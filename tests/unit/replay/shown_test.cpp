// Digest format 2 (XXH3-64), digest files of both versions, thumbnails (downscale rule, PNG),
// half-float reference frames and base64: each against independent values.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>

#include <png.h>

#include <platform/image/thumbnail.h>
#include <platform/image/xyz_frame.h>
#include <platform/loop/frame_digest.h>
#include <recordings/sample_codec.h>

#include <gtest/gtest.h>

namespace replica::platform {
namespace {

std::filesystem::path tempPath(const std::string& name)
{
    return std::filesystem::temp_directory_path() /
           (name + "-" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
}

std::span<const std::uint8_t> bytesOf(const std::string& s)
{
    return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()};
}

// Reference values from xxhsum -H3 (Debian's xxhash 0.8.1 command-line tool), not this code.
TEST(FrameDigest, Xxh3MatchesTheReferenceTool)
{
    EXPECT_EQ(xxh3_64(bytesOf("")), 0x2d06800538d394c2ULL);
    EXPECT_EQ(xxh3_64(bytesOf("abc")), 0x78af5f94892f3950ULL);
    // 100000 bytes (i * 7 + 3) mod 256: past every short-input path of XXH3.
    std::vector<std::uint8_t> big(100000);
    for (std::size_t i = 0; i < big.size(); ++i) {
        big[i] = static_cast<std::uint8_t>((i * 7 + 3) & 0xff);
    }
    EXPECT_EQ(xxh3_64(big), 0x0c056f6fcc340974ULL);
    EXPECT_EQ(frameHash(DigestHash::Xxh3_64, big), 0x0c056f6fcc340974ULL);
}

// FNV-1a 64 of "a" is 0xaf63dc4c8601ec8c (the published FNV test vectors, isthe.com/chongo).
TEST(FrameDigest, Fnv1aStaysTheVersionOneHash)
{
    EXPECT_EQ(fnv1a64(bytesOf("a")), 0xaf63dc4c8601ec8cULL);
    EXPECT_EQ(frameHash(DigestHash::Fnv1a64, bytesOf("a")), 0xaf63dc4c8601ec8cULL);
}

TEST(FrameDigest, FilesOfBothVersionsReadBackWithTheirHash)
{
    const std::vector<FrameDigest> d = {{0, 0, 0x0123456789abcdefULL, 0xfedcba9876543210ULL},
                                        {1, 16666667, 1, 2}};
    const auto v1 = tempPath("digests-v1.json");
    const auto v2 = tempPath("digests-v2.json");
    ASSERT_TRUE(writeDigests(v1, d, DigestHash::Fnv1a64));
    ASSERT_TRUE(writeDigests(v2, d));
    const auto r1 = readDigestFile(v1);
    const auto r2 = readDigestFile(v2);
    ASSERT_TRUE(r1) << r1.error().message;
    ASSERT_TRUE(r2) << r2.error().message;
    EXPECT_EQ(r1->hash, DigestHash::Fnv1a64);
    EXPECT_EQ(r2->hash, DigestHash::Xxh3_64);
    EXPECT_EQ(r1->frames, d);
    EXPECT_EQ(r2->frames, d);
    // A committed version 1 golden names no hash at all.
    std::ifstream in(v1);
    const std::string text((std::istreambuf_iterator<char>(in)), {});
    EXPECT_EQ(text.find("hash"), std::string::npos);
    // An unknown version is refused with the file named.
    const auto v9 = tempPath("digests-v9.json");
    std::ofstream(v9) << R"({"format": "replica-digests", "version": 9, "frames": []})";
    const auto r9 = readDigestFile(v9);
    ASSERT_FALSE(r9);
    EXPECT_NE(r9.error().message.find(v9.string()), std::string::npos);
    for (const auto& p : {v1, v2, v9}) {
        std::filesystem::remove(p);
    }
}

// RFC 4648 section 10 test vectors.
TEST(Base64, MatchesTheRfcVectors)
{
    auto b64 = [](const std::string& s) {
        return recordings::base64Encode(std::vector<std::uint8_t>(s.begin(), s.end()));
    };
    EXPECT_EQ(b64(""), "");
    EXPECT_EQ(b64("f"), "Zg==");
    EXPECT_EQ(b64("fo"), "Zm8=");
    EXPECT_EQ(b64("foo"), "Zm9v");
    EXPECT_EQ(b64("foob"), "Zm9vYg==");
    EXPECT_EQ(b64("fooba"), "Zm9vYmE=");
    EXPECT_EQ(b64("foobar"), "Zm9vYmFy");
}

TEST(Thumbnail, DownscaleIsTheBoxMeanRoundedHalfUp)
{
    // 4x2 RGBA, GL rows bottom-up: bottom row red 0, 1, 2, 3; top row red 10, 20, 30, 41.
    std::vector<std::uint8_t> rgba(4 * 2 * 4, 255);
    const int bottom[4] = {0, 1, 2, 3};
    const int top[4] = {10, 20, 30, 41};
    for (int x = 0; x < 4; ++x) {
        rgba[static_cast<std::size_t>(x) * 4] = static_cast<std::uint8_t>(bottom[x]);
        rgba[static_cast<std::size_t>(4 + x) * 4] = static_cast<std::uint8_t>(top[x]);
    }
    // To 2 wide: height 2 * 2 / 4 = 1, each output the mean of a 2x2 block.
    const RgbImage t = downscaleRgba(4, 2, rgba, 2);
    ASSERT_EQ(t.width, 2);
    ASSERT_EQ(t.height, 1);
    EXPECT_EQ(t.rgb[0], (0 + 1 + 10 + 20 + 2) / 4); // 33 / 4 = 8.25 -> 8
    EXPECT_EQ(t.rgb[3], (2 + 3 + 30 + 41 + 2) / 4); // 76 / 4 = 19
    EXPECT_EQ(t.rgb[1], 255);
    // Full width keeps the picture, top row first (PNG order).
    const RgbImage same = downscaleRgba(4, 2, rgba, 320);
    ASSERT_EQ(same.width, 4);
    ASSERT_EQ(same.height, 2);
    EXPECT_EQ(same.rgb[0], 10);
    EXPECT_EQ(same.rgb[3 * 4], 0);
    // 960x600 to 320: 3x3 blocks, 200 rows.
    const RgbImage big = downscaleRgba(960, 600, std::vector<std::uint8_t>(960 * 600 * 4, 7), 320);
    EXPECT_EQ(big.width, 320);
    EXPECT_EQ(big.height, 200);
}

TEST(Thumbnail, PngDecodesToTheSamePixels)
{
    RgbImage img{5, 3, {}};
    for (int i = 0; i < 5 * 3 * 3; ++i) {
        img.rgb.push_back(static_cast<std::uint8_t>(i * 17 % 256));
    }
    auto png = encodePngRgb(img);
    ASSERT_TRUE(png) << png.error().message;
    png_image decoded{};
    decoded.version = PNG_IMAGE_VERSION;
    ASSERT_NE(png_image_begin_read_from_memory(&decoded, png->data(), png->size()), 0);
    decoded.format = PNG_FORMAT_RGB;
    std::vector<std::uint8_t> out(PNG_IMAGE_SIZE(decoded));
    ASSERT_NE(png_image_finish_read(&decoded, nullptr, out.data(), 0, nullptr), 0);
    EXPECT_EQ(decoded.width, 5u);
    EXPECT_EQ(decoded.height, 3u);
    EXPECT_EQ(out, img.rgb);
}

// Half floats keep 11 significant bits: every value comes back within 2^-11 relative.
TEST(XyzFrame, HalfFloatExrRoundTripsWithinHalfPrecision)
{
    FloatImage f{3, 2, {}};
    for (int i = 0; i < 3 * 2; ++i) {
        const float base = 0.37f * static_cast<float>(i + 1);
        f.rgba.insert(f.rgba.end(), {base * 100.0f, base * 3.0f, base / 7.0f, 1.0f});
    }
    const auto path = tempPath("frame.exr");
    path.string();
    const auto exr = std::filesystem::path(path.string() + ".exr");
    ASSERT_TRUE(writeXyzFrame(exr, f));
    auto back = readXyzFrame(exr);
    ASSERT_TRUE(back) << back.error().message;
    ASSERT_EQ(back->width, 3);
    ASSERT_EQ(back->height, 2);
    for (std::size_t i = 0; i < f.rgba.size(); ++i) {
        EXPECT_NEAR(back->rgba[i], f.rgba[i], std::ldexp(std::abs(f.rgba[i]), -11)) << i;
    }
    EXPECT_LT(std::filesystem::file_size(exr), 3u * 2u * 3u * 4u + 2000u);
    std::filesystem::remove(exr);
}

} // namespace
} // namespace replica::platform
