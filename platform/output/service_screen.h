// The panel's service screen: when the kiosk refuses its configuration, the panel says what
// failed, where, and the command that checks it, instead of staying black. Drawn with a small
// built-in 5x7 bitmap font (printable ASCII; anything else shows as '?').
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <pipeline/base/expected.h>
#include <platform/output/output.h>

namespace replica::platform {

struct ServiceImage {
    int width = 0;
    int height = 0;
    std::vector<std::uint8_t> rgba; // rows bottom-up (GL order), as DisplayFrame
};

// The text laid out on a width x height frame: 'title' first, then each of 'lines' wrapped at the
// frame's width, as large as fits (the font scaled by a whole number).
ServiceImage renderServiceScreen(int width,
                                 int height,
                                 const std::string& title,
                                 const std::vector<std::string>& lines);

// Whether the pixel at column x, row y (top-down) of a character of the built-in font is lit
// (x 0-4, y 0-6).
bool fontPixel(char c, int x, int y);

// Hands the image to the output as a frame (a framebuffer in the output's GL context).
Expected<void> presentServiceScreen(Output& output, const ServiceImage& image);

} // namespace replica::platform
