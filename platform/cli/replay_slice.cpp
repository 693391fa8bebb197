// The slice of a recording 'replica replay' outputs (--from, --to).
#include <cmath>
#include <sstream>
#include <tuple>

#include <fmt/format.h>

#include <platform/cli/replay.h>
#include <platform/cli/wall_clock_time.h>

namespace replica::platform {

namespace {

// One of --from/--to: its session seconds, and the line saying where a wall-clock time landed.
Expected<std::optional<std::string>> resolveOne(const std::string& option,
                                                const std::string& text,
                                                const RecordingSpan& span,
                                                std::optional<double>& seconds,
                                                std::string& wallClock)
{
    if (text.empty()) {
        return std::optional<std::string>();
    }
    auto arg = parseTimeArg(text);
    if (!arg) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{} {}", option, arg.error().message));
    }
    if (arg->form == TimeArg::Form::SessionSeconds) {
        seconds = arg->seconds;
        return std::optional<std::string>();
    }
    auto at = resolveWallClock(option, text, *arg, span);
    if (!at) {
        return tl::unexpected(at.error());
    }
    seconds = at->sessionS;
    wallClock = isoLocal(at->unixNs);
    return fmt::format("{} {} is session second {} ({}, {})", option, text, at->sessionS, wallClock,
                       isoUtcMs(at->unixNs));
}

} // namespace

Expected<std::vector<std::string>> resolveSliceTimes(ReplayOptions& o,
                                                     const recordings::Recording& recording)
{
    const RecordingSpan span{recording.session.wallClockStartNs,
                             recording.frames.empty() ? 0 : recording.frames.back().tickNs};
    std::vector<std::string> lines;
    for (auto [option, text, seconds, wall] :
         {std::tuple{"--from", &o.fromArg, &o.fromS, &o.fromWallClock},
          std::tuple{"--to", &o.toArg, &o.toS, &o.toWallClock}}) {
        auto line = resolveOne(option, *text, span, *seconds, *wall);
        if (!line) {
            return tl::unexpected(line.error());
        }
        if (*line) {
            lines.push_back(**line);
        }
    }
    return lines;
}

Expected<ReplaySlice> makeSlice(const ReplayOptions& o, const recordings::Recording& recording)
{
    ReplaySlice slice;
    const auto toNs = [](double sec) { return static_cast<std::int64_t>(std::llround(sec * 1e9)); };
    // 1 us of slack: tick k is k * round(period), a few ns off k / rate after many frames.
    constexpr std::int64_t kSlackNs = 1000;
    slice.fromNs = o.fromS ? toNs(*o.fromS) - kSlackNs : INT64_MIN;
    slice.untilNs = o.toS ? toNs(*o.toS) + kSlackNs : INT64_MAX;
    if (slice.fromNs > slice.untilNs) {
        return makeError(
                ErrorCode::InvalidArgument,
                fmt::format("--from {} is after --to {}: nothing to replay", *o.fromS, *o.toS));
    }
    for (const auto& f : recording.frames) {
        if (f.tickNs > slice.untilNs) {
            break;
        }
        TickPlan t{f.frameIndex, f.tickNs, f};
        t.estimateOnly = !slice.contains(f.tickNs);
        slice.frames += t.estimateOnly ? 0 : 1;
        slice.plan.push_back(t);
    }
    if ((o.fromS || o.toS) && slice.frames == 0) {
        const double lastS = recording.frames.empty()
                                     ? 0.0
                                     : static_cast<double>(recording.frames.back().tickNs) * 1e-9;
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: no frame between {} s and {} s (the recording's frames "
                                     "span 0 to {:.3f} s of session time)",
                                     o.file, o.fromS.value_or(0.0),
                                     o.toS ? fmt::format("{}", *o.toS) : "the end", lastS));
    }
    return slice;
}

std::optional<std::vector<std::uint64_t>> parseFrameList(const std::string& s)
{
    std::vector<std::uint64_t> out;
    std::stringstream in(s);
    std::string item;
    while (std::getline(in, item, ',')) {
        std::size_t used = 0;
        try {
            out.push_back(std::stoull(item, &used));
        } catch (const std::exception&) {
            return std::nullopt;
        }
        if (used != item.size()) {
            return std::nullopt;
        }
    }
    if (out.empty()) {
        return std::nullopt;
    }
    return out;
}

} // namespace replica::platform
