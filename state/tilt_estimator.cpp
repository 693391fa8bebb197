// Gravity -> tilt; the hold filter and the sliced refresh of the diffuse term's tilt.
#include <algorithm>
#include <cmath>
#include <vector>

#include <state/json_state.h>
#include <state/tilt_estimator.h>

#include <pipeline/scene/diffuse_schedule.h>
#include <pipeline/scene/stand.h>

namespace replica::state {

TiltEstimator::TiltEstimator(TiltEstimatorSetup setup) : setup_(setup), tilt_(setup.defaultTiltRad)
{
    setup_.cacheSlices = std::max(setup_.cacheSlices, 1);
}

void TiltEstimator::update(const hal::AccelSample* accel)
{
    if (accel == nullptr || accel->sequence == lastAccel_) {
        return;
    }
    lastAccel_ = accel->sequence;
    if (auto tilt = pipeline::scene::tiltFromGravity(accel->gravity)) {
        sense(*tilt);
    } else {
        ++rejected_;
        lastRefusal_ = pipeline::scene::whyNoTilt(accel->gravity);
    }
}

bool TiltEstimator::noisierThanDesign() const
{
    return noise_.sigmaRad() > kTiltNoiseFitRad;
}

double TiltEstimator::motionThresholdRad() const
{
    if (!noisierThanDesign()) {
        return kTiltMotionRad;
    }
    return std::max(kTiltMotionRad, kTiltMotionSigmas * noise_.sigmaRad() * std::sqrt(17.0 / 16.0));
}

double TiltEstimator::holdThresholdRad() const
{
    if (!noisierThanDesign()) {
        return kTiltHoldRad;
    }
    return std::max(kTiltHoldRad, kTiltHoldSigmas * noise_.sigmaRad() * std::sqrt(2.0 / 16.0));
}

double TiltEstimator::windowMean() const
{
    // The window fills from slot 0 after a start (count_ < size: slots 0..count_-1 hold it).
    double sum = 0.0;
    for (std::size_t i = 0; i < count_; ++i) {
        sum += window_[i];
    }
    return count_ > 0 ? sum / static_cast<double>(count_) : held_;
}

std::optional<double> TiltEstimator::trendSlope() const
{
    // The least-squares slope of the trend's tilts against their frame numbers (0, 1, ...).
    const std::size_t n = trendCount_;
    if (n < trend_.size()) {
        return std::nullopt; // too few tilts since the start for a slope its noise allows
    }
    const double meanX = static_cast<double>(n - 1) / 2.0;
    double meanY = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        meanY += trend_[i];
    }
    meanY /= static_cast<double>(n);
    double sxy = 0.0;
    double sxx = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        const double dx = static_cast<double>(i) - meanX;
        sxy += dx * (trend_[i] - meanY);
        sxx += dx * dx;
    }
    return sxy / sxx; // sxx > 0: n >= 2 distinct frame numbers
}

double TiltEstimator::refreshTarget() const
{
    const double ahead = trendSlope().value_or(0.0) * (3.0 * setup_.cacheSlices - 3.0) / 2.0;
    if (!(std::abs(ahead) > motionThresholdRad())) {
        return held_;
    }
    return held_ + std::clamp(ahead, -kDiffuseMaxLagRad, kDiffuseMaxLagRad);
}

int TiltEstimator::nodeDirection() const
{
    // Motion: the trend's travel over its own frames past the motion threshold (its noise is
    // 0.17 degrees there, so a still panel seldom prefetches, and then a node it keeps).
    const double travel = trendSlope().value_or(0.0) * static_cast<double>(kTiltTrend);
    if (!(std::abs(travel) > motionThresholdRad())) {
        return 0;
    }
    return travel > 0.0 ? 1 : -1;
}

