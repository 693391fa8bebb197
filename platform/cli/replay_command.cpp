// 'replica replay': feeds a recording back through the replay HAL and renders the same frames.
#include <filesystem>
#include <optional>

#include <fmt/format.h>

#include <platform/appliance.h>
#include <platform/cli/commands.h>
#include <platform/cli/frame_compare.h>
#include <platform/cli/frame_outputs.h>
#include <platform/image/png_writer.h>
#include <platform/logging.h>
#include <platform/loop/frame_loop.h>

namespace replica::platform {
namespace {

struct ReplayOptions {
    std::string file;
    std::string digests;
    std::string check;
    std::string snapshot;
    std::string clock = "fast";
    std::string saveFrames;  // write every frame's XYZ here (reference frames for a golden)
    std::string reference;   // reference XYZ frames for --check (default: GOLDEN.frames/)
    std::string mismatchDir; // where --check writes the first differing frame
    std::string savePng;     // write every frame's display counts here (PNG)
    std::string output = "headless";
    KmsOptions kms;
};

std::filesystem::path
framePath(const std::filesystem::path& dir, long frame, const char* suffix = ".pfm")
{
    return dir / fmt::format("frame-{:06d}{}", frame, suffix);
}

// Writes the first differing frame, and, when its reference frame exists, the ΔE00 difference
// image and statistics. Returns the report lines.
Expected<void> reportMismatch(const ReplayOptions& o,
                              long frame,
                              const FloatImage& xyz,
                              const std::vector<std::uint8_t>& rgba,
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
    std::filesystem::path refDir = o.reference;
    if (refDir.empty()) {
        refDir = std::filesystem::path(o.check).replace_extension(".frames");
    }
    const auto refPath = framePath(refDir, frame);
    if (!std::filesystem::exists(refPath, ec)) {
        fmt::print("no reference frame {} (write reference frames with 'replica replay FILE "
                   "--save-frames DIR' and pass --reference DIR): no ΔE00 statistics\n",
                   refPath.string());
        return {};
    }
    auto ref = readPfm(refPath);
    if (!ref) {
        return tl::unexpected(ref.error());
    }
    auto de = deltaE00Image(xyz, *ref, white);
    if (!de) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: {}", refPath.string(), de.error().message));
    }
    const auto diffPath = framePath(dir, frame, "-diff.png");
    if (auto ok = writeDifferencePng(diffPath, xyz.width, xyz.height, *de); !ok) {
        return ok;
    }
    const auto st = summarise(*de);
    fmt::print("ΔE00 against {} over {} pixels: mean {:.3f}, median {:.3f}, p95 {:.3f}, max "
               "{:.3f}; {:.2f}% above 1, {:.2f}% above 2; difference image {}\n",
               refPath.string(), st.pixels, st.mean, st.median, st.p95, st.max,
               100.0 * st.fractionAbove1, 100.0 * st.fractionAbove2, diffPath.string());
    return {};
}

int replayMain(const ReplayOptions& o)
{
    auto log = logger("replica");
    auto recording = recordings::readRecording(o.file);
    if (!recording) {
        log->error("{}", recording.error().message);
        return kExitFailure;
    }
    auto config = RunConfig::fromJson(recording->session.configJson);
    if (!config) {
        log->error("{}: {}", o.file, config.error().message);
        return kExitFailure;
    }
    if (o.output != "headless" && o.output != "kms") {
        log->error("--output {}: expected 'headless' or 'kms'", o.output);
        return kExitUsage;
    }
    OutputChoice outputChoice;
    outputChoice.kind = o.output;
    outputChoice.kms = o.kms;
    if (o.output == "kms" && o.kms.mode.empty()) {
        // The recording's frame size is the mode to ask for; the preferred one if there is none
        // of that size (the frame is then centred or cropped).
        outputChoice.kms.mode = fmt::format("{}x{}", config->width, config->height);
        outputChoice.kms.modeOrPreferred = true;
    }
    auto appliance = buildAppliance(*config, outputChoice);
    if (!appliance) {
        log->error("{}", appliance.error().message);
        return kExitFailure;
    }
    Sources sources = makeReplaySources(*recording);
    const Pacing pacing = o.clock == "recorded" ? Pacing::Realtime
                          : o.clock == "step"   ? Pacing::Step
                                                : Pacing::Fast;
    log->info("replay {}: {} frames, {} spectra, {} poses, {} accel samples, {} lamp selector "
              "samples (recorded by {}); clock={}; renderer={} on {}; {}x{}",
              o.file, recording->frames.size(), recording->spectra.size(), recording->poses.size(),
              recording->accel.size(), recording->lampSelector.size(),
              recording->session.softwareVersion, o.clock, (*appliance)->renderer->description(),
              (*appliance)->output->glRenderer(), config->width, config->height);

    std::optional<std::vector<FrameDigest>> golden;
    if (!o.check.empty()) {
        auto g = readDigests(o.check);
        if (!g) {
            log->error("{}", g.error().message);
            return kExitFailure;
        }
        golden = std::move(*g);
    }
    for (const std::string& dir : {o.saveFrames, o.savePng}) {
        if (dir.empty()) {
            continue;
        }
        std::error_code ec;
        std::filesystem::create_directories(dir, ec);
        if (ec) {
            log->error("{}: cannot create directory: {}", dir, ec.message());
            return kExitFailure;
        }
    }
    FrameOutputs outputs(!o.digests.empty() || golden || !o.saveFrames.empty(),
                         !o.snapshot.empty());
    // Keep the first frame whose digest differs from the golden one, and save frames on request.
    std::optional<FloatImage> firstDiffXyz;
    std::vector<std::uint8_t> firstDiffRgba;
    std::optional<Error> saveError;
    std::size_t pngCount = 0;
    auto keep = outputs.callback();
    auto onFrame = [&](const recordings::FrameRecord& f, const pipeline::scene::SceneState& scene,
                       const pipeline::render::RenderedFrame& image) {
        keep(f, scene, image);
        const std::size_t i = outputs.digests().size() - 1;
        if (!o.saveFrames.empty() && !saveError) {
            if (auto ok = writePfm(framePath(o.saveFrames, static_cast<long>(i)),
                                   {image.width, image.height, image.xyz});
                !ok) {
                saveError = ok.error();
            }
        }
        if (!o.savePng.empty() && !saveError) {
            if (auto ok = writePng(framePath(o.savePng, static_cast<long>(pngCount++), ".png"),
                                   image.width, image.height, image.rgba);
                !ok) {
                saveError = ok.error();
            }
        }
        if (golden && !firstDiffXyz &&
            (i >= golden->size() || !((*golden)[i] == outputs.digests()[i]))) {
            firstDiffXyz = FloatImage{image.width, image.height, image.xyz};
            firstDiffRgba = image.rgba;
        }
    };
    auto readback = outputs.readback();
    if ((!o.savePng.empty() || (*appliance)->output->needsPixels()) &&
        readback == pipeline::render::Readback::None) {
        readback = pipeline::render::Readback::Display;
    }
    auto stats = runFrames(**appliance, sources, replayPlan(recording->frames), pacing, nullptr,
                           readback, onFrame);
    if (saveError) {
        log->error("{}", saveError->message);
        return kExitFailure;
    }
    if (!stats) {
        log->error("{}", stats.error().message);
        return kExitFailure;
    }
    if (auto ok = outputs.finish(o.digests, o.snapshot); !ok) {
        log->error("{}", ok.error().message);
        return kExitFailure;
    }
    if (!o.digests.empty()) {
        fmt::print("digests: {}\n", o.digests);
    }
    if (!o.saveFrames.empty()) {
        fmt::print("frames: {} XYZ frames in {}\n", outputs.digests().size(), o.saveFrames);
    }
    if (golden) {
        const long diff = firstDifference(*golden, outputs.digests());
        if (diff >= 0) {
            log->error("{}: frame {} differs from the golden digests in {} ({} golden frames, {} "
                       "replayed)",
                       o.file, diff, o.check, golden->size(), outputs.digests().size());
            if (firstDiffXyz) {
                const pipeline::colour::Xyz white = (*appliance)->displayWhiteXyz;
                if (auto ok = reportMismatch(o, diff, *firstDiffXyz, firstDiffRgba, white); !ok) {
                    log->error("{}", ok.error().message);
                }
            }
            return kExitFailure;
        }
        fmt::print("check: all {} frames match {}\n", golden->size(), o.check);
    }
    return stats->replayMismatches > 0 ? kExitLossy : kExitOk;
}

} // namespace

