// ΔE00 between frames through the colour library's CIELAB and CIEDE2000 (no second implementation).
#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include <pipeline/colour/ciede2000.h>
#include <pipeline/colour/cielab.h>
#include <platform/cli/frame_compare.h>
#include <platform/image/png_writer.h>

namespace replica::platform {

Expected<std::vector<double>>
deltaE00Image(const FloatImage& a, const FloatImage& b, const pipeline::colour::Xyz& white)
{
    if (a.width != b.width || a.height != b.height || a.rgba.size() != b.rgba.size()) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("frames differ in size ({}x{} and {}x{}); cannot compare",
                                     a.width, a.height, b.width, b.height));
    }
    const std::size_t pixels = a.rgba.size() / 4;
    std::vector<double> out(pixels);
    for (std::size_t p = 0; p < pixels; ++p) {
        const pipeline::colour::Xyz xa{a.rgba[p * 4], a.rgba[p * 4 + 1], a.rgba[p * 4 + 2]};
        const pipeline::colour::Xyz xb{b.rgba[p * 4], b.rgba[p * 4 + 1], b.rgba[p * 4 + 2]};
        const double d = pipeline::colour::ciede2000(pipeline::colour::xyzToLab(xa, white),
                                                     pipeline::colour::xyzToLab(xb, white));
        // A non-finite pixel (NaN in a frame) is the largest difference there is.
        out[p] = std::isfinite(d) ? d : HUGE_VAL;
    }
    return out;
}

DeltaEStats summarise(std::vector<double> deltaE)
{
    DeltaEStats s;
    s.pixels = deltaE.size();
    if (deltaE.empty()) {
        return s;
    }
    std::sort(deltaE.begin(), deltaE.end());
    double sum = 0.0;
    std::size_t above1 = 0, above2 = 0;
    for (double d : deltaE) {
        sum += d;
        above1 += d > 1.0 ? 1 : 0;
        above2 += d > 2.0 ? 1 : 0;
    }
    const auto n = static_cast<double>(deltaE.size());
    auto at = [&](double q) {
        const auto i = static_cast<std::size_t>(std::ceil(q * n)) - 1;
        return deltaE[std::min(i, deltaE.size() - 1)];
    };
    s.mean = sum / n;
    s.median = at(0.5);
    s.p95 = at(0.95);
    s.max = deltaE.back();
    s.fractionAbove1 = static_cast<double>(above1) / n;
    s.fractionAbove2 = static_cast<double>(above2) / n;
    return s;
}

Expected<void> writeDifferencePng(const std::filesystem::path& path,
                                  int width,
                                  int height,
                                  const std::vector<double>& deltaE)
{
    std::vector<std::uint8_t> rgba(deltaE.size() * 4, 255);
    for (std::size_t p = 0; p < deltaE.size(); ++p) {
        const double v = std::clamp(deltaE[p] / 10.0, 0.0, 1.0) * 255.0;
        const auto g = static_cast<std::uint8_t>(std::lround(v));
        rgba[p * 4] = rgba[p * 4 + 1] = rgba[p * 4 + 2] = g;
    }
    return writePng(path, width, height, rgba);
}

} // namespace replica::platform
