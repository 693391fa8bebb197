// Copies a rendered RGBA frame (rows bottom-up, as GL reads them) into a scan-out buffer in
// XRGB8888 (rows top-down, with its own pitch), centred, with black borders where the frame is
// smaller than the mode and cropped where it is larger. Pure, so it is tested without a display.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

namespace replica::platform {

struct ScanoutBuffer {
    int width = 0;
    int height = 0;
    std::size_t pitchBytes = 0; // bytes per row, >= 4 * width
    std::span<std::uint8_t> bytes;
};

void copyToScanout(int frameWidth,
                   int frameHeight,
                   std::span<const std::uint8_t> rgba,
                   const ScanoutBuffer& dst);

} // namespace replica::platform