void registerReplayCommand(CLI::App& app, int& exitCode)
{
    auto opts = std::make_shared<ReplayOptions>();
    auto* cmd = app.add_subcommand(
            "replay",
            "render a recording again through the replay HAL; the same recording always gives the "
            "same frames, bit for bit");
    cmd->add_option("file", opts->file, "recording (.mcap) written by 'replica run --record'")
            ->required();
    cmd->add_option("--digests", opts->digests, "write one digest per frame to FILE (JSON)");
    cmd->add_option("--check", opts->check,
                    "compare the frame digests with GOLDEN (a digests file); on the first "
                    "difference write that frame (PNG and XYZ), its ΔE00 difference image against "
                    "the reference frame, print ΔE00 statistics, and exit 1");
    cmd->add_option("--snapshot", opts->snapshot, "write the last frame to FILE (PNG)");
    cmd->add_option("--save-frames", opts->saveFrames,
                    "write every frame's absolute XYZ to DIR/frame-NNNNNN.pfm (reference frames "
                    "for a golden)");
    cmd->add_option("--save-png", opts->savePng,
                    "write every frame's display counts to DIR/frame-NNNNNN.png (as the panel "
                    "shows them)");
    cmd->add_option("--output", opts->output,
                    "headless (no display) or kms (fullscreen: the recording's frame size as the "
                    "mode, or the preferred mode with the frame centred)")
            ->check(CLI::IsMember({"headless", "kms"}))
            ->capture_default_str();
    addKmsOptions(*cmd, opts->kms);
    cmd->add_option("--reference", opts->reference,
                    "reference XYZ frames for --check (default: GOLDEN with .frames instead of "
                    ".json, if it exists): on a mismatch, ΔE00 of the first differing frame");
    cmd->add_option("--mismatch-dir", opts->mismatchDir,
                    "where --check writes the first differing frame and the difference image "
                    "(default: OUT.mismatch beside --digests OUT, else ./replay-mismatch)");
    cmd->add_option("--clock", opts->clock,
                    "recorded: at the recorded pace; fast: as fast as possible; step: one frame "
                    "per line "
                    "on standard input")
            ->check(CLI::IsMember({"recorded", "fast", "step"}))
            ->capture_default_str();
    cmd->callback([opts, &exitCode] { exitCode = replayMain(*opts); });
}

} // namespace replica::platform
