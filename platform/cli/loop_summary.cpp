// What 'replica run' and 'replica replay' report of the frames a loop ran.
#include <string>
#include <utility>
#include <vector>

#include <platform/cli/loop_summary.h>
#include <platform/logging.h>
#include <recordings/device_kind.h>

namespace replica::platform {
namespace {

// The steady cadence's rates (platform/loop/cadence.h): each rate the loop drew frames at, as
// the summary writes it ("30"), and how many, fastest first.
std::vector<std::pair<std::string, std::uint64_t>> framesByRate(const LoopStats& stats,
                                                                double periodMs)
{
    std::vector<std::pair<std::string, std::uint64_t>> rates;
    for (std::size_t n = 1; n < stats.framesAtDivisor.size() && periodMs > 0.0; ++n) {
        if (stats.framesAtDivisor[n] > 0) {
            rates.emplace_back(fmt::format("{:.4g}", 1000.0 / periodMs / static_cast<double>(n)),
                               stats.framesAtDivisor[n]);
        }
    }
    return rates;
}

} // namespace

nlohmann::json loopSummaryJson(const LoopStats& stats, double periodMs)
{
    const FrameTimes& t = stats.frameTimes;
    nlohmann::json j;
    j["frames"] = stats.frames;
    j["late_frames"] = stats.lateFrames;
    j["skipped_ticks"] = stats.skippedTicks;
    // The steady cadence (platform/loop/cadence.h): the frames drawn at each rate it ran at.
    nlohmann::json atRate = nlohmann::json::object();
    for (const auto& [rate, frames] : framesByRate(stats, periodMs)) {
        atRate[rate] = frames;
    }
    j["cadence"] = {{"every_nth_tick", stats.divisor},
                    {"changes", stats.cadenceChanges},
                    {"ticks_paced", stats.pacedTicks},
                    {"frames_over_its_period", stats.framesOverCadence},
                    {"frames_at_hz", atRate}};
    j["dropped"] = nlohmann::json::object();
    for (const auto* kind : recordings::deviceKinds()) {
        const auto it = stats.dropped.find(kind->name());
        j["dropped"][kind->name()] = it != stats.dropped.end() ? it->second : 0;
    }
    j["refused"] = nlohmann::json::object();
    for (const auto& [kind, n] : stats.refused) {
        j["refused"][kind] = n;
    }
    j["frame_time_ms"] = {{"mean", t.meanMs()},
                          {"p50", t.percentileMs(0.50)},
                          {"p95", t.percentileMs(0.95)},
                          {"p99", t.percentileMs(0.99)},
                          {"max", t.maxMs()},
                          {"at_least_period", t.atLeast(periodMs)}};
    // Fractions of the surface's pixels (the black surround is below black by construction).
    j["out_of_gamut"] = {{"mean", stats.meanOutOfGamutFraction()},
                         {"max", stats.maxOutOfGamutFraction},
                         {"over_peak_mean", stats.meanOverPeakFraction()},
                         {"over_peak_max", stats.maxOverPeakFraction},
                         {"of", "surface pixels"}};
    return j;
}

nlohmann::json digestsJson(const std::string& file, DigestHash hash)
{
    return {{"file", file}, {"hash", digestHashName(hash)}};
}

void logLoopSummary(const LoopStats& stats, double periodMs, bool digests)
{
    auto log = logger("replica");
    // The kinds the loop polled (a kind it had no source for has no count).
    std::string dropped;
    for (const auto* kind : recordings::deviceKinds()) {
        const auto it = stats.dropped.find(kind->name());
        if (it != stats.dropped.end()) {
            dropped += fmt::format("{}{} {}", dropped.empty() ? "" : ", ",
                                   kind->names().displayName, it->second);
        }
    }
    log->info("{} frames; dropped samples: {}; late frames {}, skipped ticks {}; out of gamut: "
              "mean {:.4f}, max {:.4f} of the surface's pixels (above the panel's peak: mean "
              "{:.4f}, max {:.4f})",
              stats.frames, dropped.empty() ? std::string("none") : dropped, stats.lateFrames,
              stats.skippedTicks, stats.meanOutOfGamutFraction(), stats.maxOutOfGamutFraction,
              stats.meanOverPeakFraction(), stats.maxOverPeakFraction);
    if (!stats.refused.empty()) {
        std::string refused;
        for (const auto& [kind, n] : stats.refused) {
            refused += fmt::format("{}{} {}", refused.empty() ? "" : ", ", kind, n);
        }
        log->warn("samples the state stage did not use (each kept the last good value; the log "
                  "says why): {}",
                  refused);
    }
    if (stats.cadenceChanges > 0) {
        std::string rates;
        for (const auto& [rate, frames] : framesByRate(stats, periodMs)) {
            rates += fmt::format("{}{} at {} Hz", rates.empty() ? "" : ", ", frames, rate);
        }
        log->info("cadence: frames {}; {} ticks passed over for an even cadence, {} changes, {} "
                  "frames longer than the cadence's period (platform/loop/cadence.h)",
                  rates, stats.pacedTicks, stats.cadenceChanges, stats.framesOverCadence);
    }
    const FrameTimes& t = stats.frameTimes;
    // --digests reads every frame back as float XYZ and hashes it (XXH3-64, digest format 2; about
    // 1 ms for the 11.5 MB of a 960x600 frame, docs/performance.md) inside each frame's time; the
    // read-back of the XYZ frame costs more than the hash. Said so that the figure is not taken
    // for the appliance's.
    log->info("frame time: mean {:.1f} ms ({:.0f} frames/s), 50th percentile {:.1f}, 95th {:.1f}, "
              "99th {:.1f}, max {:.1f}; {} of {} frames took the whole {:.1f} ms period or more{}",
              t.meanMs(), t.meanMs() > 0.0 ? 1000.0 / t.meanMs() : 0.0, t.percentileMs(0.50),
              t.percentileMs(0.95), t.percentileMs(0.99), t.maxMs(), t.atLeast(periodMs), t.count(),
              periodMs,
              !digests ? ""
                       : " (including --digests: each frame read back as XYZ and hashed, which a "
                         "run without it does not do)");
}

} // namespace replica::platform
