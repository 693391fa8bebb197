// What the run and replay commands keep from each frame: digests and the last frame for a snapshot.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <pipeline/render/renderer.h>
#include <platform/loop/frame_digest.h>
#include <platform/loop/frame_loop.h>

namespace replica::platform {

class FrameOutputs
{
public:
    // digests: hash every frame; keepLastFrame: keep the last frame's display values for a
    // snapshot.
    FrameOutputs(bool digests, bool keepLastFrame, DigestHash hash = kDigestHash)
        : digest_(digests), keepLast_(keepLastFrame), hash_(hash)
    {}
    // What the loop must read back for this.
    pipeline::render::Readback readback() const;
    // One frame's digests and, when kept, its display values.
    void add(const recordings::FrameRecord& f, const pipeline::render::RenderedFrame& image);
    const std::vector<FrameDigest>& digests() const { return digests_; }
    DigestHash hash() const { return hash_; }
    // The snapshot's colour space and time chunks (png_metadata.h): the display profile as ICC
    // (empty: sRGB) and the session's wall-clock start (0: unknown).
    void
    tagSnapshot(std::vector<std::uint8_t> icc, std::string profileName, std::int64_t wallStartNs)
    {
        icc_ = std::move(icc);
        iccName_ = std::move(profileName);
        wallStartNs_ = wallStartNs;
        tagged_ = true;
    }
    // Writes the digest file and the PNG snapshot of the last frame (either path may be empty).
    Expected<void> finish(const std::string& digestPath, const std::string& snapshotPath) const;

private:
    bool digest_;
    bool keepLast_;
    DigestHash hash_;
    std::vector<FrameDigest> digests_;
    int lastWidth_ = 0;
    int lastHeight_ = 0;
    std::vector<std::uint8_t> lastRgba_;
    std::int64_t lastTickNs_ = 0;
    std::uint64_t lastFrame_ = 0;
    bool tagged_ = false;
    std::vector<std::uint8_t> icc_;
    std::string iccName_;
    std::int64_t wallStartNs_ = 0;
};

} // namespace replica::platform
