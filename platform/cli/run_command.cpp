// 'replica run': the appliance's main job, the fixed-rate loop on the chosen sensors and output.
#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <map>
#include <mutex>
#include <numbers>
#include <optional>
#include <thread>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <sys/stat.h>

#include <pipeline/base/data_dir.h>
#include <pipeline/display/icc_profile.h>
#include <pipeline/spectral/representation_catalogue.h>
#include <platform/appliance.h>
#include <platform/cli/commands.h>
#include <platform/cli/frame_outputs.h>
#include <platform/cli/loop_summary.h>
#include <platform/cli/run_options.h>
#include <platform/cli/run_resolve.h>
#include <platform/cli/run_sources.h>
#include <platform/fault_injection.h>
#include <platform/image/png_writer.h>
#include <platform/live_sources.h>
#include <platform/logging.h>
#include <platform/loop/error_probe.h>
#include <platform/loop/frame_loop.h>
#include <platform/loop/shown_recorder.h>
#include <platform/output/pass_warm_up.h>
#include <platform/output/service_screen.h>
#include <platform/session_files.h>
#include <platform/site_config.h>
#include <platform/site_file.h>
#include <platform/systemd_notify.h>
#include <platform/version.h>
#include <recordings/recording.h>

namespace replica::platform {
namespace {

void logStart(const Appliance& appliance, const Sources& sources)
{
    auto log = logger("replica");
    log->info("{}; data {}", versionString(), dataDir().string());
    std::string devices;
    for (const auto& e : sources.entries()) {
        if (e.source) {
            const auto& info = e.source->info();
            devices += fmt::format("{}{}={} [{} {}]", devices.empty() ? "" : ", ", e.kind->name(),
                                   hal::toString(info.kind), info.model, info.serial);
        }
    }
    log->info("hal: {}; output={}; renderer={} on {}; {}x{} at {} Hz; display {}", devices,
              appliance.output->name(), appliance.renderer->description(),
              appliance.output->glRenderer(), appliance.config.width, appliance.config.height,
              appliance.config.rateHz, appliance.displayProfileId);
    log->info("booth {} ({}, digest {}; lamps {}); light {}{}", appliance.config.booth,
              resolveSceneDir(appliance.config.boothDir).string(), appliance.config.boothDigest,
              appliance.booth.names(), appliance.config.light,
              appliance.config.light == kLightDirect
                      ? fmt::format(" (direct-sensor mode: the sensed spectrum at {} cd/m^2 per "
                                    "unit of its Y)",
                                    appliance.config.directCdM2PerY)
                      : std::string());
}

// The session as recorded in each file: the configuration as built (the scene folder and digest,
// the display profile's digest), the options the run resolved from the command line and the site
// file, the site file itself, and the devices.
recordings::SessionInfo sessionInfo(const run_cli::RunOptions& o,
                                    const Appliance& appliance,
                                    const OutputChoice& outputChoice,
                                    const Sources& sources)
{
    recordings::SessionInfo session;
    session.softwareVersion = versionString();
    const RunConfig& built = appliance.config;
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
    session.displayProfile = appliance.displayProfileId;
    session.wallClockStartNs = std::chrono::duration_cast<std::chrono::nanoseconds>(
                                       std::chrono::system_clock::now().time_since_epoch())
                                       .count();
    for (const auto& e : sources.entries()) {
        if (e.source) {
            session.devices[e.kind] = e.source->info();
        }
    }
    return session;
}

// Where the run records: one --record file, or the kiosk's session files (rotated, each starting
// with the estimators' state). Either way ShownRecorder adds what the panel showed, so that every
// file, each rotated one included, holds the same channels.
struct RunRecording {
    std::unique_ptr<recordings::RecordingWriter> file;
    std::unique_ptr<SessionRecorder> sessions;
    std::unique_ptr<ShownRecorder> shown;
    std::unique_ptr<ErrorProbe> probe; // with or without a recording (the summary reports it)
    bool failed = false; // --record could not be opened: the run reports failure at the end

