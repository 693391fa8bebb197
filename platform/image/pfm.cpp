// PFM reading and writing: a text header ("PF", size, scale whose sign gives the byte order) and
// raw 32-bit floats, rows bottom-up.
#include <bit>
#include <cstring>
#include <sstream>

#include <fmt/format.h>

#include <pipeline/base/input_file.h>
#include <pipeline/base/output_file.h>
#include <platform/image/pfm.h>

namespace replica::platform {

Expected<void> writePfm(const std::filesystem::path& path, const FloatImage& image)
{
    const auto pixels =
            static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height);
    if (image.width <= 0 || image.height <= 0 || image.rgba.size() != pixels * 4) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: no image to write ({}x{}, {} values)", path.string(),
                                     image.width, image.height, image.rgba.size()));
    }
    // Negative scale: little-endian floats (this writer only runs on little-endian machines).
    static_assert(std::endian::native == std::endian::little);
    std::string bytes = fmt::format("PF\n{} {}\n-1.0\n", image.width, image.height);
    const std::size_t header = bytes.size();
    bytes.resize(header + pixels * 3 * sizeof(float));
    char* raster = bytes.data() + header;
    for (std::size_t p = 0; p < pixels; ++p) {
        for (std::size_t c = 0; c < 3; ++c) {
            std::memcpy(raster + (p * 3 + c) * sizeof(float), &image.rgba[p * 4 + c],
                        sizeof(float));
        }
    }
    return writeOutputFile(path, bytes, "PFM image");
}

Expected<FloatImage> readPfm(const std::filesystem::path& path)
{
    // A regular file of bounded size, opened once and read whole (a FIFO, a directory or /dev/zero
    // is an error naming it); the header's size is checked against it before the image is
    // allocated.
    auto bytes = readInputFile(path, kMaxImageBytes, "PFM");
    if (!bytes) {
        return tl::unexpected(bytes.error());
    }
    // The header is a few dozen bytes: "PF", width, height, scale, one white space byte.
    std::istringstream in(bytes->substr(0, 256));
    std::string magic;
    FloatImage image;
    double scale = 0.0;
    in >> magic >> image.width >> image.height >> scale;
    in.get(); // the single whitespace byte before the raster
    if (!in || magic != "PF" || image.width <= 0 || image.height <= 0 || scale == 0.0 ||
        image.width > 65536 || image.height > 65536) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: not a 3-channel PFM image (bad header)", path.string()));
    }
    const auto rasterAt = static_cast<std::size_t>(in.tellg());
    const auto pixels =
            static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height);
    if (pixels * 3 * sizeof(std::uint32_t) > bytes->size() - rasterAt) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: truncated PFM ({}x{} pixels expected)", path.string(),
                                     image.width, image.height));
    }
    std::vector<std::uint32_t> raw(pixels * 3);
    std::memcpy(raw.data(), bytes->data() + rasterAt, raw.size() * sizeof(std::uint32_t));
    bytes->clear();
    bytes->shrink_to_fit();
    const bool swap = (scale > 0.0) != (std::endian::native == std::endian::big);
    image.rgba.resize(pixels * 4);
    for (std::size_t p = 0; p < pixels; ++p) {
        for (std::size_t c = 0; c < 3; ++c) {
            std::uint32_t v = raw[p * 3 + c];
            if (swap) {
                v = ((v & 0xffU) << 24) | ((v & 0xff00U) << 8) | ((v >> 8) & 0xff00U) | (v >> 24);
            }
            image.rgba[p * 4 + c] = std::bit_cast<float>(v);
        }
        image.rgba[p * 4 + 3] = 1.0f;
    }
    return image;
}

} // namespace replica::platform
