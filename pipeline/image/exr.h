// Reading and writing float OpenEXR images with named channels; non-finite values are rejected at
// load.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <pipeline/base/expected.h>

namespace replica::pipeline::image {

// Planar float channels, row-major, row 0 at the top of the image (EXR scan-line order).
struct ChannelImage {
    int width = 0;
    int height = 0;
    std::vector<std::string> names;
    std::vector<std::vector<float>> planes; // planes[c][y * width + x]

    const std::vector<float>* plane(const std::string& name) const;
};

// Reads the named channels (all must exist, any pixel type, converted to float). Fails with the
// file and the first offending pixel if any value is NaN or Inf (hard case 18), or if the file is
// not EXR.
Expected<ChannelImage> readExr(const std::filesystem::path& path,
                               const std::vector<std::string>& names);

// Writes 32-bit float channels (or, with halfFloat, 16-bit half channels: OpenEXR rounds each
// value to the nearest half) with ZIP compression; string attributes are stored as header
// comments.
Expected<void> writeExr(const std::filesystem::path& path,
                        const ChannelImage& img,
                        const std::vector<std::pair<std::string, std::string>>& attributes = {},
                        bool halfFloat = false);

} // namespace replica::pipeline::image
