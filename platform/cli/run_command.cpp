// 'replica run': the appliance's main job, the fixed-rate loop on the chosen sensors and output.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <map>
#include <numbers>
#include <optional>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <sys/stat.h>

#include <pipeline/base/data_dir.h>
#include <pipeline/spectral/representation_catalogue.h>
#include <platform/appliance.h>
#include <platform/cli/commands.h>
#include <platform/cli/frame_outputs.h>
#include <platform/cli/loop_summary.h>
#include <platform/cli/run_options.h>
#include <platform/cli/run_sources.h>
#include <platform/fault_injection.h>
#include <platform/live_sources.h>
#include <platform/logging.h>
#include <platform/loop/frame_loop.h>
#include <platform/loop/shown_recorder.h>
#include <platform/session_files.h>
#include <platform/site_config.h>
#include <platform/site_file.h>
#include <platform/systemd_notify.h>
#include <platform/version.h>
#include <recordings/recording.h>

namespace replica::platform {
namespace {

int runMain(const run_cli::RunOptions& given)
{
    auto log = logger("replica");
    // --frames 0 runs until SIGINT/SIGTERM (the kiosk), closing the recording properly. Routed to
    // the loop's stop flag before anything is opened: a signal during start-up (the recording is
    // created before the shading passes are built and warmed up) then ends the run cleanly at its
    // first frame instead of killing it (SIGTERM) or being lost (SIGINT is ignored in a
    // background job of a non-interactive shell until a handler is installed).
    installStopSignals();
    run_cli::RunOptions o = given;
    if (!o.sitePath.empty()) {
        // The site file's [sources] fill in what the command line leaves open.
        auto site = readSiteSources(o.sitePath);
        if (!site) {
            log->error("{}", site.error().message);
            return kExitUsage;
        }
        for (const auto& [kind, from] : *site) {
            if (o.sources[kind].empty()) {
                o.sources[kind] = from;
            }
        }
    }
    if (o.hal == "replay" && o.replayFile.empty()) {
        log->error("--hal replay needs --replay-file RECORDING (or run.replay_file in the site "
                   "file)");
        return kExitUsage;
    }
    if (o.hal == "replay" && o.replayFrom.empty()) {
        o.replayFrom = o.replayFile; // every device replays it unless told otherwise
    }
    if (o.hal == "live" && o.fast) {
        log->error("--fast needs the simulated sensors: live sensors run on the wall clock");
        return kExitUsage;
    }
    if (auto choice = run_cli::chooseDevices(o); !choice) { // usage errors before anything is built
        log->error("{}", choice.error().message);
        return kExitUsage;
    }
    if (o.output != "headless" && o.output != "kms") {
        log->error("--output {}: expected 'headless' (no display) or 'kms' (fullscreen on the "
                   "console, no display server)",
                   o.output);
        return kExitUsage;
    }
    if (!o.record.empty() && !o.force) {
        // Refused before the run starts (the writer refuses it again, race-free): an existing
        // recording is evidence, and a link must not redirect the write.
        struct stat st {
        };
        if (::lstat(o.record.c_str(), &st) == 0 &&
            (S_ISLNK(st.st_mode) || (S_ISREG(st.st_mode) && st.st_size > 0))) {
            log->error("--record {}: {}", o.record,
                       S_ISLNK(st.st_mode) ? "is a symbolic link; name the file itself"
                                           : "already exists; pass --force to overwrite it, or "
                                             "name a new file");
            return kExitUsage;
        }
    }
    if (o.output == "kms" && !o.size.empty()) {
        log->error("--size {}: on KMS the frame is the display mode's size; choose the mode with "
                   "--kms-mode WIDTHxHEIGHT",
                   o.size);
        return kExitUsage;
    }
    const auto size = run_cli::parseSize(o.size.empty() ? std::string("960x600") : o.size);
    if (!size) {
        log->error("--size {}: expected WIDTHxHEIGHT, e.g. 960x600, each side 1-{} and at most "
                   "{}:1",
                   o.size, kMaxFrameSide, kMaxFrameAspect);
        return kExitUsage;
    }
    RunConfig config;
    if (const int code = run_cli::runConfigFromOptions(o, *size, config); code != kExitOk) {
        return code;
    }

    OutputChoice outputChoice = o.outputChoice;
    outputChoice.kind = o.output;
    outputChoice.frameFromMode = true;
    // The EDID's physical size only when neither the command line nor a site file gives one.
    outputChoice.panelFromDisplay = o.panelSizeMm.empty() && !o.site;
    auto appliance = buildAppliance(config, outputChoice);
    if (!appliance) {
        log->error("{}", appliance.error().message);
        return kExitFailure;
    }
    // Live devices stamp samples on this clock; the loop's ticks start with it (within the few
    // milliseconds between here and the first tick, which only delays samples by that much).
    hal::SteadyClock liveClock;
    auto sources = run_cli::makeRunSources(o, **appliance, liveClock);
    if (!sources) {
        log->error("{}", sources.error().message);
        return kExitFailure; // usage errors were caught before anything was built
    }
    if (!o.faults.empty()) {
        auto plan = parseFaultPlan(o.faults);
        if (!plan) {
            log->error("{}", plan.error().message);
            return kExitUsage;
        }
        injectFaults(*sources, *plan);
        log->warn("injecting faults into the sensor samples: {}", o.faults);
    }
    log->info("{}; data {}", versionString(), dataDir().string());
    std::string devices;
    for (const auto& e : sources->entries()) {
        if (e.source) {
            const auto& info = e.source->info();
            devices += fmt::format("{}{}={} [{} {}]", devices.empty() ? "" : ", ", e.kind->name(),
                                   hal::toString(info.kind), info.model, info.serial);
        }
    }
    log->info("hal: {}; output={}; renderer={} on {}; {}x{} at {} Hz; display {}", devices,
              (*appliance)->output->name(), (*appliance)->renderer->description(),
              (*appliance)->output->glRenderer(), (*appliance)->config.width,
              (*appliance)->config.height, config.rateHz, (*appliance)->displayProfileId);

    std::unique_ptr<recordings::RecordingWriter> recorder;
    std::unique_ptr<SessionRecorder> sessions;
    bool recordFailed = false;
    const bool kioskRecording = o.kiosk && o.site && o.site->recordingEnabled && o.record.empty();
    if (!o.record.empty() || kioskRecording) {
        recordings::SessionInfo session;
        session.softwareVersion = versionString();
        // The configuration as built: the scene folder and digest, the display profile's digest.
        const RunConfig& built = (*appliance)->config;
        // The resolved configuration: the run configuration as built, the options the run
        // resolved from the command line and the site file, and the site file itself.
        auto resolved = nlohmann::json::parse(built.toJson());
        resolved["run_options"] = {{"hal", o.hal},
                                   {"replay_file", o.replayFile},
                                   {"output", o.output},
                                   {"kms_device", outputChoice.kms.device},
                                   {"kms_connector", outputChoice.kms.connector},
                                   {"kiosk", o.kiosk},
                                   {"tracker_port", o.live.trackerPort},
                                   {"tracker_bind", o.live.trackerBind},
                                   {"iio_root", o.live.iioRoot.string()},
                                   {"accel_name", o.live.accelName},
                                   {"accel_axes", o.live.accelAxes},
                                   {"lamp_gpio", o.live.lampGpio},
                                   {"spectrometer_serial", o.live.spectrometerSerial}};
        if (o.site) {
            resolved["site"] = nlohmann::json::parse(o.site->toJson());
        }
        session.configJson = resolved.dump();
        session.boothModel = built.booth;
        session.scene = built.scene;
        session.displayProfile = (*appliance)->displayProfileId;
        session.wallClockStartNs = std::chrono::duration_cast<std::chrono::nanoseconds>(
                                           std::chrono::system_clock::now().time_since_epoch())
                                           .count();
        for (const auto& e : sources->entries()) {
            if (e.source) {
                session.devices[e.kind->name()] = e.source->info();
            }
        }
        recordings::WriterOptions options;
        options.flushInterval = std::chrono::milliseconds(o.recordFlushMs);
        options.overwrite = o.force;
        // Called once from the writer thread; the loop keeps displaying without the recording.
        options.onError = [log](const Error& e) {
            log->error("{}; recording stopped, display continues", e.message);
        };
        if (kioskRecording) {
            const SiteConfig& site = *o.site;
            const std::filesystem::path dir = site.recordingDirectory;
            std::error_code ec;
            std::filesystem::create_directories(dir, ec);
            recoverUnfinished(dir);
            RotationPolicy policy;
            policy.rotateBytes = site.rotateBytes;
            policy.rotateAge = std::chrono::seconds(site.rotateSeconds);
            policy.keepBytes = site.keepBytes;
            // Each rotated file starts with the estimators' state ("state_at_start": the
            // classifier's hysteresis, the lamp selector's arbitration, the encoding, the held
            // eye and tilts), so that it replays alone, bit for bit, as the panel showed it.
            const state::SceneEstimator* estimator = (*appliance)->sceneEstimator.get();
            sessions = std::make_unique<SessionRecorder>(
                    dir, policy, [session, options, estimator](const std::filesystem::path& path) {
                        if (!estimator->started()) {
                            return recordings::RecordingWriter::create(path, session, options);
                        }
                        recordings::SessionInfo withState = session;
                        auto resolvedJson = nlohmann::json::parse(session.configJson);
                        resolvedJson[kStateAtStartKey] = estimator->save();
                        withState.configJson = resolvedJson.dump();
                        return recordings::RecordingWriter::create(path, withState, options);
                    });
            if (auto ok = sessions->open(); !ok) {
                log->error("{}; running without recording", ok.error().message);
                sessions.reset();
            }
        } else {
            auto w = recordings::RecordingWriter::create(o.record, session, options);
            if (!w) {
                // The appliance still displays; the run reports failure at the end.
                log->error("{}; running without recording", w.error().message);
                recordFailed = true;
            } else {
                recorder = std::move(*w);
            }
        }
    }

    // What the panel showed, into the recording (format 4 channels).
    std::unique_ptr<ShownRecorder> shown;
    if (recorder) {
        ShownOptions so;
        so.displayDigests = o.recordDigests;
        so.thumbnailHz = o.thumbnailHz;
        so.thumbnailWidth = o.thumbnailWidth;
        shown = std::make_unique<ShownRecorder>(*recorder, **appliance, so);
    }
    FrameOutputs outputs(!o.digests.empty(), !o.snapshot.empty());
    const TickSource ticks = o.frames == 0 ? endlessTicks(config.periodNs())
                                           : fixedRateTicks(config.periodNs(), o.frames);
    // Scan-out needs the display pixels of every frame, digests or not.
    auto readback = outputs.readback();
    if ((*appliance)->output->needsPixels() && readback == pipeline::render::Readback::None) {
        readback = pipeline::render::Readback::Display;
    }
    if (shown) {
        readback = std::max(readback, shown->readback());
    }
    auto keep = outputs.callback();
    const FrameCallback onFrame = [&](const recordings::FrameRecord& f,
                                      const pipeline::scene::SceneState& state,
                                      const pipeline::render::RenderedFrame& image) {
        keep(f, state, image);
        if (shown) {
            shown->onFrame(f, state, image);
        }
    };
    SystemdNotifier notifier;
    LoopOptions loopOptions;
    loopOptions.skipLateTicks = true;
    loopOptions.periodNs = config.periodNs();
    loopOptions.afterFrame = [&notifier](const LoopStats& s) {
        notifier.frameShown(s.frames, s.skippedTicks);
    };
    if (sessions) {
        loopOptions.nextRecorder = [&sessions](recordings::RecordingWriter*) {
            return sessions->afterFrame();
        };
    }
    const auto wallStart = std::chrono::steady_clock::now();
    auto stats = runFrames(**appliance, *sources, ticks, o.fast ? Pacing::Fast : Pacing::Realtime,
                           sessions ? sessions->current() : recorder.get(), readback, onFrame,
                           loopOptions);
    const double wallS =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - wallStart).count();
    notifier.stopping();
    if (shown) {
        shown->finish(); // the last thumbnail and the log tap, before the writer closes
    }
    if (!stats) {
        log->error("{}", stats.error().message);
        return kExitFailure;
    }
    int code = recordFailed ? kExitFailure : kExitOk;
    if (sessions) {
        if (auto closed = sessions->close(); !closed) {
            log->warn("session {} is incomplete; the next start recovers it",
                      sessions->currentPath().string());
            code = kExitFailure;
        } else {
            fmt::print("recording: {} ({} rotations)\n", sessions->currentPath().string(),
                       sessions->rotations());
        }
    }
    nlohmann::json summary{{"command", "run"}, {"wall_s", wallS}};
    if (recorder) {
        if (auto closed = recorder->close(); !closed) {
            // Already logged by onError when it happened; say where the run stands.
            log->warn("recording {} is incomplete; 'replica recover' rebuilds what was written",
                      o.record);
            code = kExitFailure;
        } else if (!o.json) {
            fmt::print("recording: {}\n", o.record);
        }
        const auto ws = recorder->stats();
        summary["recording"] = {{"file", o.record},      {"complete", code == kExitOk},
                                {"bytes", ws.bytes},     {"messages", ws.messages},
                                {"dropped", ws.dropped}, {"rejected_nonfinite", ws.rejected},
                                {"chunks", ws.chunks}};
    }
    if (shown) {
        const auto ss = shown->stats();
        const auto n = static_cast<double>(std::max<std::uint64_t>(ss.thumbnails, 1));
        const auto d = static_cast<double>(std::max<std::uint64_t>(ss.digests, 1));
        summary["shown"] = {{"display_digests", ss.digests},
                            {"digest_ms_mean", ss.digestMsTotal / d},
                            {"thumbnails", ss.thumbnails},
                            {"thumbnail_bytes", ss.thumbnailBytes},
                            {"thumbnails_skipped", ss.thumbnailsSkipped},
                            {"thumbnail_copy_ms_mean", ss.copyMsTotal / n},
                            {"thumbnail_encode_ms_mean", ss.encodeMsTotal / n},
                            {"light_changes", ss.lightChanges},
                            {"poses", ss.poses}};
        log->info("recorded what was shown: {} display digests ({:.3f} ms each in the frame), {} "
                  "thumbnails ({} bytes; {:.3f} ms copy in the frame, {:.2f} ms encode off it), {} "
                  "light decisions, {} poses",
                  ss.digests, ss.digestMsTotal / d, ss.thumbnails, ss.thumbnailBytes,
                  ss.copyMsTotal / n, ss.encodeMsTotal / n, ss.lightChanges, ss.poses);
    }
    if (auto ok = outputs.finish(o.digests, o.snapshot); !ok) {
        log->error("{}", ok.error().message);
        return kExitFailure;
    }
    if (!o.digests.empty()) {
        summary["digests"] = digestsJson(o.digests, kDigestHash);
        if (!o.json) {
            fmt::print("digests: {}\n", o.digests);
        }
    }
    if (!o.snapshot.empty()) {
        summary["snapshot"] = o.snapshot;
        if (!o.json) {
            fmt::print("snapshot: {}\n", o.snapshot);
        }
    }
    if (const auto* selector = sources->get(recordings::lampSelectorKind())) {
        log->info("lamp selector {} [{} {}]: overruled by the spectrometer {} times",
                  hal::toString(selector->info().kind), selector->info().model,
                  selector->info().serial, (*appliance)->sceneEstimator->lampArbiter().overruled());
    }
    const double periodMs = 1000.0 / o.rateHz;
    logLoopSummary(*stats, periodMs, !o.digests.empty());
    summary.update(loopSummaryJson(*stats, periodMs));
    summary["exit_code"] = code;
    if (o.json) {
        fmt::print("{}\n", summary.dump(2));
    }
    return code;
}

} // namespace

