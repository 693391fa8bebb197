// The PNGs of shown frames (replay --frames-out, snapshots, the recordings' thumbnails) say their
// colour space and time: read back with libpng (which checks every chunk's CRC), the iCCP profile
// parsed by Little CMS and checked against the display model at every 8-bit value.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <lcms2.h>
#include <png.h>
#include <unistd.h>

#include <pipeline/display/icc_profile.h>
#include <pipeline/display/nominal_display.h>
#include <platform/image/png_metadata.h>
#include <platform/image/png_writer.h>
#include <platform/image/thumbnail.h>

#include <gtest/gtest.h>

namespace replica::platform::png_metadata_tests {
// A namespace of its own: in a unity batch beside wall_clock_time_test.cpp, whose kS and k143205Z
// are the same names.
namespace {

constexpr std::int64_t kPngSecondNs = 1'000'000'000;
constexpr std::int64_t kPng143205Z = 1796567525LL * kPngSecondNs; // 2026-12-06T14:32:05Z

struct ReadBack {
    bool ok = false;
    std::string error;
    std::string iccName;
    std::vector<std::uint8_t> icc;
    bool hasTime = false;
    png_time time{};
    std::map<std::string, std::string> text;
    int srgbIntent = -1;
};

struct MemoryReader {
    const std::vector<std::uint8_t>* bytes;
    std::size_t pos;
};

void readBytes(png_structp png, png_bytep out, png_size_t n)
{
    auto* r = static_cast<MemoryReader*>(png_get_io_ptr(png));
    if (r->pos + n > r->bytes->size()) {
        png_error(png, "read past the end");
    }
    std::copy_n(r->bytes->data() + r->pos, n, out);
    r->pos += n;
}

void onError(png_structp png, png_const_charp msg)
{
    static_cast<ReadBack*>(png_get_error_ptr(png))->error = msg;
    png_longjmp(png, 1);
}

void onWarning(png_structp png, png_const_charp msg)
{
    // A bad CRC on an ancillary chunk is only a warning by default; here it is a failure.
    static_cast<ReadBack*>(png_get_error_ptr(png))->error = std::string("warning: ") + msg;
}

// Reads the whole PNG (pixels included, so that IDAT's and IEND's CRCs are checked) with every CRC
// error an error.
ReadBack readPng(const std::vector<std::uint8_t>& bytes)
{
    ReadBack out;
    MemoryReader reader{&bytes, 0};
    std::vector<std::uint8_t> pixels;
    std::vector<png_bytep> rows;
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &out, &onError, &onWarning);
    png_infop info = png_create_info_struct(png);
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_read_struct(&png, &info, nullptr);
        return out;
    }
    png_set_crc_action(png, PNG_CRC_ERROR_QUIT, PNG_CRC_ERROR_QUIT);
    png_set_read_fn(png, &reader, &readBytes);
    png_read_info(png, info);
    const auto width = png_get_rowbytes(png, info);
    const auto height = png_get_image_height(png, info);
    pixels.resize(width * height);
    rows.resize(height);
    for (png_uint_32 y = 0; y < height; ++y) {
        rows[y] = pixels.data() + y * width;
    }
    png_read_image(png, rows.data());
    png_read_end(png, info);
    png_charp name = nullptr;
    int compression = 0;
    png_bytep profile = nullptr;
    png_uint_32 length = 0;
    if (png_get_iCCP(png, info, &name, &compression, &profile, &length) != 0) {
        out.iccName = name;
        out.icc.assign(profile, profile + length);
    }
    png_timep t = nullptr;
    if (png_get_tIME(png, info, &t) != 0) {
        out.hasTime = true;
        out.time = *t;
    }
    png_textp text = nullptr;
    int n = 0;
    png_get_text(png, info, &text, &n);
    for (int i = 0; i < n; ++i) {
        out.text[text[i].key] = text[i].text;
    }
    int intent = 0;
    if (png_get_sRGB(png, info, &intent) != 0) {
        out.srgbIntent = intent;
    }
    png_destroy_read_struct(&png, &info, nullptr);
    out.ok = out.error.empty();
    return out;
}

