// RGBA (bottom-up) to XRGB8888 (top-down) with centring.
#include <algorithm>
#include <cstring>

#include <platform/output/scanout_copy.h>

namespace replica::platform {

void copyToScanout(int frameWidth,
                   int frameHeight,
                   std::span<const std::uint8_t> rgba,
                   const ScanoutBuffer& dst)
{
    for (int y = 0; y < dst.height; ++y) {
        std::memset(dst.bytes.data() + static_cast<std::size_t>(y) * dst.pitchBytes, 0,
                    static_cast<std::size_t>(dst.width) * 4);
    }
    if (rgba.size() <
        static_cast<std::size_t>(frameWidth) * static_cast<std::size_t>(frameHeight) * 4) {
        return; // no pixels were read back: show black rather than garbage
    }
    // Offsets of the frame inside the buffer (negative: the frame is cropped on that side).
    const int ox = (dst.width - frameWidth) / 2;
    const int oy = (dst.height - frameHeight) / 2;
    const int x0 = std::max(0, ox);
    const int x1 = std::min(dst.width, ox + frameWidth);
    const int y0 = std::max(0, oy);
    const int y1 = std::min(dst.height, oy + frameHeight);
    for (int y = y0; y < y1; ++y) {
        const int frameRowTopDown = y - oy;
        const int frameRow = frameHeight - 1 - frameRowTopDown; // GL rows run bottom-up
        const std::uint8_t* src = rgba.data() + (static_cast<std::size_t>(frameRow) *
                                                         static_cast<std::size_t>(frameWidth) +
                                                 static_cast<std::size_t>(x0 - ox)) *
                                                        4;
        std::uint8_t* out = dst.bytes.data() + static_cast<std::size_t>(y) * dst.pitchBytes +
                            static_cast<std::size_t>(x0) * 4;
        for (int x = x0; x < x1; ++x, src += 4, out += 4) {
            // XRGB8888 is a little-endian 32-bit word: bytes B, G, R, X.
            out[0] = src[2];
            out[1] = src[1];
            out[2] = src[0];
            out[3] = 0xFF;
        }
    }
}

} // namespace replica::platform
