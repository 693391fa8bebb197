// What the KMS output decides before it draws: which mode to drive (from a request such as
// "1920x1080@60", or the preferred one), and how large the panel is physically (from the site's
// configuration, else the display's EDID, else the shipped 24-inch stand). Pure, so it is tested
// without a display.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <pipeline/base/expected.h>

namespace replica::platform {

// One of a connector's modes, as KMS lists it.
struct DisplayMode {
    int width = 0;
    int height = 0;
    int refreshHz = 0;
    bool preferred = false;
};

// "WIDTHxHEIGHT" in pixels: two whole numbers (digits only) joined by 'x' or 'X', nothing
// around them; nullopt otherwise. The one parser of a pixel size (run --size, the site file's
// display.size, render --size, plan --check, the KMS mode): each side is read whole as a 64-bit
// number before any range check or narrowing, so that 4294967392 is a side far out of range, not
// 96 (a side past 18 digits is refused as not a number). The caller checks its own range.
std::optional<std::pair<long long, long long>> parsePixelSize(std::string_view text);

// A mode request: "WIDTHxHEIGHT" or "WIDTHxHEIGHT@HZ"; empty: the preferred mode.
struct ModeRequest {
    int width = 0; // 0: no request
    int height = 0;
    int refreshHz = 0; // 0: any rate (the highest of that size)
};

Expected<ModeRequest> parseModeRequest(const std::string& text);

// The index of the mode to drive: the requested size (at the requested rate, else the highest
// rate of that size), or with no request the preferred mode (the first listed when none is marked
// preferred). A request no mode meets is an error that lists the modes there are.
Expected<std::size_t> chooseMode(std::span<const DisplayMode> modes, const ModeRequest& request);

// A physical size in millimetres (the panel's active area).
struct SizeMm {
    double width = 0.0;
    double height = 0.0;
};

// "518x324" (millimetres): the panel's active area, for --panel-size-mm and the site file.
Expected<SizeMm> parseSizeMm(const std::string& text);

// The physical size an EDID base block gives: the first detailed timing descriptor's image size in
// millimetres (bytes 66-68), else the basic display parameters' size in centimetres (bytes 21-22).
// Nullopt when the block is not an EDID (header or checksum wrong) or gives no size (zeros, or an
// aspect ratio in place of a size).
std::optional<SizeMm> edidPhysicalSize(std::span<const std::uint8_t> edid);

// The panel's active area the renderer maps the frame onto, and where it came from.
struct PanelSize {
    double widthM = 0.0;
    double heightM = 0.0;
    std::string source; // "configured", "edid" or "default"
};

// The geometry rule every output follows: the configured size when there is one, else the
// display's own (EDID), else the default (the stand model's 24-inch 16:10 panel).
PanelSize resolvePanelSize(const std::optional<SizeMm>& configured,
                           const std::optional<SizeMm>& edid,
                           double defaultWidthM,
                           double defaultHeightM);

// How far the pixels' aspect (the panel's millimetres per pixel across over down) is from square:
// |ratio - 1|. A frame shows surfaces at their true size only when this is near 0.
double pixelAspectError(const PanelSize& panel, int widthPx, int heightPx);

} // namespace replica::platform
