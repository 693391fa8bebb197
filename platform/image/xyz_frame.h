// Reference XYZ frames on disk: small half-float OpenEXR files (channels X, Y, Z, cd/m^2) for
// committed goldens, or PFM (32-bit float) for local comparisons. Chosen by the file's extension.
#pragma once

#include <filesystem>

#include <pipeline/base/expected.h>
#include <platform/image/pfm.h>

namespace replica::platform {

// .exr: half-float X, Y, Z with ZIP compression (about 11 bits of mantissa: a relative rounding of
// at most 2^-11, far below 0.1 ΔE00); anything else: PFM.
Expected<void> writeXyzFrame(const std::filesystem::path& path, const FloatImage& image);
// Reads either kind; rows come back bottom-up (GL order), like FloatImage everywhere.
Expected<FloatImage> readXyzFrame(const std::filesystem::path& path);

} // namespace replica::platform
