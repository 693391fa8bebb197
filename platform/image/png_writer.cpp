// libpng snapshot writer.
#include <string>

#include <fmt/format.h>
#include <png.h>

#include <pipeline/base/output_file.h>
#include <platform/image/png_metadata.h>
#include <platform/image/png_writer.h>

namespace replica::platform {

Expected<void> writePng(const std::filesystem::path& path,
                        int width,
                        int height,
                        const std::vector<std::uint8_t>& rgba,
                        const PngMetadata* meta)
{
    if (width <= 0 || height <= 0 ||
        rgba.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 4) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: frame has no pixels or the wrong size", path.string()));
    }
    // Encoded in memory, then written the one safe way (pipeline/base/output_file.h).
    std::string encoded;
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    png_infop info = png != nullptr ? png_create_info_struct(png) : nullptr;
    if (png == nullptr || info == nullptr) {
        png_destroy_write_struct(&png, nullptr);
        return makeError(ErrorCode::Io, "libpng could not be initialised");
    }
    std::vector<png_bytep> rows(static_cast<std::size_t>(height));
    for (int y = 0; y < height; ++y) {
        // GL rows are bottom-up; PNG rows top-down.
        rows[static_cast<std::size_t>(y)] =
                const_cast<png_bytep>(rgba.data() + static_cast<std::size_t>(height - 1 - y) *
                                                            static_cast<std::size_t>(width) * 4);
    }
    const PngChunks chunks(meta);
    // libpng reports errors by longjmp; nothing with a destructor is created after this point.
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        return makeError(ErrorCode::Io, fmt::format("{}: writing PNG failed", path.string()));
    }
    png_set_write_fn(
            png, &encoded,
            [](png_structp p, png_bytep data, png_size_t n) {
                static_cast<std::string*>(png_get_io_ptr(p))
                        ->append(reinterpret_cast<const char*>(data), n);
            },
            nullptr);
    png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8,
                 PNG_COLOR_TYPE_RGBA, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    chunks.apply(png, info);
    png_write_info(png, info);
    png_write_image(png, rows.data());
    png_write_end(png, nullptr);
    png_destroy_write_struct(&png, &info);
    return writeOutputFile(path, encoded, "PNG");
}

} // namespace replica::platform