void TiltEstimator::write(pipeline::scene::SceneState& state)
{
    // The held tilt: the mean of the last kTiltWindow frames' tilts, taken when the light changes
    // (the cache is drawn whole anyway) or when that mean has moved more than the hold threshold
    // from the held tilt; a tilt past the motion threshold from the mean starts the window again
    // (motion: the mean would lag it). Non-finite tilts are left out.
    if (std::isfinite(tilt_)) {
        if (trendCount_ == trend_.size()) {
            std::rotate(trend_.begin(), trend_.begin() + 1, trend_.end());
        }
        trend_[std::min(trendCount_, trend_.size() - 1)] = tilt_;
        trendCount_ = std::min(trendCount_ + 1, trend_.size());
        if (count_ > 0 && std::abs(tilt_ - windowMean()) > motionThresholdRad()) {
            count_ = 0;
            next_ = 0;
        }
        window_[next_] = tilt_;
        next_ = (next_ + 1) % window_.size();
        count_ = std::min(count_ + 1, window_.size());
    }
    if (count_ > 0) {
        const double mean = windowMean();
        // On a sensor noisier than the design's, the held tilt follows the window's mean while it
        // fills (after a start or motion): re-taken at its first samples, it kept their error (up
        // to a sample's noise) for as long as the full mean stayed within the hold of it, where
        // the full mean's error is a quarter of that (held error RMS 0.57 sigma; now 0.2-0.33).
        // The design's sensor keeps its schedule (its hold is about one sample's noise).
        const bool filling = count_ < window_.size() && noisierThanDesign();
        if (state.lightChanged || !heldValid_ || filling ||
            std::abs(mean - held_) > holdThresholdRad()) {
            held_ = mean;
            heldValid_ = true;
        }
    }
    // The specular term follows the sensed tilt (a highlight moves twice as fast as the panel); a
    // non-finite one (set from elsewhere: sense()) shows the held tilt.
    state.tiltRad = std::isfinite(tilt_) ? tilt_ : held_;
    state.heldTiltRad = held_;
    // The diffuse term's tilt: one frame of the cache's refresh schedule, and what the frame
    // draws of it (the band of a refresh under way; with tilt nodes, the two it interpolates).
    if (setup_.tiltNodesRad > 0.0) {
        auto step = pipeline::scene::nextDiffuseNodes(nodes_, held_, state.lightChanged,
                                                      setup_.cacheSlices, setup_.tiltNodesRad,
                                                      kDiffuseMaxLagRad, nodeDirection());
        nodes_ = std::move(step.nodes);
        state.diffuse = step.draw;
        return;
    }
    const auto last = diffuse_;
    diffuse_ = pipeline::scene::nextDiffuse(diffuse_, held_, state.lightChanged, setup_.cacheSlices,
                                            kDiffuseMaxLagRad, refreshTarget());
    state.diffuse =
            pipeline::scene::diffuseDraw(last, *diffuse_, state.lightChanged, setup_.cacheSlices);
}

nlohmann::json TiltEstimator::save() const
{
    return {{"last_accel", optionalJson(lastAccel_)},
            {"have_tilt", haveTilt_},
            {"rejected", rejected_},
            {"tilt_rad", tilt_},
            {"window", window_},
            {"next", next_},
            {"count", count_},
            {"held_rad", held_},
            {"held_valid", heldValid_},
            {"trend",
             std::vector<double>(trend_.begin(), trend_.begin() + static_cast<long>(trendCount_))},
            {"shown_rad", diffuse_ ? nlohmann::json(diffuse_->shownRad) : nlohmann::json()},
            {"refresh_rad", optionalJson(diffuse_ ? diffuse_->refreshRad : std::nullopt)},
            {"refresh_bands", diffuse_ ? diffuse_->refreshBands : 0},
            {"nodes", nodes_ ? nlohmann::json(nodes_->nodes) : nlohmann::json()},
            {"node_refresh_rad", optionalJson(nodes_ ? nodes_->refreshRad : std::nullopt)},
            {"node_refresh_bands", nodes_ ? nodes_->refreshBands : 0},
            {"noise", noise_.save()}};
}

