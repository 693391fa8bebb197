// The options of 'replica run'.
#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numbers>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <pipeline/base/data_dir.h>
#include <pipeline/spectral/representation_catalogue.h>
#include <platform/cli/commands.h>
#include <platform/cli/run_options.h>
#include <platform/logging.h>
#include <platform/loop/frame_loop.h>
#include <platform/output/display_geometry.h>
#include <platform/site_file.h>

namespace replica::platform::run_cli {
namespace {

// Copies the site file's value into the run's option: Site a SiteConfig member, Path the
// RunOptions member (or a path of members into it).
template <auto Site, auto... Path>
void fromSite(const SiteConfig& s, RunOptions& o)
{
    (o.*....*Path) = s.*Site;
}

// The run settings the site file gives as they are, each taken when the command line leaves its
// option unset: a new one is one row (and its key in site_config.cpp).
struct SiteDefault {
    const char* option;
    void (*fill)(const SiteConfig&, RunOptions&);
};
using S = SiteConfig;
using O = RunOptions;
using L = LiveOptions;
constexpr std::array kSiteDefaults = {
        SiteDefault{"--hal", fromSite<&S::hal, &O::hal>},
        SiteDefault{"--replay-file", fromSite<&S::replayFile, &O::replayFile>},
        SiteDefault{"--rate", fromSite<&S::rateHz, &O::rateHz>},
        SiteDefault{"--min-rate", fromSite<&S::minRateHz, &O::minRateHz>},
        SiteDefault{"--output", fromSite<&S::output, &O::output>},
        SiteDefault{
                "--kms-device",
                fromSite<&S::kmsDevice, &O::outputChoice, &OutputChoice::kms, &KmsOptions::device>},
        SiteDefault{"--kms-connector", fromSite<&S::kmsConnector,
                                                &O::outputChoice,
                                                &OutputChoice::kms,
                                                &KmsOptions::connector>},
        SiteDefault{"--renderer", fromSite<&S::renderer, &O::renderer>},
        SiteDefault{"--light", fromSite<&S::light, &O::light>},
        SiteDefault{"--tracker-port", fromSite<&S::trackerPort, &O::live, &L::trackerPort>},
        SiteDefault{"--tracker-bind", fromSite<&S::trackerBind, &O::live, &L::trackerBind>},
        SiteDefault{"--iio-root", fromSite<&S::iioRoot, &O::live, &L::iioRoot>},
        SiteDefault{"--accel-name", fromSite<&S::accelName, &O::live, &L::accelName>},
        SiteDefault{"--accel-axes", fromSite<&S::accelAxes, &O::live, &L::accelAxes>},
        SiteDefault{"--lamp-gpio", fromSite<&S::lampGpio, &O::live, &L::lampGpio>},
        SiteDefault{"--spectrometer-serial",
                    fromSite<&S::spectrometerSerial, &O::live, &L::spectrometerSerial>},
        SiteDefault{"--record-flush-ms", fromSite<&S::flushMs, &O::recordFlushMs>},
        SiteDefault{"--no-warm-up", [](const S& s, O& o) { o.noWarmUp = !s.warmUp; }},
        SiteDefault{"--error-probe", fromSite<&S::errorProbeS, &O::errorProbeS>},
};

// The site file, the sensor sources and the live devices' settings.
void addSourceOptions(CLI::App& cmd, RunOptions& o)
{
    cmd.add_option("--config", o.config,
                   "site file (TOML, docs/appliance.md); the command line overrides it. "
                   "--kiosk reads " +
                           defaultSiteConfigPath().string() + " when none is given");
    cmd.add_flag("--kiosk", o.kiosk,
                 "the gallery appliance: run until stopped, record sessions into the site "
                 "file's recording.directory (rotated, oldest deleted beyond keep_bytes, a "
                 "crashed session recovered at start); refuses a live run on a synthetic "
                 "display profile unless display.allow_synthetic");
    cmd.add_option("--hal", o.hal,
                   "sensor sources: sim (built-in simulated sensors), live (USB2000+ over "
                   "libusb, opentrack UDP head poses, IIO accelerometer) or replay (the samples "
                   "of --replay-file, then the last state held)")
            ->capture_default_str();
    cmd.add_option("--replay-file", o.replayFile, "--hal replay: the recording to play");
    cmd.add_option("--inject-faults", o.faults,
                   "soak tests: nan-pose=N (every Nth head pose NaN), saturate=N (every Nth "
                   "spectrum saturated), unplug=EVERY_S/FOR_S (spectrometer and tracker "
                   "silent FOR_S of every EVERY_S)")
            ->group("Testing");
    cmd.add_option("--tracker-port", o.live.trackerPort,
                   "live: UDP port opentrack sends head poses to")
            ->capture_default_str();
    cmd.add_option("--tracker-bind", o.live.trackerBind, "live: address to listen on")
            ->capture_default_str();
    cmd.add_option("--iio-root", o.live.iioRoot, "live: where IIO devices are listed")
            ->capture_default_str();
    cmd.add_option("--accel-name", o.live.accelName,
                   "live: the accelerometer's IIO name (default: the first one)");
    cmd.add_option("--accel-axes", o.live.accelAxes,
                   "live: sensor axis for each panel axis (x right, y up, z out of the screen), "
                   "e.g. -y,x,z")
            ->capture_default_str();
    cmd.add_option("--lamp-gpio", o.live.lampGpio,
                   "live: the booth's lamp selector switch, CHIP:OFFSET,OFFSET,... with one GPIO "
                   "line per lamp in the booth's lamp order (active low, pull-up), e.g. "
                   "gpiochip0:17,27,22; without it the spectrometer alone decides the light");
    cmd.add_option("--spectrometer-serial", o.live.spectrometerSerial,
                   "live: open the USB2000+ whose USB serial number is this (as `lsusb -v` "
                   "shows it); default: the first one found");
    for (const auto* kind : recordings::deviceKinds()) { // --spectrometer, ..., --lamp-selector
        cmd.add_option("--" + deviceOption(*kind), o.sources[kind->name()],
                       kind->names().sourceHelp)
                ->check(CLI::IsMember(kind->names().sources));
    }
    cmd.add_option("--replay-from", o.replayFrom,
                   "the recording that devices set to 'replay' play back (from its session "
                   "start)");
    cmd.add_option("--site", o.sitePath,
                   "site configuration file (e.g. /etc/replica/replica.toml): [sources] "
                   "spectrometer/tracker/accel/lamp_selector (the command line wins) and the "
                   "calibrated tracker pose [tracker] T_booth_tracker from 'replica calibrate "
                   "tracker'");
    cmd.add_option("--hid-tracker", o.live.hidTracker,
                   "--tracker hid: the hidraw node, e.g. /dev/hidraw3 (default: the first eye/head "
                   "tracker found; 'replica probe' lists them)");
    cmd.add_option("--tracker-axes", o.live.trackerAxes,
                   "--tracker hid: the device axis for x right, y up, z towards the viewer, e.g. "
                   "x,-y,z for a tracker whose y points down the screen")
            ->capture_default_str();
}

// The output, the frames, the recording and what it records.
void addOutputOptions(CLI::App& cmd, RunOptions& o)
{
    cmd.add_option("--output", o.output,
                   "frame output: headless (surfaceless EGL) or kms (fullscreen scan-out)")
            ->capture_default_str();
    addKmsOptions(cmd, o.outputChoice.kms);
    cmd.add_option("--frames", o.frames,
                   "number of frames to run; 0 = until SIGINT/SIGTERM (the kiosk)")
            ->check(CLI::Range(std::uint64_t{0}, kMaxFrames))
            ->capture_default_str();
    cmd.add_option("--size", o.size,
                   "headless: frame size WIDTHxHEIGHT (default 960x600); on kms the frame is the "
                   "mode's size");
    cmd.add_option("--panel-size-mm", o.panelSizeMm,
                   "the panel's active area WIDTHxHEIGHT in millimetres, which the frame covers "
                   "(default: the display's EDID on kms, else 518x324, a 24-inch 16:10 panel)");
    cmd.add_option("--rate", o.rateHz, "frame rate (Hz)")
            ->check(CLI::Range(1.0, 1000.0))
            ->capture_default_str();
    cmd.add_option("--min-rate", o.minRateHz,
                   "when frames take longer than the period, draw every n-th tick (rate / n, the "
                   "smallest whole n the frames fit) down to this rate, for even motion, instead "
                   "of late ticks as they come; at or above --rate: never (Hz; realtime runs only, "
                   "not --fast)")
            ->check(CLI::Range(1.0, 1000.0))
            ->capture_default_str();
    cmd.add_option("--record", o.record, "write every sensor sample and frame input to FILE");
    cmd.add_flag("--force", o.force,
                 "--record: overwrite FILE if it exists (never through a symbolic link)");
    cmd.add_option("--record-flush-ms", o.recordFlushMs,
                   "close and sync the recording's open chunk at least this often (ms): a power "
                   "cut loses at most about this much")
            ->check(CLI::Range(10, 10000))
            ->capture_default_str();
    cmd.add_option("--record-digests", o.recordDigests,
                   "with --record: an XXH3-64 digest of every frame sent to the panel in the "
                   "recording (/replica/display_digest; replay checks it)")
            ->capture_default_str();
    cmd.add_option("--thumbnail-hz", o.thumbnailHz,
                   "with --record: PNG thumbnails of the displayed frame per second of session "
                   "time (/replica/thumbnail); 0: none")
            ->check(CLI::Range(0.0, 60.0))
            ->capture_default_str();
    cmd.add_option("--thumbnail-width", o.thumbnailWidth, "thumbnail width (pixels)")
            ->check(CLI::Range(16, 4096))
            ->capture_default_str();
    cmd.add_option("--tilt-nodes", o.tiltNodesDeg,
                   "cache the diffuse term at panel tilts this many degrees apart and show a "
                   "moving panel's term interpolated between the two around its tilt (redrawn "
                   "every node, not every tilt); 0: redraw the term at every held tilt (degrees)")
            ->check(CLI::Range(0.0, kMaxTiltNodesDeg))
            ->capture_default_str();
    cmd.add_option("--error-probe", o.errorProbeS,
                   "every SECONDS of session time, the exact reference at a few hundred random "
                   "pixels of the frame against the frame, at idle priority: ΔE00 p95/max into "
                   "the recording (/replica/error_probe) and the summary; 0: off (the default "
                   "without a site file; the site file's [render] error_probe, 10 s when absent)")
            ->check(CLI::Range(0.0, 3600.0))
            ->capture_default_str();
    cmd.add_flag("--json", o.json,
                 "print a JSON summary (frames, frame times, drops, recording, outputs) on "
                 "standard output instead of the text lines");
    cmd.add_option("--digests", o.digests, "write one digest per frame to FILE (JSON)");
    cmd.add_option("--snapshot", o.snapshot, "write the last frame to FILE (PNG)");
}

// The scene, the renderer and the display model.
void addRenderOptions(CLI::App& cmd, RunOptions& o)
{
    cmd.add_option("--scene", o.scene,
                   "surface scene folder (scene.json + EXRs); default: the shipped ColorChecker, "
                   "data/scenes/colorchecker");
    cmd.add_option("--booth", o.booth,
                   "booth model folder (booth.json and a luminance EXR per lamp, as 'replica booth "
                   "build' makes it from a site's captures: docs/booth-capture.md); default: the "
                   "shipped data/booth; the site file's [booth] dir");
    cmd.add_option("--light", o.light,
                   "auto: the booth lamp the spectrometer's reading matches (the sensed spectrum "
                   "where none does); direct: always the sensed spectrum on a uniform emitter at "
                   "the sensed level (the paper's direct-sensor mode; docs/rendering.md); the site "
                   "file's [booth] light")
            ->check(CLI::IsMember({"auto", "direct"}))
            ->capture_default_str();
    cmd.add_option("--renderer", o.renderer,
                   "booth (the scene lit by the booth model; the one renderer, so the option can "
                   "be left out)")
            ->capture_default_str();
    cmd.add_option("--basis", o.basis,
                   "channel basis: adaptive_k6 (re-encoded for each light, exact for the light "
                   "present; the default), replica_k6, general_k6, pca6, box6 (fixed; "
                   "docs/accuracy.md)")
            ->check(CLI::IsMember(pipeline::spectral::channelBasisNames()));
    cmd.add_flag("--fast", o.fast,
                 "do not wait for each tick's wall-clock time (same frames, rendered as fast as "
                 "possible)");
    cmd.add_option("--display-profile", o.displayProfile,
                   "display profile (JSON, from 'replica display fit'); default: the shipped "
                   "data/displays/wide-ips-synthetic.json");
    cmd.add_flag("--uncalibrated", o.uncalibrated,
                 "run without a display profile, on a nominal sRGB-like model (colours are then "
                 "not faithful)");
    cmd.add_option("--display-inverse", o.displayInverse,
                   "inverse display model in the shader: analytic or lut3d")
            ->check(CLI::IsMember({"analytic", "lut3d"}))
            ->capture_default_str();
    cmd.add_option("--gamut", o.gamut,
                   "out-of-gamut colours: hue (hue-keeping mapping) or clip (per channel; for "
                   "comparison)")
            ->check(CLI::IsMember({"hue", "clip"}))
            ->capture_default_str();
    cmd.add_flag("--no-viewing-compensation", o.noViewing,
                 "drive every pixel as if seen on the panel normal");
    cmd.add_flag("--no-flare-subtraction", o.noFlare,
                 "do not subtract the screen's own reflection of the booth light");
    auto* planner = cmd.add_flag(
            "--planner", o.planner,
            "draw each lamp with the planner's lights, specular samples and horizon directions, "
            "planning the scene now (minutes, once; cached) when it has no plan; without "
            "--planner or --no-planner a scene's cached or shipped plan is used when there is one "
            "(the choice is recorded); the site file's [render] planner = true asks the same");
    cmd.add_flag("--no-planner", o.noPlanner,
                 "the fixed per-scene rules for every lamp (the site file's [render] planner = "
                 "false asks the same)")
            ->excludes(planner);
    cmd.add_option("--plan-cache", o.planCache,
                   "folder of the planner's cached plans (default $REPLICA_PLAN_CACHE, else "
                   "$XDG_CACHE_HOME/replica/plans, else ~/.cache/replica/plans)");
    addWarmUpOption(cmd, o.noWarmUp, "; the site file's [render] warm_up = false asks the same");
    cmd.add_flag("--false-colour", o.falseColour,
                 "field-staff overlay: stripe out-of-gamut pixels (magenta: chroma, cyan: above "
                 "peak, blue: below black)");
}

} // namespace

void addRunOptions(CLI::App& cmd, RunOptions& o)
{
    addSourceOptions(cmd, o);
    addOutputOptions(cmd, o);
    addRenderOptions(cmd, o);
}

std::string deviceOption(const recordings::DeviceKindBase& kind)
{
    std::string s = kind.name();
    std::replace(s.begin(), s.end(), '_', '-');
    return s;
}

std::string dataPath(const std::string& p)
{
    const std::filesystem::path path(p);
    return path.is_relative() ? (dataDir() / path).string() : path.string();
}

std::set<std::string> givenOptions(const CLI::App& cmd)
{
    std::set<std::string> given;
    for (const auto* opt : cmd.get_options()) {
        if (opt->count() > 0) {
            for (const auto& name : opt->get_lnames()) {
                given.insert("--" + name);
            }
        }
    }
    return given;
}

void applySite(const SiteConfig& s, RunOptions& o)
{
    const auto unset = [&o](const char* name) { return !o.given.contains(name); };
    for (const auto& row : kSiteDefaults) {
        if (unset(row.option)) {
            row.fill(s, o);
        }
    }
    // The four whose site value is not taken as it is.
    if (unset("--size") && o.output != "kms") { // on KMS the frame is the mode's size
        o.size = s.size;
    }
    if (unset("--scene") && !s.sceneDir.empty()) {
        o.scene = dataPath(s.sceneDir);
    }
    if (unset("--booth") && !s.boothDir.empty()) {
        o.booth = dataPath(s.boothDir);
    }
    if (unset("--display-profile") && unset("--uncalibrated") && !s.displayProfile.empty()) {
        o.displayProfile = dataPath(s.displayProfile);
    }
}

std::optional<std::pair<int, int>> parseSize(const std::string& s)
{
    // Checked whole before it is narrowed to int: 4294967392x60 is out of range, not 96x60.
    const auto size = parsePixelSize(s);
    if (!size || !frameSizeOk(size->first, size->second)) {
        return std::nullopt;
    }
    return std::make_pair(static_cast<int>(size->first), static_cast<int>(size->second));
}

} // namespace replica::platform::run_cli

