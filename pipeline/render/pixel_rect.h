// A rectangle of framebuffer pixels in GL window coordinates (x right, y up from the bottom row).
#pragma once

namespace replica::pipeline::render {

struct PixelRect {
    int x = 0;
    int y = 0;
    int width = 0;
    int height = 0;
    bool operator==(const PixelRect&) const = default;
};

} // namespace replica::pipeline::render
