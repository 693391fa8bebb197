// Frame digests (FNV-1a for version 1 files, XXH3-64 for version 2) and their JSON file.
#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <xxhash.h>

#include <pipeline/base/input_file.h>
#include <pipeline/base/json_limits.h>
#include <pipeline/base/output_file.h>
#include <platform/loop/frame_digest.h>

namespace replica::platform {

std::uint64_t fnv1a64(std::span<const std::uint8_t> bytes)
{
    std::uint64_t h = 0xcbf29ce484222325ULL;
    for (std::uint8_t b : bytes) {
        h ^= b;
        h *= 0x100000001b3ULL;
    }
    return h;
}

std::uint64_t xxh3_64(std::span<const std::uint8_t> bytes)
{
    return XXH3_64bits(bytes.data(), bytes.size());
}

std::uint64_t frameHash(DigestHash hash, std::span<const std::uint8_t> bytes)
{
    return hash == DigestHash::Fnv1a64 ? fnv1a64(bytes) : xxh3_64(bytes);
}

const char* digestHashName(DigestHash hash)
{
    return hash == DigestHash::Fnv1a64 ? "fnv1a64" : "xxh3_64";
}

Expected<void>
writeDigests(const std::filesystem::path& path, const std::vector<FrameDigest>& d, DigestHash hash)
{
    // One frame per line so that a diff of two digest files points at the frame.
    // Version 1 files name no hash (FNV-1a); version 2 says it.
    std::string out;
    if (hash == DigestHash::Fnv1a64) {
        out += "{\"format\": \"replica-digests\", \"version\": 1, \"frames\": [\n";
    } else {
        out += fmt::format("{{\"format\": \"replica-digests\", \"version\": {}, \"hash\": "
                           "\"{}\", \"frames\": [\n",
                           static_cast<int>(hash), digestHashName(hash));
    }
    for (std::size_t i = 0; i < d.size(); ++i) {
        out += fmt::format("  {{\"frame\": {}, \"tick_ns\": {}, \"xyz\": \"{:016x}\", \"rgba\": "
                           "\"{:016x}\"}}{}\n",
                           d[i].frameIndex, d[i].tickNs, d[i].xyz, d[i].rgba,
                           i + 1 < d.size() ? "," : "");
    }
    out += "]}\n";
    return writeOutputFile(path, out, "digests");
}

Expected<DigestFile> readDigestFile(const std::filesystem::path& path)
{
    auto in = readInputFile(path, kMaxJsonBytes, "digests");
    if (!in) {
        if (in.error().code == ErrorCode::NotFound) {
            return makeError(ErrorCode::NotFound,
                             fmt::format("{}: cannot open digests", path.string()));
        }
        return tl::unexpected(in.error());
    }
    if (auto ok = checkJsonLimits(*in, path.string()); !ok) {
        return tl::unexpected(ok.error());
    }
    DigestFile file;
    auto& out = file.frames;
    try {
        const auto j = nlohmann::json::parse(*in);
        if (j.value("format", "") != "replica-digests") {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("{}: not a replica digest file", path.string()));
        }
        const int version = j.value("version", 1);
        if (version == 1) {
            file.hash = DigestHash::Fnv1a64;
        } else if (version == 2 && j.value("hash", "") == "xxh3_64") {
            file.hash = DigestHash::Xxh3_64;
        } else {
            return makeError(ErrorCode::Unsupported,
                             fmt::format("{}: digest file version {} (hash '{}') is not one this "
                                         "replica knows (1: fnv1a64, 2: xxh3_64); update replica",
                                         path.string(), version, j.value("hash", "")));
        }
        for (const auto& f : j.at("frames")) {
            FrameDigest d;
            d.frameIndex = f.at("frame").get<std::uint64_t>();
            d.tickNs = f.at("tick_ns").get<std::int64_t>();
            d.xyz = std::stoull(f.at("xyz").get<std::string>(), nullptr, 16);
            d.rgba = std::stoull(f.at("rgba").get<std::string>(), nullptr, 16);
            out.push_back(d);
        }
    } catch (const std::exception& e) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: malformed digest file: {}", path.string(), e.what()));
    }
    return file;
}

} // namespace replica::platform
