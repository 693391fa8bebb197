#include <algorithm>

#include <fmt/format.h>

#include <pipeline/base/printable.h>
#include <pipeline/render/render_profile.h>
#include <platform/cli/replay_shown.h>

namespace replica::platform {

ShownComparison::ShownComparison(const recordings::Recording& recording,
                                 pipeline::display::DisplayModel model,
                                 double toleranceDe00)
    : model_(std::move(model)), tolerance_(toleranceDe00)
{
    for (const auto& t : recording.thumbnails) {
        thumbnails_.emplace(t.tNs, &t);
    }
}

FloatImage ShownComparison::toXyz(const RgbImage& image) const
{
    FloatImage out;
    out.width = image.width;
    out.height = image.height;
    out.rgba.reserve(image.rgb.size() / 3 * 4);
    for (std::size_t p = 0; p + 2 < image.rgb.size(); p += 3) {
        const glm::dvec3 xyz = model_.forward({image.rgb[p], image.rgb[p + 1], image.rgb[p + 2]});
        out.rgba.insert(out.rgba.end(), {static_cast<float>(xyz.x), static_cast<float>(xyz.y),
                                         static_cast<float>(xyz.z), 1.0f});
    }
    return out;
}

Expected<void> ShownComparison::add(std::uint64_t frameIndex,
                                    std::int64_t tickNs,
                                    int width,
                                    int height,
                                    const std::vector<std::uint8_t>& rgba)
{
    const auto it = thumbnails_.find(tickNs);
    if (it == thumbnails_.end() || rgba.empty()) {
        return {};
    }
    auto shown = decodePngRgb(it->second->png);
    if (!shown) {
        return makeError(ErrorCode::Corrupt, fmt::format("the thumbnail of frame {}: {}",
                                                         frameIndex, shown.error().message));
    }
    const RgbImage replayed = downscaleRgba(width, height, rgba, shown->width);
    if (replayed.width != shown->width || replayed.height != shown->height) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("the thumbnail of frame {} is {}x{}; the replayed frame "
                                     "({}x{}) downscales to {}x{}",
                                     frameIndex, shown->width, shown->height, width, height,
                                     replayed.width, replayed.height));
    }
    if (replayed.rgb == shown->rgb) {
        // The same drive values give the same XYZ through the model, and CIEDE2000 of a colour
        // with itself is 0: the statistics of every pixel at 0, without converting 2 x 64 000
        // pixels and measuring each (what a bit-exact replay's thumbnails always are).
        const auto pixels =
                static_cast<std::size_t>(shown->width) * static_cast<std::size_t>(shown->height);
        measured_.push_back({frameIndex, tickNs, summarise(std::vector<double>(pixels, 0.0))});
        return {};
    }
    auto de = deltaE00Image(toXyz(replayed), toXyz(*shown), model_.whiteXyz());
    if (!de) {
        return tl::unexpected(de.error());
    }
    measured_.push_back({frameIndex, tickNs, summarise(std::move(*de))});
    return {};
}

std::vector<ShownFrameDeltaE> ShownComparison::worst(std::size_t count) const
{
    std::vector<ShownFrameDeltaE> sorted = measured_;
    std::stable_sort(sorted.begin(), sorted.end(),
                     [](const auto& a, const auto& b) { return a.stats.p95 > b.stats.p95; });
    sorted.resize(std::min(count, sorted.size()));
    return sorted;
}

bool ShownComparison::within() const
{
    return std::all_of(measured_.begin(), measured_.end(),
                       [this](const auto& m) { return m.stats.p95 <= tolerance_; });
}

nlohmann::json ShownComparison::json() const
{
    nlohmann::json worstFrames = nlohmann::json::array();
    for (const auto& m : worst(5)) {
        worstFrames.push_back({{"frame", m.frame},
                               {"mean", m.stats.mean},
                               {"p95", m.stats.p95},
                               {"max", m.stats.max}});
    }
    return {{"thumbnails", thumbnails()},
            {"measured", measured_.size()},
            {"tolerance_p95_de00", tolerance_},
            {"result", within() ? "within_tolerance" : "beyond_tolerance"},
            {"worst", worstFrames}};
}

std::string olderRecordingLine(const std::string& file,
                               const std::string& madeBy,
                               int recordedProfile,
                               bool drawnByFlatRenderer)
{
    if (drawnByFlatRenderer) {
        return fmt::format("{}: made by {} and drawn by the flat renderer (render profile {}); "
                           "this build has no flat renderer and draws it with the booth pass "
                           "(profile {}); bit-exact replay needs that build: comparing with what "
                           "was shown instead",
                           printable(file, 512), printable(madeBy, 200), recordedProfile,
                           pipeline::render::kRenderProfile);
    }
    return fmt::format("{}: made by {} (render profile {}; this build renders profile {}); "
                       "bit-exact replay needs that build: comparing with what was shown instead",
                       printable(file, 512), printable(madeBy, 200), recordedProfile,
                       pipeline::render::kRenderProfile);
}

} // namespace replica::platform
