// Frame digests: a 64-bit FNV-1a hash of each read-back frame, written as JSON for replay checks.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include <pipeline/base/expected.h>

namespace replica::platform {

std::uint64_t fnv1a64(std::span<const std::uint8_t> bytes);

struct FrameDigest {
    std::uint64_t frameIndex = 0;
    std::int64_t tickNs = 0;
    std::uint64_t xyz = 0;  // hash of the RGBA32F absolute-XYZ frame
    std::uint64_t rgba = 0; // hash of the 8-bit display frame
    bool operator==(const FrameDigest&) const = default;
};

Expected<void> writeDigests(const std::filesystem::path& path, const std::vector<FrameDigest>& d);
Expected<std::vector<FrameDigest>> readDigests(const std::filesystem::path& path);

// The first index where the two lists differ (in any field or in length), or -1 if they are equal.
long firstDifference(const std::vector<FrameDigest>& a, const std::vector<FrameDigest>& b);

} // namespace replica::platform
