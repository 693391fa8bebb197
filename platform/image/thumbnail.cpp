// Box-filter downscale and PNG encoding to memory through libpng's write callback.
#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <png.h>

#include <platform/image/png_metadata.h>
#include <platform/image/thumbnail.h>

namespace replica::platform {

RgbImage downscaleRgba(int width, int height, const std::vector<std::uint8_t>& rgba, int toWidth)
{
    RgbImage out;
    if (width <= 0 || height <= 0 || toWidth <= 0 ||
        rgba.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 4) {
        return out;
    }
    const int w = std::min(toWidth, width);
    const long long hRounded = (static_cast<long long>(height) * w * 2 + width) / (2LL * width);
    const int h = static_cast<int>(std::clamp<long long>(hRounded, 1, height));
    out.width = w;
    out.height = h;
    out.rgb.resize(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 3);
    auto lo = [](int i, int src, int dst) {
        return static_cast<int>(static_cast<long long>(i) * src / dst);
    };
    for (int y = 0; y < h; ++y) {
        const int y0 = lo(y, height, h);
        const int y1 = std::max(lo(y + 1, height, h), y0 + 1);
        for (int x = 0; x < w; ++x) {
            const int x0 = lo(x, width, w);
            const int x1 = std::max(lo(x + 1, width, w), x0 + 1);
            unsigned sum[3] = {0, 0, 0};
            for (int sy = y0; sy < y1; ++sy) {
                // Top-down row sy of the picture is GL row height - 1 - sy.
                const std::size_t row =
                        static_cast<std::size_t>(height - 1 - sy) * static_cast<std::size_t>(width);
                for (int sx = x0; sx < x1; ++sx) {
                    const std::uint8_t* p = rgba.data() + (row + static_cast<std::size_t>(sx)) * 4;
                    sum[0] += p[0];
                    sum[1] += p[1];
                    sum[2] += p[2];
                }
            }
            const auto n = static_cast<unsigned>((y1 - y0) * (x1 - x0));
            std::uint8_t* q =
                    out.rgb.data() + (static_cast<std::size_t>(y) * static_cast<std::size_t>(w) +
                                      static_cast<std::size_t>(x)) *
                                             3;
            for (int c = 0; c < 3; ++c) {
                q[c] = static_cast<std::uint8_t>((sum[c] + n / 2) / n);
            }
        }
    }
    return out;
}

namespace {

void appendBytes(png_structp png, png_bytep data, png_size_t length)
{
    auto* out = static_cast<std::vector<std::uint8_t>*>(png_get_io_ptr(png));
    out->insert(out->end(), data, data + length);
}

void noFlush(png_structp)
{}

} // namespace

Expected<std::vector<std::uint8_t>> encodePngRgb(const RgbImage& image, const PngMetadata* meta)
{
    if (image.width <= 0 || image.height <= 0 ||
        image.rgb.size() != static_cast<std::size_t>(image.width) *
                                    static_cast<std::size_t>(image.height) * 3) {
        return makeError(ErrorCode::InvalidArgument, "thumbnail has no pixels or the wrong size");
    }
    std::vector<std::uint8_t> out;
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    png_infop info = png != nullptr ? png_create_info_struct(png) : nullptr;
    if (png == nullptr || info == nullptr) {
        png_destroy_write_struct(&png, nullptr);
        return makeError(ErrorCode::Io, "libpng could not be initialised");
    }
    std::vector<png_bytep> rows(static_cast<std::size_t>(image.height));
    for (int y = 0; y < image.height; ++y) {
        rows[static_cast<std::size_t>(y)] = const_cast<png_bytep>(
                image.rgb.data() +
                static_cast<std::size_t>(y) * static_cast<std::size_t>(image.width) * 3);
    }
    const PngChunks chunks(meta);
    // libpng reports errors by longjmp; nothing with a destructor is created after this point.
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        return makeError(ErrorCode::Io, "encoding a PNG thumbnail failed");
    }
    png_set_write_fn(png, &out, &appendBytes, &noFlush);
    png_set_compression_level(png, 6);
    png_set_IHDR(png, info, static_cast<png_uint_32>(image.width),
                 static_cast<png_uint_32>(image.height), 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    chunks.apply(png, info);
    png_write_info(png, info);
    png_write_image(png, rows.data());
    png_write_end(png, nullptr);
    png_destroy_write_struct(&png, &info);
    return out;
}

Expected<RgbImage> decodePngRgb(const std::vector<std::uint8_t>& png)
{
    png_image image{};
    image.version = PNG_IMAGE_VERSION;
    if (png.empty() || png_image_begin_read_from_memory(&image, png.data(), png.size()) == 0) {
        return makeError(ErrorCode::Corrupt, fmt::format("not a PNG: {}", image.message));
    }
    if (static_cast<long long>(image.width) * static_cast<long long>(image.height) >
        kMaxThumbnailPixels) {
        png_image_free(&image);
        return makeError(ErrorCode::Corrupt, fmt::format("a PNG of {}x{} pixels is no thumbnail",
                                                         image.width, image.height));
    }
    image.format = PNG_FORMAT_RGB;
    RgbImage out;
    out.width = static_cast<int>(image.width);
    out.height = static_cast<int>(image.height);
    out.rgb.resize(PNG_IMAGE_SIZE(image));
    if (png_image_finish_read(&image, nullptr, out.rgb.data(), 0, nullptr) == 0) {
        return makeError(ErrorCode::Corrupt, fmt::format("damaged PNG: {}", image.message));
    }
    return out;
}

} // namespace replica::platform
