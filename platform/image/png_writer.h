// Writing 8-bit RGBA frames as PNG snapshots.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include <pipeline/base/expected.h>

namespace replica::platform {

struct PngMetadata; // png_metadata.h

// rgba: width * height * 4 bytes, rows bottom-up (GL order); the PNG is written top-down. 'meta':
// the colour space and time chunks (png_metadata.h), none when null.
Expected<void> writePng(const std::filesystem::path& path,
                        int width,
                        int height,
                        const std::vector<std::uint8_t>& rgba,
                        const PngMetadata* meta = nullptr);

} // namespace replica::platform
