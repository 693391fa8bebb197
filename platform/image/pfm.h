// Portable Float Map (PFM, 3 channels) files: the XYZ frames that replay comparisons keep.
#pragma once

#include <filesystem>
#include <vector>

#include <pipeline/base/expected.h>

namespace replica::platform {

struct FloatImage {
    int width = 0;
    int height = 0;
    std::vector<float> rgba; // 4 floats per pixel (the fourth is 1), rows bottom-up (GL order)
};

// Writes the first three channels; PFM stores rows bottom-up, as GL reads them back.
Expected<void> writePfm(const std::filesystem::path& path, const FloatImage& image);
// Reads a 3-channel little- or big-endian PFM; errors name the file and the problem.
Expected<FloatImage> readPfm(const std::filesystem::path& path);

} // namespace replica::platform
