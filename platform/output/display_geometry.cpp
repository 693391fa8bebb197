// Mode choice, EDID physical size and the panel-size rule (display_geometry.h).
#include <charconv>
#include <cmath>
#include <cstdio>

#include <fmt/format.h>

#include <platform/output/display_geometry.h>

namespace replica::platform {

namespace {

// A whole number of digits only (no sign, no spaces), read whole: nullopt when it is not one or
// does not fit 64 bits.
std::optional<long long> wholeNumber(std::string_view text)
{
    long long v = 0;
    const char* end = text.data() + text.size();
    if (text.empty() || text.front() < '0' || text.front() > '9') {
        return std::nullopt;
    }
    const auto [ptr, ec] = std::from_chars(text.data(), end, v);
    if (ec != std::errc() || ptr != end) {
        return std::nullopt;
    }
    return v;
}

} // namespace

std::optional<std::pair<long long, long long>> parsePixelSize(std::string_view text)
{
    const auto x = text.find_first_of("xX");
    if (x == std::string_view::npos) {
        return std::nullopt;
    }
    const auto w = wholeNumber(text.substr(0, x));
    const auto h = wholeNumber(text.substr(x + 1));
    if (!w || !h) {
        return std::nullopt;
    }
    return std::make_pair(*w, *h);
}

Expected<ModeRequest> parseModeRequest(const std::string& text)
{
    ModeRequest r;
    if (text.empty()) {
        return r;
    }
    const auto at = text.find('@');
    const auto size = parsePixelSize(std::string_view(text).substr(0, at));
    const auto hz = at == std::string::npos ? std::optional<long long>(0)
                                            : wholeNumber(std::string_view(text).substr(at + 1));
    if (!size || !hz || size->first <= 0 || size->second <= 0 || size->first > 16384 ||
        size->second > 16384 || *hz > 1000) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("mode '{}': expected WIDTHxHEIGHT or WIDTHxHEIGHT@HZ, e.g. "
                                     "1920x1200 or 1920x1200@60",
                                     text));
    }
    r.width = static_cast<int>(size->first);
    r.height = static_cast<int>(size->second);
    r.refreshHz = static_cast<int>(*hz);
    return r;
}

Expected<std::size_t> chooseMode(std::span<const DisplayMode> modes, const ModeRequest& request)
{
    if (modes.empty()) {
        return makeError(ErrorCode::NotFound, "the display lists no modes");
    }
    if (request.width == 0) {
        for (std::size_t i = 0; i < modes.size(); ++i) {
            if (modes[i].preferred) {
                return i;
            }
        }
        return std::size_t{0};
    }
    std::optional<std::size_t> best;
    for (std::size_t i = 0; i < modes.size(); ++i) {
        const DisplayMode& m = modes[i];
        if (m.width != request.width || m.height != request.height) {
            continue;
        }
        if (request.refreshHz != 0) {
            if (m.refreshHz == request.refreshHz) {
                return i;
            }
        } else if (!best || m.refreshHz > modes[*best].refreshHz) {
            best = i;
        }
    }
    if (best) {
        return *best;
    }
    std::string listed;
    for (const DisplayMode& m : modes) {
        listed += fmt::format("{}{}x{}@{}{}", listed.empty() ? "" : ", ", m.width, m.height,
                              m.refreshHz, m.preferred ? " (preferred)" : "");
    }
    return makeError(ErrorCode::NotFound,
                     fmt::format("no mode {}x{}{} on this display (it has {}); pick one of those",
                                 request.width, request.height,
                                 request.refreshHz != 0 ? fmt::format("@{}", request.refreshHz)
                                                        : std::string(),
                                 listed));
}

Expected<SizeMm> parseSizeMm(const std::string& text)
{
    double w = 0.0;
    double h = 0.0;
    char x = 0;
    char extra = 0;
    // A panel between 20 mm and 10 m across: anything else is a unit mistake (metres, inches).
    if (std::sscanf(text.c_str(), "%lf%c%lf%c", &w, &x, &h, &extra) != 3 ||
        (x != 'x' && x != 'X') || !(w >= 20.0 && w <= 10000.0) || !(h >= 20.0 && h <= 10000.0)) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("panel size '{}': expected the active area as WIDTHxHEIGHT "
                                     "in millimetres, each 20 to 10000, e.g. 518x324",
                                     text));
    }
    return SizeMm{w, h};
}

std::optional<SizeMm> edidPhysicalSize(std::span<const std::uint8_t> edid)
{
    static constexpr std::uint8_t kHeader[8] = {0x00, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0x00};
    if (edid.size() < 128) {
        return std::nullopt;
    }
    for (int i = 0; i < 8; ++i) {
        if (edid[static_cast<std::size_t>(i)] != kHeader[i]) {
            return std::nullopt;
        }
    }
    unsigned sum = 0;
    for (std::size_t i = 0; i < 128; ++i) {
        sum += edid[i];
    }
    if (sum % 256 != 0) {
        return std::nullopt;
    }
    // The first 18-byte descriptor is a detailed timing when its pixel clock (bytes 54-55) is not
    // zero; its image size is 12 bits each: bytes 66 and 67 low, byte 68 the high nibbles.
    if (edid[54] != 0 || edid[55] != 0) {
        const int w = edid[66] | ((edid[68] & 0xf0) << 4);
        const int h = edid[67] | ((edid[68] & 0x0f) << 8);
        // Some panels put the size in centimetres here or leave it 0; trust it only when it
        // agrees with bytes 21-22 to within a centimetre-and-a-bit (or those are unset).
        const int wcm = edid[21];
        const int hcm = edid[22];
        const bool agrees = (wcm == 0 || hcm == 0) ||
                            (std::abs(w - 10 * wcm) <= 15 && std::abs(h - 10 * hcm) <= 15);
        if (w > 0 && h > 0 && agrees) {
            return SizeMm{static_cast<double>(w), static_cast<double>(h)};
        }
    }
    // EDID 1.3/1.4 basic parameters: size in cm; one of them 0 means an aspect ratio (1.4) or
    // unknown (a projector).
    if (edid[21] != 0 && edid[22] != 0) {
        return SizeMm{10.0 * edid[21], 10.0 * edid[22]};
    }
    return std::nullopt;
}

PanelSize resolvePanelSize(const std::optional<SizeMm>& configured,
                           const std::optional<SizeMm>& edid,
                           double defaultWidthM,
                           double defaultHeightM)
{
    if (configured) {
        return {configured->width / 1000.0, configured->height / 1000.0, "configured"};
    }
    if (edid && edid->width > 0.0 && edid->height > 0.0) {
        return {edid->width / 1000.0, edid->height / 1000.0, "edid"};
    }
    return {defaultWidthM, defaultHeightM, "default"};
}

double pixelAspectError(const PanelSize& panel, int widthPx, int heightPx)
{
    if (widthPx <= 0 || heightPx <= 0 || !(panel.widthM > 0.0) || !(panel.heightM > 0.0)) {
        return INFINITY;
    }
    const double across = panel.widthM / widthPx;
    const double down = panel.heightM / heightPx;
    return std::abs(across / down - 1.0);
}

} // namespace replica::platform