namespace replica::platform {

void addWarmUpOption(CLI::App& cmd, bool& noWarmUp, const std::string& also)
{
    cmd.add_flag("--no-warm-up", noWarmUp,
                 "compile no lamp's shading pass ahead (run: the first frame's alone before it, "
                 "the others after it in the background; replay: every one before the first "
                 "frame): each then compiles at its first use, and the first switch to a lamp "
                 "waits for it (the frames are the same; for software emulation, where the "
                 "compilation takes minutes)" +
                         also);
}

void addKmsOptions(CLI::App& cmd, KmsOptions& kms)
{
    cmd.add_option("--kms-device", kms.device, "kms: the DRM card to drive")->capture_default_str();
    cmd.add_option("--kms-connector", kms.connector,
                   "kms: connector name, e.g. HDMI-A-1 (default: the first connected)");
    cmd.add_option("--kms-mode", kms.mode,
                   "kms: the mode, WIDTHxHEIGHT or WIDTHxHEIGHT@HZ (default: the display's "
                   "preferred mode)");
    cmd.add_option("--kms-modeset", kms.modeset,
                   "kms: auto (atomic where the driver has it, else legacy), atomic or legacy")
            ->check(CLI::IsMember({"auto", "atomic", "legacy"}))
            ->capture_default_str();
    cmd.add_option("--kms-path", kms.path,
                   "kms: auto (EGL on a GBM surface, else CPU copies into dumb buffers), gbm or "
                   "dumb")
            ->check(CLI::IsMember({"auto", "gbm", "dumb"}))
            ->capture_default_str();
}

} // namespace replica::platform