void registerRunCommand(CLI::App& app, int& exitCode)
{
    auto opts = std::make_shared<run_cli::RunOptions>();
    auto* cmd =
            app.add_subcommand("run", "run the appliance: sensors -> scene -> render -> output at "
                                      "a fixed rate");
    run_cli::addRunOptions(*cmd, *opts);
    cmd->callback([opts, cmd, &exitCode] {
        run_cli::RunOptions o = *opts;
        std::string file = o.config;
        if (file.empty() && o.kiosk) {
            file = defaultSiteConfigPath().string();
            std::error_code ec;
            if (!std::filesystem::exists(file, ec)) {
                logger("replica")->error("--kiosk: no site file at {}; install the package (it "
                                         "ships one) or pass --config FILE",
                                         file);
                exitCode = run_cli::kExitConfig;
                return;
            }
        }
        if (!file.empty()) {
            auto site = loadSiteConfig(file);
            if (!site) {
                logger("replica")->error("{}", site.error().message);
                exitCode = run_cli::kExitConfig;
                return;
            }
            if (!site->problems.empty()) {
                for (const auto& p : site->problems) {
                    logger("replica")->error("{}", formatProblem(file, p));
                }
                logger("replica")->error("{}: {} problems; 'replica config check {}' lists them",
                                         file, site->problems.size(), file);
                exitCode = run_cli::kExitConfig;
                return;
            }
            o.site = site->config;
            run_cli::applySite(*o.site, o, *cmd);
            // The site's log levels, unless the command line or $REPLICA_LOG set them.
            const auto* parent = cmd->get_parent();
            if (parent != nullptr && parent->get_option("--log-level")->count() == 0 &&
                std::getenv("REPLICA_LOG") == nullptr) {
                setupLogging(o.site->logLevel, true);
            }
        }
        if (o.kiosk && cmd->get_option("--frames")->count() == 0) {
            o.frames = 0;
        }
        exitCode = runMain(o);
    });
}

} // namespace replica::platform
