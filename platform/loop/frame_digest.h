// Frame digests: a 64-bit hash of each read-back frame, written as JSON for replay checks.
// Digest files of version 1 hash with FNV-1a (byte at a time, ~19 ms a 960x600 XYZ frame); version
// 2, what new runs write, with XXH3-64 from libxxhash (the same frame in about 1 ms). A replay
// checked against a golden hashes with the golden's own algorithm, so version 1 goldens still
// verify.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include <pipeline/base/expected.h>

namespace replica::platform {

std::uint64_t fnv1a64(std::span<const std::uint8_t> bytes);
// XXH3-64 with seed 0 (the reference algorithm's default, as `xxhsum -H3` prints it).
std::uint64_t xxh3_64(std::span<const std::uint8_t> bytes);

// A digest file's version is its hash: 1 = FNV-1a 64, 2 = XXH3-64.
enum class DigestHash : int { Fnv1a64 = 1, Xxh3_64 = 2 };
constexpr DigestHash kDigestHash = DigestHash::Xxh3_64; // what new digest files use
std::uint64_t frameHash(DigestHash hash, std::span<const std::uint8_t> bytes);
const char* digestHashName(DigestHash hash); // "fnv1a64", "xxh3_64"

struct FrameDigest {
    std::uint64_t frameIndex = 0;
    std::int64_t tickNs = 0;
    std::uint64_t xyz = 0;  // hash of the RGBA32F absolute-XYZ frame
    std::uint64_t rgba = 0; // hash of the 8-bit display frame
    bool operator==(const FrameDigest&) const = default;
};

struct DigestFile {
    DigestHash hash = kDigestHash;
    std::vector<FrameDigest> frames;
};

Expected<void> writeDigests(const std::filesystem::path& path,
                            const std::vector<FrameDigest>& d,
                            DigestHash hash = kDigestHash);
Expected<DigestFile> readDigestFile(const std::filesystem::path& path);

} // namespace replica::platform
