// Thumbnails of displayed frames for recordings: a box-filtered downscale and an in-memory PNG.
#pragma once

#include <cstdint>
#include <vector>

#include <pipeline/base/expected.h>

namespace replica::platform {

struct RgbImage {
    int width = 0;
    int height = 0;
    std::vector<std::uint8_t> rgb; // 3 bytes per pixel, rows top-down (PNG order)
};

// Downscales an 8-bit RGBA frame (rows bottom-up, GL order) to `width` pixels wide (height in
// proportion, rounded, at least 1), dropping alpha. Output pixel (x, y) is the mean of the source
// pixels in columns [floor(x W / w), floor((x + 1) W / w)) and the rows likewise (at least one of
// each), rounded half up: (sum + n / 2) / n in integers. tests/interop/mcap_core_check.cjs
// recomputes this rule independently. A width at or above the frame's keeps the frame's size.
RgbImage downscaleRgba(int width, int height, const std::vector<std::uint8_t>& rgba, int toWidth);

struct PngMetadata; // png_metadata.h

// PNG (8-bit RGB, zlib level 6) of the image, in memory; 'meta': its colour space and time chunks
// (png_metadata.h), none when null.
Expected<std::vector<std::uint8_t>> encodePngRgb(const RgbImage& image,
                                                 const PngMetadata* meta = nullptr);

// The image of a PNG in memory (any colour type, converted to 8-bit RGB by libpng), at most
// kMaxThumbnailPixels; fails with the reason on anything else.
inline constexpr long long kMaxThumbnailPixels = 8192LL * 8192LL;
Expected<RgbImage> decodePngRgb(const std::vector<std::uint8_t>& png);

} // namespace replica::platform
