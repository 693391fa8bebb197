// 'replica replay --check GOLDEN': the replayed frames' digests against a golden's, and ΔE00 of the
// differing frames against the golden's reference frames (--tolerance).
#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include <platform/cli/commands.h>
#include <platform/cli/replay.h>
#include <platform/image/png_writer.h>
#include <platform/image/xyz_frame.h>
#include <platform/logging.h>

namespace replica::platform {
namespace {

// The reference frame of `frame` in dir: .exr (committed goldens) or .pfm (local).
std::optional<std::filesystem::path> referenceFrame(const std::filesystem::path& dir, long frame)
{
    std::error_code ec;
    for (const char* ext : {".exr", ".pfm"}) {
        auto p = dir / fmt::format("frame-{:06d}{}", frame, ext);
        if (std::filesystem::exists(p, ec)) {
            return p;
        }
    }
    return std::nullopt;
}

// One measured frame as --json reports it (the worst adds its reference file).
nlohmann::json frameDeltaEJson(const FrameDeltaE& m)
{
    return {{"frame", m.frame},
            {"mean", m.stats.mean},
            {"p95", m.stats.p95},
            {"max", m.stats.max},
            {"max_at", {m.maxX, m.maxY}}};
}

// Writes the first differing frame, and, when its reference frame exists, the ΔE00 difference
// image and statistics.
Expected<void> reportMismatch(const ReplayOptions& o,
                              long frame,
                              const FloatImage& xyz,
                              const std::vector<std::uint8_t>& rgba,
                              const std::filesystem::path& refDir,
                              const pipeline::colour::Xyz& white)
{
    std::filesystem::path dir = o.mismatchDir;
    if (dir.empty()) {
        dir = o.digests.empty() ? std::filesystem::path("replay-mismatch")
                                : std::filesystem::path(o.digests).replace_extension(".mismatch");
    }
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) {
        return makeError(ErrorCode::Io, fmt::format("{}: cannot create directory: {}", dir.string(),
                                                    ec.message()));
    }
    if (auto ok = writePng(framePath(dir, frame, ".png"), xyz.width, xyz.height, rgba); !ok) {
        return ok;
    }
    if (auto ok = writePfm(framePath(dir, frame), xyz); !ok) {
        return ok;
    }
    fmt::print("first differing frame {}: replayed frame written to {} (XYZ {})\n", frame,
               framePath(dir, frame, ".png").string(), framePath(dir, frame).string());
    const auto found = referenceFrame(refDir, frame);
    if (!found) {
        fmt::print("no reference frame {} (write reference frames with 'replica replay FILE "
                   "--save-frames DIR' and pass --reference DIR): no ΔE00 statistics\n",
                   framePath(refDir, frame).string());
        return {};
    }
    auto ref = readXyzFrame(*found);
    if (!ref) {
        return tl::unexpected(ref.error());
    }
    auto de = deltaE00Image(xyz, *ref, white);
    if (!de) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: {}", found->string(), de.error().message));
    }
    const auto diffPath = framePath(dir, frame, "-diff.png");
    if (auto ok = writeDifferencePng(diffPath, xyz.width, xyz.height, *de); !ok) {
        return ok;
    }
    const auto st = summarise(*de);
    fmt::print("ΔE00 against {} over {} pixels: mean {:.3f}, median {:.3f}, p95 {:.3f}, max "
               "{:.3f}; {:.2f}% above 1, {:.2f}% above 2; difference image {}\n",
               found->string(), st.pixels, st.mean, st.median, st.p95, st.max,
               100.0 * st.fractionAbove1, 100.0 * st.fractionAbove2, diffPath.string());
    return {};
}

} // namespace

std::filesystem::path framePath(const std::filesystem::path& dir, long frame, const char* suffix)
{
    return dir / fmt::format("frame-{:06d}{}", frame, suffix);
}

Expected<void>
GoldenCheck::open(const ReplayOptions& o, const ReplaySlice& slice, pipeline::colour::Xyz white)
{
    white_ = white;
    refDir_ = o.reference;
    if (o.check.empty()) {
        return {};
    }
    auto g = readDigestFile(o.check);
    if (!g) {
        return tl::unexpected(g.error());
    }
    for (const auto& d : g->frames) {
        if (slice.contains(d.tickNs)) {
            byFrame_[d.frameIndex] = d;
        }
    }
    golden_ = std::move(*g);
    if (refDir_.empty()) {
        refDir_ = std::filesystem::path(o.check).replace_extension(".frames");
    }
    return {};
}

Expected<void> GoldenCheck::frame(long frameNo,
                                  const pipeline::render::RenderedFrame& image,
                                  const FrameDigest& digest)
{
    if (!golden_) {
        return {};
    }
    ++compared_;
    const auto g = byFrame_.find(static_cast<std::uint64_t>(frameNo));
    seen_ += g != byFrame_.end() ? 1 : 0;
    if (g != byFrame_.end() && g->second == digest) {
        return {};
    }
    ++differing_;
    if (!firstDiffXyz_) {
        firstDiff_ = frameNo;
        firstDiffXyz_ = FloatImage{image.width, image.height, image.xyz};
        firstDiffRgba_ = image.rgba;
    }
    // Every differing frame that has a reference frame: tolerance mode decides on them, and a
    // plain --check reports them.
    return measure(frameNo, image);
}

