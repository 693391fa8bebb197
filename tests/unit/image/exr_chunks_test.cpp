// The EXR reader against files whose header and pixel data disagree (image/exr_chunks.h).
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <pipeline/image/exr.h>
#include <pipeline/image/exr_chunks.h>

#include <gtest/gtest.h>

namespace replica::pipeline::image {
namespace {

namespace fs = std::filesystem;

std::string slurp(const fs::path& p)
{
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A 64 x 32 luminance ramp, written by our own writer (ZIP, 16 lines a chunk).
fs::path writeRamp(const std::string& name)
{
    ChannelImage img;
    img.width = 64;
    img.height = 32;
    img.names = {"Y"};
    img.planes.assign(1, std::vector<float>(64 * 32));
    for (std::size_t i = 0; i < img.planes[0].size(); ++i) {
        img.planes[0][i] = 100.0f + static_cast<float>(i);
    }
    const fs::path p = fs::temp_directory_path() / ("replica_exr_chunks_" + name + ".exr");
    EXPECT_TRUE(writeExr(p, img));
    return p;
}

// The header's dataWindow box (xMin, yMin, xMax, yMax) rewritten in place.
void setDataWindow(std::string& bytes, std::int32_t xMax, std::int32_t yMax)
{
    const std::string key("dataWindow\0box2i\0", 17);
    const auto at = bytes.find(key);
    ASSERT_NE(at, std::string::npos);
    const std::size_t box = at + key.size() + 4; // past the attribute's size field
    std::memcpy(bytes.data() + box + 8, &xMax, 4);
    std::memcpy(bytes.data() + box + 12, &yMax, 4);
}

TEST(ExrChunks, AnIntactFileDecodesAndReadsBack)
{
    const fs::path p = writeRamp("intact");
    EXPECT_TRUE(checkExrChunks(slurp(p), p.string()));
    auto img = readExr(p, {"Y"});
    ASSERT_TRUE(img) << img.error().message;
    EXPECT_EQ(img->planes[0][64 * 31 + 5], 100.0f + 64 * 31 + 5);
}

TEST(ExrChunks, ADataWindowTheChunksCannotFillIsRefusedNamingTheFile)
{
    // One line of 4096 pixels where the first chunk holds 16 lines of 64 (1024 pixels): the C++
    // reader alone read it without an error, a line of the ramp and then zeros.
    const fs::path p = writeRamp("wide");
    std::string bytes = slurp(p);
    setDataWindow(bytes, 4095, 0);
    std::ofstream(p, std::ios::binary | std::ios::trunc) << bytes;
    EXPECT_FALSE(checkExrChunks(bytes, p.string()));
    auto img = readExr(p, {"Y"});
    ASSERT_FALSE(img);
    EXPECT_NE(img.error().message.find(p.string() + ": not a readable OpenEXR file"),
              std::string::npos)
            << img.error().message;
    // Taller than the chunks go (64 lines where 32 were written): the offset table is short.
    std::string tall = slurp(writeRamp("tall"));
    setDataWindow(tall, 63, 63);
    EXPECT_FALSE(checkExrChunks(tall, "tall.exr"));
}

TEST(ExrChunks, BytesThatAreNoExrAreRefused)
{
    EXPECT_FALSE(checkExrChunks(std::string(), "empty.exr"));
    EXPECT_FALSE(checkExrChunks(std::string("v/1\x01 not an exr", 16), "text.exr"));
}

} // namespace
} // namespace replica::pipeline::image