    recordings::RecordingWriter* writer() const
    {
        return sessions ? sessions->current() : file.get();
    }
};

std::unique_ptr<SessionRecorder> openSessions(const SiteConfig& site,
                                              const recordings::SessionInfo& session,
                                              const recordings::WriterOptions& options,
                                              const state::SceneEstimator* estimator)
{
    const std::filesystem::path dir = site.recordingDirectory;
    RotationPolicy policy;
    policy.rotateBytes = site.rotateBytes;
    policy.rotateAge = std::chrono::seconds(site.rotateSeconds);
    policy.keepBytes = site.keepBytes;
    // Each rotated file starts with the estimators' state ("state_at_start": the classifier's
    // hysteresis, the lamp selector's arbitration, the encoding, the held eye and tilts), so
    // that it replays alone, bit for bit, as the panel showed it.
    auto sessions = std::make_unique<SessionRecorder>(
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
        logger("replica")->error("{}; running without recording", ok.error().message);
        return nullptr;
    }
    return sessions;
}

RunRecording openRecording(const run_cli::RunOptions& o,
                           const Appliance& appliance,
                           const OutputChoice& outputChoice,
                           const Sources& sources)
{
    auto log = logger("replica");
    RunRecording rec;
    const bool kioskRecording = o.kiosk && o.site && o.site->recordingEnabled && o.record.empty();
    if (o.record.empty() && !kioskRecording) {
        return rec;
    }
    const auto session = sessionInfo(o, appliance, outputChoice, sources);
    recordings::WriterOptions options;
    options.flushInterval = std::chrono::milliseconds(o.recordFlushMs);
    options.overwrite = o.force;
    // Called once from the writer thread; the loop keeps displaying without the recording.
    options.onError = [log](const Error& e) {
        log->error("{}; recording stopped, display continues", e.message);
    };
    if (kioskRecording) {
        rec.sessions = openSessions(*o.site, session, options, appliance.sceneEstimator.get());
    } else if (auto w = recordings::RecordingWriter::create(o.record, session, options); !w) {
        // The appliance still displays; the run reports failure at the end.
        log->error("{}; running without recording", w.error().message);
        rec.failed = true;
    } else {
        rec.file = std::move(*w);
    }
    if (rec.writer() != nullptr) {
        ShownOptions so;
        so.displayDigests = o.recordDigests;
        so.thumbnailHz = o.thumbnailHz;
        so.thumbnailWidth = o.thumbnailWidth;
        rec.shown = std::make_unique<ShownRecorder>(rec.writer(), appliance, so);
    }
    return rec;
}

// Closes the recording; returns the run's exit code given the loop's ('code') and adds the
// recording's figures to the summary.
int closeRecording(RunRecording& rec, const run_cli::RunOptions& o, nlohmann::json& summary)
{
    auto log = logger("replica");
    int code = rec.failed ? kExitFailure : kExitOk;
    if (rec.sessions) {
        if (auto closed = rec.sessions->close(); !closed) {
            log->warn("session {} is incomplete; the next start recovers it",
                      rec.sessions->currentPath().string());
            code = kExitFailure;
        } else if (!o.json) {
            fmt::print("recording: {} ({} rotations)\n", rec.sessions->currentPath().string(),
                       rec.sessions->rotations());
        }
        // With --json standard output is the summary alone: the session file is in it.
        summary["sessions"] = {{"file", rec.sessions->currentPath().string()},
                               {"rotations", rec.sessions->rotations()},
                               {"complete", code == kExitOk}};
    }
    if (rec.file) {
        if (auto closed = rec.file->close(); !closed) {
            // Already logged by onError when it happened; say where the run stands.
            log->warn("recording {} is incomplete; 'replica recover' rebuilds what was written",
                      o.record);
            code = kExitFailure;
        } else if (!o.json) {
            fmt::print("recording: {}\n", o.record);
        }
        const auto ws = rec.file->stats();
        summary["recording"] = {{"file", o.record},      {"complete", code == kExitOk},
                                {"bytes", ws.bytes},     {"messages", ws.messages},
                                {"dropped", ws.dropped}, {"rejected_nonfinite", ws.rejected},
                                {"chunks", ws.chunks}};
    }
    if (rec.shown) {
        const auto ss = rec.shown->stats();
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
    return code;
}

// The loop, from the first tick to the stop (or the last frame), into the recording.
Expected<LoopStats> runLoop(const run_cli::RunOptions& o,
                            Appliance& appliance,
                            Sources& sources,
                            RunRecording& rec,
                            FrameOutputs& outputs,
                            double& wallS)
{
    const auto periodNs = appliance.config.periodNs();
    const TickSource ticks =
            o.frames == 0 ? endlessTicks(periodNs) : fixedRateTicks(periodNs, o.frames);
    // Scan-out needs the display pixels of every frame, digests or not.
    auto readback = outputs.readback();
    if (appliance.output->needsPixels() && readback == pipeline::render::Readback::None) {
        readback = pipeline::render::Readback::Display;
    }
    if (rec.shown) {
        readback = std::max(readback, rec.shown->readback());
    }
    const FrameCallback onFrame = [&](const recordings::FrameRecord& f,
                                      const pipeline::scene::SceneState& state,
                                      const pipeline::render::RenderedFrame& image) {
        outputs.add(f, image);
        if (rec.shown) {
            rec.shown->onFrame(f, state, image);
        }
        if (rec.probe) {
            rec.probe->onFrame(f, state); // after the frame was presented, before the next
        }
    };
    SystemdNotifier notifier;
    // The other lamps' shading passes, compiled after the first frame
    // (platform/output/pass_warm_up.h).
    std::optional<PassWarmUp> warmUp;
    if (appliance.config.warmUp && appliance.config.warmUpAfterFirstFrame && appliance.boothScene) {
        warmUp.emplace(appliance.boothScene, appliance.config.width, appliance.config.height);
    }
    LoopOptions loopOptions;
    loopOptions.skipLateTicks = true;
    loopOptions.periodNs = periodNs;
    loopOptions.maxDivisor = CadenceGovernor::divisorLimit(o.rateHz, o.minRateHz);
    loopOptions.afterFrame = [&notifier, &warmUp](const LoopStats& s) {
        notifier.frameShown(s.frames, s.skippedTicks, s.divisor);
        if (warmUp) {
            warmUp->afterFrame(s.frames);
        }
    };
    if (rec.sessions) {
        loopOptions.nextRecorder = [&rec](recordings::RecordingWriter*) {
            auto* next = rec.sessions->afterFrame();
            if (rec.shown) {
                rec.shown->setWriter(next); // the next file holds what was shown too
            }
            if (rec.probe) {
                rec.probe->setWriter(next);
            }
            return next;
        };
    }
    const auto wallStart = std::chrono::steady_clock::now();
    auto stats = runFrames(appliance, sources, ticks, o.fast ? Pacing::Fast : Pacing::Realtime,
                           rec.writer(), readback, onFrame, loopOptions);
    wallS = std::chrono::duration<double>(std::chrono::steady_clock::now() - wallStart).count();
    if (warmUp) {
        warmUp->finish();
    }
    notifier.stopping();
    if (rec.shown) {
        rec.shown->finish(); // the last thumbnail and the log tap, before the writer closes
    }
    if (rec.probe) {
        rec.probe->finish(); // the probe in hand written, before the writer closes
    }
    return stats;
}

// The frame outputs (--digests, --snapshot) written, the summary's last lines printed.
int finishRun(const run_cli::RunOptions& o,
              const Appliance& appliance,
              const Sources& sources,
              FrameOutputs& outputs,
              const LoopStats& stats,
              const ErrorProbe* probe,
              nlohmann::json& summary,
              int code)
{
    auto log = logger("replica");
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
    if (const auto* selector = sources.get(recordings::lampSelectorKind())) {
        log->info("lamp selector {} [{} {}]: overruled by the spectrometer {} times",
                  hal::toString(selector->info().kind), selector->info().model,
                  selector->info().serial, appliance.sceneEstimator->lampArbiter().overruled());
    }
    const double periodMs = 1000.0 / o.rateHz;
    logLoopSummary(stats, periodMs, !o.digests.empty());
    summary.update(loopSummaryJson(stats, periodMs));
    if (probe != nullptr) {
        const double wallS = summary.value("wall_s", 0.0);
        logSpeedAndError(probe->stats(), probe->options(), stats.frameTimes.atLeast(periodMs),
                         stats.frames, wallS);
        summary["error_probe"] = errorProbeJson(probe->stats(), probe->options(), wallS);
    }
    summary["exit_code"] = code;
    if (o.json) {
        fmt::print("{}\n", summary.dump(2));
    }
    return code;
}

// Start-up (planning a scene that has no plan, the warm-up, recovering the sessions a crash left)
// runs before any recording is open: a stop signal then ends the process within 50 ms instead of
// waiting for it (systemd would kill it after TimeoutStopSec). Nothing is lost: a session being
// recovered is renamed over only once complete, and the plan cache and the folder's lock are
// written atomically or released by the kernel. From the loop on, stops end at a frame boundary.
class StartupStop
{
public:
    StartupStop() : thread_([this] { watch(); }) {}
    ~StartupStop()
    {
        {
            std::lock_guard lock(mutex_);
            done_ = true;
        }
        wake_.notify_one();
        thread_.join();
    }
    StartupStop(const StartupStop&) = delete;
    StartupStop& operator=(const StartupStop&) = delete;

private:
    void watch()
    {
        std::unique_lock lock(mutex_);
        while (!done_) {
            if (stopRequested()) {
                logger("replica")->info("stop requested during start-up: exiting before the first "
                                        "frame (no recording was open yet)");
                std::fflush(stdout);
                std::_Exit(kExitOk);
            }
            wake_.wait_for(lock, std::chrono::milliseconds(50));
        }
    }

    std::mutex mutex_;
    std::condition_variable wake_;
    bool done_ = false;
    std::thread thread_;
};

// The kiosk's answer to a configuration error: a service screen on the panel instead of black,
// through the output the options name (headless too: --snapshot writes it), saying what failed,
// where, and the command that checks it. An endless run holds it until stopped (a process that
// exits leaves a KMS panel black), telling systemd it is up so that the unit neither restarts it
// nor times it out; then, like a counted run at once, it exits 78, which the unit does not
// restart on.
int showServiceScreen(const run_cli::Refusal& r, const run_cli::RunOptions& given)
{
    auto log = logger("replica");
    auto output = r.output.kind == "kms" ? createKmsOutput(r.output.kms) : createHeadlessOutput();
    if (!output) {
        log->error("service screen: {}", output.error().message);
        return r.code;
    }
    auto size = run_cli::parseSize(r.size);
    if (const auto display = (*output)->display(); display) {
        size = std::make_pair(display->width, display->height);
    }
    const auto [width, height] = size.value_or(std::make_pair(960, 600));
    std::vector<std::string> lines = r.lines;
    lines.push_back("");
    lines.push_back("Check it:  replica config check " + r.siteFile);
    lines.push_back("Then:      systemctl restart replica");
    const auto image = renderServiceScreen(
            width, height, "Replica cannot start: the site file has a problem", lines);
    if (auto shown = presentServiceScreen(**output, image); !shown) {
        log->error("service screen: {}", shown.error().message);
    }
    if (!given.snapshot.empty()) {
        if (auto ok = writePng(given.snapshot, image.width, image.height, image.rgba); !ok) {
            log->error("{}", ok.error().message);
        }
    }
    log->error("the service screen shows the problem; 'replica config check {}' lists it",
               r.siteFile);
    if (r.endless) {
        SystemdNotifier notifier; // READY=1 (the screen is up), then the watchdog's pings
        for (std::uint64_t n = 0; !stopRequested(); ++n) {
            notifier.frameShown(n, 0);
            std::this_thread::sleep_for(std::chrono::milliseconds(100));
        }
        notifier.stopping();
    }
    return r.code;
}

int runMain(const run_cli::RunOptions& given)
{
    auto log = logger("replica");
    // --frames 0 runs until SIGINT/SIGTERM (the kiosk), closing the recording properly. Routed to
    // the stop flag before anything is opened (SIGINT is ignored in a background job of a
    // non-interactive shell until a handler is installed): during start-up StartupStop ends the
    // process at once, from the first frame on the loop ends at a frame boundary.
    installStopSignals();
    // What 'replica config check' resolves too: a site file it accepts starts here.
    auto plan = run_cli::resolveRun(given);
    if (!plan) {
        for (const auto& line : plan.error().lines) {
            log->error("{}", line);
        }
        if (given.kiosk && plan.error().code == run_cli::kExitConfig) {
            return showServiceScreen(plan.error(), given);
        }
        return plan.error().code;
    }
    const run_cli::RunOptions& o = plan->options;
    if (o.site && !o.logLevelGiven) {
        setupLogging(o.site->logLevel, true); // the site's log levels (checked by resolveRun)
    }
    // The sessions folder is this kiosk's alone: a second kiosk on it is refused here, in one
    // line naming the first one's pid, before it builds anything.
    std::optional<SessionFolderLock> folderLock;
    const bool kioskRecording = o.kiosk && o.site && o.site->recordingEnabled && o.record.empty();
    if (kioskRecording) {
        auto lock = SessionFolderLock::acquire(o.site->recordingDirectory);
        if (!lock && lock.error().code == ErrorCode::InvalidArgument) {
            log->error("{}", lock.error().message);
            return kExitFailure;
        }
        if (!lock) {
            log->warn("{}", lock.error().message); // recording then says why it cannot start
        } else {
            folderLock.emplace(std::move(*lock));
        }
    }
    auto startup = std::make_unique<StartupStop>();
    if (folderLock) {
        recoverUnfinished(o.site->recordingDirectory);
    }
    auto appliance = buildAppliance(plan->config, plan->output);
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
        auto faults = parseFaultPlan(o.faults);
        if (!faults) {
            log->error("{}", faults.error().message);
            return kExitUsage;
        }
        injectFaults(*sources, *faults);
        log->warn("injecting faults into the sensor samples: {}", o.faults);
    }
    startup.reset(); // from here a stop ends the loop at a frame, the recording closed
    logStart(**appliance, *sources);
    RunRecording rec = openRecording(o, **appliance, plan->output, *sources);
    ErrorProbeOptions probeOptions;
    probeOptions.periodS = o.errorProbeS;
    rec.probe = ErrorProbe::create(**appliance, probeOptions, rec.writer());
    FrameOutputs outputs(!o.digests.empty(), !o.snapshot.empty());
    if (!o.snapshot.empty()) {
        // The snapshot says the panel's colour space, and its time where a recording gives one.
        auto icc = pipeline::display::iccProfileBytes((*appliance)->displayModel);
        outputs.tagSnapshot(icc ? std::move(*icc) : std::vector<std::uint8_t>{},
                            (*appliance)->displayModel.name,
                            rec.writer() != nullptr ? rec.writer()->wallClockStartNs() : 0);
    }
    double wallS = 0.0;
    auto stats = runLoop(o, **appliance, *sources, rec, outputs, wallS);
    if (!stats) {
        log->error("{}", stats.error().message);
        return kExitFailure;
    }
    nlohmann::json summary{{"command", "run"}, {"wall_s", wallS}};
    const int code = closeRecording(rec, o, summary);
    return finishRun(o, **appliance, *sources, outputs, *stats, rec.probe.get(), summary, code);
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
        o.given = run_cli::givenOptions(*cmd);
        const auto* parent = cmd->get_parent();
        o.logLevelGiven = (parent != nullptr && parent->get_option("--log-level")->count() > 0) ||
                          std::getenv("REPLICA_LOG") != nullptr;
        exitCode = runMain(o);
    });
}

} // namespace replica::platform