Expected<void> GoldenCheck::measure(long frameNo, const pipeline::render::RenderedFrame& image)
{
    const auto ref = referenceFrame(refDir_, frameNo);
    if (!ref) {
        return {};
    }
    auto r = readXyzFrame(*ref);
    if (!r) {
        return tl::unexpected(r.error());
    }
    auto de = deltaE00Image({image.width, image.height, image.xyz}, *r, white_);
    if (!de) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: {}", ref->string(), de.error().message));
    }
    FrameDeltaE m;
    m.frame = frameNo;
    m.reference = *ref;
    const auto at =
            static_cast<std::size_t>(std::max_element(de->begin(), de->end()) - de->begin());
    m.maxX = static_cast<int>(at % static_cast<std::size_t>(image.width));
    m.maxY = image.height - 1 - static_cast<int>(at / static_cast<std::size_t>(image.width));
    m.stats = summarise(std::move(*de));
    measured_.push_back(m);
    return {};
}

int GoldenCheck::finish(const ReplayOptions& o,
                        nlohmann::json& summary,
                        int code,
                        const std::function<void(const std::string&)>& say) const
{
    if (!golden_) {
        return code;
    }
    // Golden frames in the slice that were not replayed make the check fail too.
    const std::uint64_t missing = byFrame_.size() - seen_;
    const bool lengthDiffers = missing > 0;
    nlohmann::json check{{"golden", o.check},
                         {"hash", digestHashName(golden_->hash)},
                         {"frames_compared", compared_},
                         {"golden_frames", byFrame_.size()},
                         {"frames_differing", differing_},
                         {"golden_frames_not_replayed", missing}};
    if (differing_ == 0 && !lengthDiffers) {
        check["result"] = "match";
        say(fmt::format("check: all {} frames match {}", compared_, o.check));
    } else if (o.tolerance && !lengthDiffers && !measured_.empty()) {
        const auto worst = *std::max_element(
                measured_.begin(), measured_.end(),
                [](const auto& a, const auto& b) { return a.stats.max < b.stats.max; });
        const bool within = worst.stats.max <= *o.tolerance;
        check["result"] = within ? "within_tolerance" : "beyond_tolerance";
        check["tolerance_de00"] = *o.tolerance;
        check["reference_frames_measured"] = measured_.size();
        check["worst"] = frameDeltaEJson(worst);
        check["worst"]["reference"] = worst.reference.string();
        nlohmann::json frames = nlohmann::json::array();
        for (const auto& m : measured_) {
            frames.push_back(frameDeltaEJson(m));
        }
        check["measured"] = frames;
        const auto line = fmt::format(
                "check: {} of {} frames differ from {} bit for bit; on the {} of them with "
                "reference frames ΔE00 is at most {:.3f} (worst frame {}: mean {:.3f}, p95 "
                "{:.3f}, max {:.3f} at x {} y {}), {} the tolerance {:.3f} by {:.3f}",
                differing_, compared_, o.check, measured_.size(), worst.stats.max, worst.frame,
                worst.stats.mean, worst.stats.p95, worst.stats.max, worst.maxX, worst.maxY,
                within ? "within" : "BEYOND", *o.tolerance,
                std::abs(*o.tolerance - worst.stats.max));
        if (within) {
            say(line);
        } else {
            logger("replica")->error("{}", line);
            code = kExitFailure;
        }
    } else {
        reportBeyond(o, check, say);
        code = kExitFailure;
    }
    summary["check"] = check;
    return code;
}

void GoldenCheck::reportBeyond(const ReplayOptions& o,
                               nlohmann::json& check,
                               const std::function<void(const std::string&)>& say) const
{
    auto log = logger("replica");
    check["result"] = "differ";
    check["first_differing_frame"] = firstDiff_;
    log->error("{}: frame {} differs from the golden digests in {} ({} golden frames, {} "
               "replayed{})",
               o.file, firstDiff_, o.check, byFrame_.size(), compared_,
               o.tolerance ? "; no reference frame among the differing frames, so no "
                             "tolerance applies"
                           : "");
    if (firstDiffXyz_ && !o.json) {
        if (auto ok =
                    reportMismatch(o, firstDiff_, *firstDiffXyz_, firstDiffRgba_, refDir_, white_);
            !ok) {
            log->error("{}", ok.error().message);
        }
    }
    nlohmann::json frames = nlohmann::json::array();
    for (const auto& m : measured_) {
        frames.push_back(frameDeltaEJson(m));
        say(fmt::format("reference frame {}: ΔE00 mean {:.3f}, p95 {:.3f}, max {:.3f} at x {} y "
                        "{} ({})",
                        m.frame, m.stats.mean, m.stats.p95, m.stats.max, m.maxX, m.maxY,
                        m.reference.string()));
    }
    check["measured"] = frames;
}

} // namespace replica::platform