Expected<void> TiltEstimator::restore(const nlohmann::json& j)
{
    try {
        lastAccel_ = optionalFromJson<std::uint32_t>(j.at("last_accel"));
        haveTilt_ = j.at("have_tilt").get<bool>();
        rejected_ = j.at("rejected").get<std::uint64_t>();
        tilt_ = finiteFromJson(j.at("tilt_rad"));
        const auto& w = j.at("window");
        if (!w.is_array() || w.size() != window_.size()) {
            throw std::out_of_range(fmt::format("the window needs {} tilts", window_.size()));
        }
        for (std::size_t i = 0; i < window_.size(); ++i) {
            window_[i] = finiteFromJson(w[i]);
        }
        next_ = j.at("next").get<std::size_t>();
        count_ = j.at("count").get<std::size_t>();
        if (next_ >= window_.size() || count_ > window_.size()) {
            throw std::out_of_range("window position out of range");
        }
        held_ = finiteFromJson(j.at("held_rad"));
        // Absent in states saved before the refresh aimed ahead: no trend yet.
        trendCount_ = 0;
        if (j.contains("trend")) {
            const auto& tr = j.at("trend");
            if (!tr.is_array() || tr.size() > trend_.size()) {
                throw std::out_of_range(
                        fmt::format("the trend holds at most {} tilts", trend_.size()));
            }
            for (const auto& v : tr) {
                trend_[trendCount_++] = finiteFromJson(v);
            }
        }
        heldValid_ = j.at("held_valid").get<bool>();
        const auto shown = j.at("shown_rad");
        const auto refresh = j.at("refresh_rad");
        pipeline::scene::DiffuseTilt d;
        d.refreshRad =
                refresh.is_null() ? std::nullopt : std::optional<double>(finiteFromJson(refresh));
        d.refreshBands = j.at("refresh_bands").get<int>();
        if (d.refreshBands < 0 || d.refreshBands >= setup_.cacheSlices ||
            (!d.refreshRad && d.refreshBands != 0) || (shown.is_null() && d.refreshRad)) {
            throw std::out_of_range(fmt::format("{} bands drawn of a refresh in {}", d.refreshBands,
                                                setup_.cacheSlices));
        }
        if (shown.is_null()) {
            diffuse_.reset();
        } else {
            d.shownRad = finiteFromJson(shown);
            diffuse_ = d;
        }
        // Absent in states saved before tilt nodes, and null before the first frame.
        nodes_.reset();
        if (j.contains("nodes") && !j.at("nodes").is_null()) {
            const auto& nodes = j.at("nodes");
            pipeline::scene::DiffuseNodes n;
            if (!nodes.is_array() || nodes.size() > pipeline::scene::kMaxDiffuseNodes) {
                throw std::out_of_range(fmt::format("the diffuse term has at most {} tilt nodes",
                                                    pipeline::scene::kMaxDiffuseNodes));
            }
            for (const auto& v : nodes) {
                n.nodes.push_back(finiteFromJson(v));
            }
            const auto nodeRefresh = j.at("node_refresh_rad");
            n.refreshRad = nodeRefresh.is_null()
                                   ? std::nullopt
                                   : std::optional<double>(finiteFromJson(nodeRefresh));
            n.refreshBands = j.at("node_refresh_bands").get<int>();
            if (n.refreshBands < 0 || n.refreshBands >= setup_.cacheSlices ||
                (!n.refreshRad && n.refreshBands != 0)) {
                throw std::out_of_range(fmt::format("{} bands drawn of a tilt node in {}",
                                                    n.refreshBands, setup_.cacheSlices));
            }
            nodes_ = std::move(n);
        }
        // Absent in states saved before the thresholds followed the noise: none measured yet.
        noise_ = TiltNoise{};
        if (j.contains("noise")) {
            if (auto r = noise_.restore(j.at("noise")); !r) {
                throw std::out_of_range(r.error().message);
            }
        }
    } catch (const std::exception& e) {
        return makeError(ErrorCode::InvalidArgument, fmt::format("tilt: {}", e.what()));
    }
    return {};
}

} // namespace replica::state
