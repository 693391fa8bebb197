// Comparing a replayed frame with a reference frame: per-pixel CIEDE2000 and its statistics, and a
// difference image, for 'replica replay --check' when a frame no longer matches its golden digest.
#pragma once

#include <filesystem>
#include <vector>

#include <pipeline/base/expected.h>
#include <pipeline/colour/xyz.h>
#include <platform/image/pfm.h>

namespace replica::platform {

struct DeltaEStats {
    std::size_t pixels = 0;
    double mean = 0.0, median = 0.0, p95 = 0.0, max = 0.0;
    double fractionAbove1 = 0.0, fractionAbove2 = 0.0; // share of pixels over 1 and 2 ΔE00
};

// ΔE00 per pixel between two absolute-XYZ frames of the same size, both converted to CIELAB
// relative to `white` (the display's white, cd/m^2). Fails when the sizes differ.
Expected<std::vector<double>>
deltaE00Image(const FloatImage& a, const FloatImage& b, const pipeline::colour::Xyz& white);
DeltaEStats summarise(std::vector<double> deltaE);

// Writes the ΔE00 image as a PNG: black = identical, white = 10 ΔE00 or more (linear between).
Expected<void> writeDifferencePng(const std::filesystem::path& path,
                                  int width,
                                  int height,
                                  const std::vector<double>& deltaE);

} // namespace replica::platform