RgbImage gradient()
{
    RgbImage img;
    img.width = 16;
    img.height = 9;
    for (int y = 0; y < img.height; ++y) {
        for (int x = 0; x < img.width; ++x) {
            img.rgb.push_back(static_cast<std::uint8_t>(x * 16));
            img.rgb.push_back(static_cast<std::uint8_t>(y * 28));
            img.rgb.push_back(static_cast<std::uint8_t>((x * y) % 256));
        }
    }
    return img;
}

const pipeline::display::DisplayModel& nominal()
{
    static const auto m = pipeline::display::nominalDisplayModel("srgb-like-800", 800.0, 0.5);
    return m;
}

TEST(PngMetadata, TheProfileIsTheDisplayModelAtEvery8BitValue)
{
    const auto& model = nominal();
    auto icc = pipeline::display::iccProfileBytes(model);
    ASSERT_TRUE(icc.has_value()) << icc.error().message;
    // 256-entry tone curves: small enough for every thumbnail.
    EXPECT_LT(icc->size(), 4096u);
    // A fixed creation date (1970-01-01 00:00:00): the same model, the same bytes, run after run.
    const std::vector<std::uint8_t> date(icc->begin() + 24, icc->begin() + 36);
    EXPECT_EQ(date, (std::vector<std::uint8_t>{0x07, 0xb2, 0, 1, 0, 1, 0, 0, 0, 0, 0, 0}));
    cmsHPROFILE h = cmsOpenProfileFromMem(icc->data(), static_cast<cmsUInt32Number>(icc->size()));
    ASSERT_NE(h, nullptr);
    EXPECT_EQ(cmsGetDeviceClass(h), cmsSigDisplayClass);
    EXPECT_EQ(cmsGetColorSpace(h), cmsSigRgbData);
    EXPECT_EQ(cmsGetPCS(h), cmsSigXYZData);
    cmsHPROFILE xyz = cmsCreateXYZProfile();
    cmsHTRANSFORM t = cmsCreateTransform(h, TYPE_RGB_DBL, xyz, TYPE_XYZ_DBL,
                                         INTENT_RELATIVE_COLORIMETRIC, cmsFLAGS_NOOPTIMIZE);
    ASSERT_NE(t, nullptr);
    const glm::dvec3 white = model.whiteXyz();
    const glm::dmat3 adapt = pipeline::display::bradfordToD50(white);
    double worst = 0.0;
    for (int v = 0; v < 256; ++v) {
        for (const glm::dvec3& counts :
             {glm::dvec3(v, v, v), glm::dvec3(v, 0, 0), glm::dvec3(0, v, 0), glm::dvec3(0, 0, v)}) {
            const double rgb[3] = {counts.x / 255.0, counts.y / 255.0, counts.z / 255.0};
            cmsCIEXYZ got{};
            cmsDoTransform(t, rgb, &got, 1);
            const glm::dvec3 want =
                    adapt * (model.forward(counts * (model.maxCount() / 255.0)) / white.y);
            worst = std::max({worst, std::abs(got.X - want.x), std::abs(got.Y - want.y),
                              std::abs(got.Z - want.z)});
        }
    }
    cmsDeleteTransform(t);
    cmsCloseProfile(xyz);
    cmsCloseProfile(h);
    // 16-bit curve entries and s15Fixed16 colorants: a few 1/65535 of white.
    EXPECT_LT(worst, 1e-4);
}

