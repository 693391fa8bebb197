// XYZ reference frames as half-float EXR (through pipeline/image/exr) or PFM.
#include <algorithm>

#include <fmt/format.h>

#include <pipeline/image/exr.h>
#include <platform/image/xyz_frame.h>

namespace replica::platform {
namespace {

bool isExr(const std::filesystem::path& path)
{
    return path.extension() == ".exr";
}

} // namespace

Expected<void> writeXyzFrame(const std::filesystem::path& path, const FloatImage& image)
{
    if (!isExr(path)) {
        return writePfm(path, image);
    }
    const auto w = static_cast<std::size_t>(std::max(image.width, 0));
    const auto h = static_cast<std::size_t>(std::max(image.height, 0));
    if (w == 0 || h == 0 || image.rgba.size() != w * h * 4) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: no image to write ({}x{}, {} values)", path.string(),
                                     image.width, image.height, image.rgba.size()));
    }
    pipeline::image::ChannelImage img;
    img.width = image.width;
    img.height = image.height;
    img.names = {"X", "Y", "Z"};
    img.planes.assign(3, std::vector<float>(w * h));
    for (std::size_t y = 0; y < h; ++y) {
        const std::size_t src = (h - 1 - y) * w; // GL rows bottom-up; EXR rows top-down
        for (std::size_t x = 0; x < w; ++x) {
            for (std::size_t c = 0; c < 3; ++c) {
                img.planes[c][y * w + x] = image.rgba[(src + x) * 4 + c];
            }
        }
    }
    return pipeline::image::writeExr(path, img, {{"replica", "absolute XYZ, cd/m^2"}}, true);
}

Expected<FloatImage> readXyzFrame(const std::filesystem::path& path)
{
    if (!isExr(path)) {
        return readPfm(path);
    }
    auto img = pipeline::image::readExr(path, {"X", "Y", "Z"});
    if (!img) {
        return tl::unexpected(img.error());
    }
    const auto w = static_cast<std::size_t>(img->width);
    const auto h = static_cast<std::size_t>(img->height);
    FloatImage out{img->width, img->height, std::vector<float>(w * h * 4, 1.0f)};
    for (std::size_t y = 0; y < h; ++y) {
        const std::size_t dst = (h - 1 - y) * w;
        for (std::size_t x = 0; x < w; ++x) {
            for (std::size_t c = 0; c < 3; ++c) {
                out.rgba[(dst + x) * 4 + c] = img->planes[c][y * w + x];
            }
        }
    }
    return out;
}

} // namespace replica::platform
