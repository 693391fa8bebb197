// An older recording on this build: the replayed frames against what the recording holds of what
// the panel showed (its thumbnails, and its display digests where they match), colorimetrically.
// A recording made with an older render profile (pipeline/render/render_profile.h), or drawn by
// the flat renderer (not in this build), replays on this build's render path; bit-exact replay of
// it is the build that made it's to promise.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <pipeline/base/expected.h>
#include <pipeline/display/display_model.h>
#include <platform/cli/frame_compare.h>
#include <platform/image/thumbnail.h>
#include <recordings/recording.h>

namespace replica::platform {

// A frame passes when the 95th percentile of ΔE00 over its thumbnail's pixels is at most this.
// The appliance's render budget is p95 1.0 ΔE00 against the exact reference (docs/rendering.md);
// two render paths each within it are within 2.0 of each other, and that is all an older
// recording's frames are promised on a newer build. The 95th percentile, not the maximum: a
// thumbnail pixel is the mean of a box of panel pixels in 8-bit counts, so a moved edge or the
// dither changes a few of them by more without the picture changing.
inline constexpr double kShownToleranceDe00 = 2.0;

// One thumbnail measured against the replayed frame of its tick.
struct ShownFrameDeltaE {
    std::uint64_t frame = 0;
    std::int64_t tickNs = 0;
    DeltaEStats stats;
};

class ShownComparison
{
public:
    // 'model': the recording's display model, through which drive values become XYZ.
    ShownComparison(const recordings::Recording& recording,
                    pipeline::display::DisplayModel model,
                    double toleranceDe00);

    // The thumbnails the recording holds.
    std::size_t thumbnails() const { return thumbnails_.size(); }
    // The replayed frame of tick 'tickNs' (display counts, RGBA rows bottom-up): measured against
    // the thumbnail of that tick, if the recording holds one. Fails on a thumbnail that is no PNG
    // or of another shape than the frame's.
    Expected<void> add(std::uint64_t frameIndex,
                       std::int64_t tickNs,
                       int width,
                       int height,
                       const std::vector<std::uint8_t>& rgba);

    const std::vector<ShownFrameDeltaE>& measured() const { return measured_; }
    // The measured frames, worst p95 first, at most 'count'.
    std::vector<ShownFrameDeltaE> worst(std::size_t count) const;
    // Every measured frame within the tolerance (true when none was measured).
    bool within() const;
    double tolerance() const { return tolerance_; }
    // The --json summary's "shown_check".
    nlohmann::json json() const;

private:
    // Drive values (8-bit counts, RGB) as absolute XYZ through the display model.
    FloatImage toXyz(const RgbImage& image) const;

    std::map<std::int64_t, const recordings::ThumbnailRecord*> thumbnails_; // by tick
    pipeline::display::DisplayModel model_;
    double tolerance_;
    std::vector<ShownFrameDeltaE> measured_;
};

// The one line an older recording's replay starts with: who made it, with which render profile
// (and that the flat renderer drew it, when it did: this build draws it with the booth pass), and
// what bit-exact replay needs.
std::string olderRecordingLine(const std::string& file,
                               const std::string& madeBy,
                               int recordedProfile,
                               bool drawnByFlatRenderer);

} // namespace replica::platform