TEST(PngMetadata, ThumbnailCarriesProfileTimeAndFrame)
{
    auto icc = pipeline::display::iccProfileBytes(nominal());
    ASSERT_TRUE(icc.has_value());
    const auto meta = shownFrameMetadata(*icc, "srgb-like-800", kPng143205Z, 1'250'000'000, 37);
    const RgbImage img = gradient();
    auto png = encodePngRgb(img, &meta);
    ASSERT_TRUE(png.has_value()) << png.error().message;
    const auto r = readPng(*png);
    ASSERT_TRUE(r.ok) << r.error;
    EXPECT_EQ(r.iccName, "srgb-like-800");
    EXPECT_EQ(r.icc, *icc);
    ASSERT_TRUE(r.hasTime);
    EXPECT_EQ(r.time.year, 2026);
    EXPECT_EQ(r.time.month, 12);
    EXPECT_EQ(r.time.day, 6);
    EXPECT_EQ(r.time.hour, 14);
    EXPECT_EQ(r.time.minute, 32);
    EXPECT_EQ(r.time.second, 6);
    EXPECT_EQ(r.text.at("Creation Time"), "2026-12-06T14:32:06.250Z");
    EXPECT_EQ(r.text.at("Replica frame"),
              "frame 37, session second 1.25, recording started 2026-12-06T14:32:05.000Z");
    EXPECT_EQ(r.srgbIntent, -1); // the display profile, not sRGB
    // libpng does not convert through the profile: the pixels read back as written.
    auto decoded = decodePngRgb(*png);
    ASSERT_TRUE(decoded.has_value()) << decoded.error().message;
    EXPECT_EQ(decoded->rgb, img.rgb);
    // The check can fail: a damaged byte in a tEXt chunk breaks its CRC.
    auto damaged = *png;
    const std::string key = "Replica frame";
    const auto at = std::search(damaged.begin(), damaged.end(), key.begin(), key.end());
    ASSERT_NE(at, damaged.end());
    at[static_cast<long>(key.size()) + 3] ^= 0x01;
    EXPECT_FALSE(readPng(damaged).ok);
}

TEST(PngMetadata, UnknownStartAndNoProfile)
{
    const auto meta = shownFrameMetadata({}, "", 0, 2 * kPngSecondNs, 5);
    auto png = encodePngRgb(gradient(), &meta);
    ASSERT_TRUE(png.has_value());
    const auto r = readPng(*png);
    ASSERT_TRUE(r.ok) << r.error;
    EXPECT_TRUE(r.icc.empty());
    EXPECT_EQ(r.srgbIntent, PNG_sRGB_INTENT_PERCEPTUAL);
    EXPECT_FALSE(r.hasTime);
    EXPECT_EQ(r.text.count("Creation Time"), 0u);
    EXPECT_EQ(r.text.at("Replica frame"), "frame 5, session second 2");
    // Without metadata a PNG is as before: no colour or time chunks.
    auto plain = encodePngRgb(gradient());
    ASSERT_TRUE(plain.has_value());
    const auto p = readPng(*plain);
    ASSERT_TRUE(p.ok);
    EXPECT_TRUE(p.icc.empty());
    EXPECT_EQ(p.srgbIntent, -1);
    EXPECT_FALSE(p.hasTime);
    EXPECT_TRUE(p.text.empty());
}

TEST(PngMetadata, WrittenFramesCarryThemToo)
{
    auto icc = pipeline::display::iccProfileBytes(nominal());
    ASSERT_TRUE(icc.has_value());
    const auto meta = shownFrameMetadata(*icc, "a panel\twith  odd\nname", kPng143205Z, 0, 0);
    const std::vector<std::uint8_t> rgba(8 * 4 * 4, 200);
    const auto path = std::filesystem::temp_directory_path() /
                      ("replica_png_metadata_" + std::to_string(::getpid()) + ".png");
    ASSERT_TRUE(writePng(path, 8, 4, rgba, &meta).has_value());
    std::vector<std::uint8_t> bytes(std::filesystem::file_size(path));
    {
        FILE* f = std::fopen(path.c_str(), "rb");
        ASSERT_NE(f, nullptr);
        EXPECT_EQ(std::fread(bytes.data(), 1, bytes.size(), f), bytes.size());
        std::fclose(f);
    }
    std::filesystem::remove(path);
    const auto r = readPng(bytes);
    ASSERT_TRUE(r.ok) << r.error;
    EXPECT_EQ(r.iccName, "a panel with odd name");
    EXPECT_EQ(r.icc, *icc);
    EXPECT_EQ(r.text.at("Creation Time"), "2026-12-06T14:32:05.000Z");
}

TEST(PngMetadata, Keywords)
{
    EXPECT_EQ(pngKeyword("  a\tb  c  "), "a b c");
    EXPECT_EQ(pngKeyword(""), "profile");
    EXPECT_EQ(pngKeyword("\xe9\xe9"), "profile");
    EXPECT_EQ(pngKeyword(std::string(200, 'x')).size(), 79u);
}

} // namespace
} // namespace replica::platform::png_metadata_tests
