// 'replica calibrate tracker|stand': the site calibration a technician can do with a marker and a
// tape measure. Readings come from a CSV file (or are typed in when stdin is a terminal); the
// result is checked (residual, degenerate points) and written into the site TOML file.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <numeric>
#include <sstream>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <unistd.h>

#include <hal/accel/iio_accel.h>
#include <pipeline/base/data_dir.h>
#include <pipeline/base/input_file.h>
#include <pipeline/colour/xyz.h>
#include <pipeline/csv/csv_cells.h>
#include <pipeline/scene/calibration.h>
#include <pipeline/spectral/direct_level.h>
#include <pipeline/spectral/live_chain.h>
#include <platform/appliance.h>
#include <platform/cli/commands.h>
#include <platform/logging.h>
#include <platform/site_config.h>
#include <platform/site_file.h>
#include <recordings/device_kind.h>
#include <recordings/recording.h>

namespace replica::platform {
namespace {

struct CalibrateOptions {
    std::string points;
    std::string site = kDefaultSiteFile;
    double maxRmsMm = 10.0;
    double panelWidthM = 0.0;
    double panelHeightM = 0.0;
    std::string accelAxes = "x,y,z";
    bool dryRun = false;
    // calibrate spectrometer
    std::string recording;
    std::string longPass;
    double cutOnNm = 0.0;
    double strayLight = -1.0;
    double luminanceCdM2 = 0.0; // direct-sensor mode's level: the metered lamp's luminance
    std::string levelRecording; // its readings (default: --recording)
};

// A header row's columns in the order 'names' gives them: header[order[k]] is names[k]. Names are
// matched without regard to case; an unknown, missing or repeated one is refused, naming the file
// and line (a header was skipped unread, so a file with its tracker columns first fitted the
// inverse transform with the same RMS and wrote it to the site file).
Expected<std::vector<std::size_t>> columnOrder(const std::string& line,
                                               const std::vector<std::string>& names,
                                               const std::string& where)
{
    std::istringstream s(line);
    std::vector<std::string> header;
    std::string word;
    while (s >> word) {
        std::transform(word.begin(), word.end(), word.begin(),
                       [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
        header.push_back(word);
    }
    std::vector<std::size_t> order;
    for (const auto& n : names) {
        const auto it = std::find(header.begin(), header.end(), n);
        if (it == header.end() || std::count(header.begin(), header.end(), n) != 1) {
            break;
        }
        order.push_back(static_cast<std::size_t>(it - header.begin()));
    }
    if (order.size() != names.size() || header.size() != names.size()) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: the header '{}' is not the columns {} (in any order, "
                                     "each once); name them so, or leave the header out and give "
                                     "them in that order",
                                     where, pipeline::csv::shownCell(line), fmt::join(names, ",")));
    }
    return order;
}

// Rows of names.size() numbers, comma- or space-separated; '#' starts a comment; a first row that
// is not numeric is a header naming the columns (columnOrder), which may come in any order. Errors
// name the file and line.
Expected<std::vector<std::vector<double>>> readRows(std::istream& in,
                                                    const std::string& name,
                                                    const std::vector<std::string>& names,
                                                    bool prompt)
{
    const std::size_t columns = names.size();
    std::vector<std::size_t> order(columns);
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::vector<std::vector<double>> rows;
    std::string line;
    int lineNo = 0;
    bool headerSeen = false;
    while (true) {
        if (prompt) {
            fmt::print(stderr, "point {} ({} numbers, empty line to finish): ", rows.size() + 1,
                       columns);
        }
        if (!std::getline(in, line)) {
            break;
        }
        ++lineNo;
        if (const auto hash = line.find('#'); hash != std::string::npos) {
            line.resize(hash);
        }
        for (auto& c : line) {
            c = c == ',' || c == ';' || c == '\t' ? ' ' : c;
        }
        std::istringstream s(line);
        s.imbue(std::locale::classic());
        std::vector<double> row;
        std::string word;
        bool numeric = true;
        std::string bad; // a field that is not a finite number: named in the error
        while (s >> word) {
            char* end = nullptr;
            const double v = std::strtod(word.c_str(), &end);
            if (end == word.c_str() || *end != '\0' || !std::isfinite(v)) {
                numeric = false;
                bad = fmt::format("field {} ('{}') is not a finite number", row.size() + 1,
                                  pipeline::csv::shownCell(word));
                break;
            }
            row.push_back(v);
        }
        if (row.empty() && numeric) {
            if (prompt) {
                break;
            }
            continue;
        }
        if (!numeric && rows.empty() && !prompt && !headerSeen) {
            auto o = columnOrder(line, names, fmt::format("{}:{}", name, lineNo));
            if (!o) {
                return tl::unexpected(o.error());
            }
            order = *o;
            headerSeen = true;
            continue;
        }
        if (!numeric || row.size() != columns) {
            const auto e = Error{ErrorCode::InvalidArgument,
                                 !bad.empty() ? fmt::format("{}:{}: {}; expected {} numbers", name,
                                                            lineNo, bad, columns)
                                              : fmt::format("{}:{}: expected {} numbers, got '{}'",
                                                            name, lineNo, columns,
                                                            pipeline::csv::shownCell(line))};
            if (prompt) {
                fmt::print(stderr, "{}; type it again\n", e.message);
                continue;
            }
            return tl::unexpected(e);
        }
        std::vector<double> ordered(columns);
        for (std::size_t k = 0; k < columns; ++k) {
            ordered[k] = row[order[k]];
        }
        rows.push_back(std::move(ordered));
    }
    return rows;
}

Expected<std::vector<std::vector<double>>>
readingsFrom(const std::string& file, const std::vector<std::string>& names, const char* what)
{
    if (file.empty()) {
        if (::isatty(STDIN_FILENO) == 0) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("no --points FILE given and stdin is not a terminal: "
                                         "give the {} as a CSV file",
                                         what));
        }
        fmt::print(stderr, "Type the {}, one per line.\n", what);
        return readRows(std::cin, "stdin", names, true);
    }
    // The bounded reader: a regular file of at most kMaxCsvBytes and a table within its limits (a
    // FIFO, /dev/zero or a directory is refused in one line, never a hang or bad_alloc).
    auto text = readInputFile(file, kMaxCsvBytes, "calibration points");
    if (!text) {
        return tl::unexpected(text.error());
    }
    if (auto ok = checkTableLimits(*text, file, ','); !ok) {
        return tl::unexpected(ok.error());
    }
    std::istringstream in(*text);
    return readRows(in, file, names, false);
}

int finish(const CalibrateOptions& o, const char* section, const std::string& body)
{
    if (o.dryRun) {
        fmt::print("[{}]\n{}", section, body);
        return kExitOk;
    }
    if (auto ok = writeSiteSection(o.site, section, body); !ok) {
        logger("replica")->error("{}", ok.error().message);
        return kExitFailure;
    }
    fmt::print("wrote [{}] to {}\n", section, o.site);
    return kExitOk;
}

int calibrateTracker(const CalibrateOptions& o)
{
    auto log = logger("replica");
    auto rows = readingsFrom(
            o.points, {"booth_x", "booth_y", "booth_z", "tracker_x", "tracker_y", "tracker_z"},
            "points as booth_x booth_y booth_z tracker_x tracker_y tracker_z "
            "(metres; the booth point measured with the tape, the tracker's "
            "reading of the marker held there)");
    if (!rows) {
        log->error("{}", rows.error().message);
        return kExitUsage;
    }
    std::vector<glm::dvec3> booth;
    std::vector<glm::dvec3> tracker;
    for (const auto& r : *rows) {
        booth.emplace_back(r[0], r[1], r[2]);
        tracker.emplace_back(r[3], r[4], r[5]);
    }
    pipeline::scene::RigidFitOptions fo;
    fo.maxRmsM = o.maxRmsMm * 1e-3;
    auto fit = pipeline::scene::fitRigid(tracker, booth, fo);
    if (!fit) {
        log->error("{}: {}", o.points.empty() ? "stdin" : o.points, fit.error().message);
        return kExitFailure;
    }
    for (std::size_t i = 0; i < fit->residualsM.size(); ++i) {
        fmt::print("point {:2}: residual {:6.2f} mm\n", i + 1, fit->residualsM[i] * 1e3);
    }
    const auto& t = fit->T_booth_tracker.translation;
    fmt::print("T_booth_tracker: RMS residual {:.2f} mm over {} points; the tracker's origin sits "
               "at ({:.3f}, {:.3f}, {:.3f}) m in the booth\n",
               fit->rmsM * 1e3, rows->size(), t.x, t.y, t.z);
    return finish(o, "tracker", trackerSection(*fit, rows->size()));
}

int calibrateStand(const CalibrateOptions& o)
{
    auto log = logger("replica");
    auto mapping = hal::accel::parseAxisMapping(o.accelAxes);
    if (!mapping) {
        log->error("--accel-axes {}: {}", o.accelAxes, mapping.error().message);
        return kExitUsage;
    }
    auto rows = readingsFrom(o.points, {"ax", "ay", "az", "top_y", "top_z"},
                             "readings as ax ay az top_y top_z (the accelerometer in m/s^2 as "
                             "'replica probe' prints it; the tape: height of the middle of the "
                             "panel's top edge above the booth floor and its distance towards the "
                             "viewer from the booth's centre, metres), one per tilt");
    if (!rows) {
        log->error("{}", rows.error().message);
        return kExitUsage;
    }
    std::vector<pipeline::scene::StandReading> readings;
    for (const auto& r : *rows) {
        readings.push_back({hal::accel::gravityInPanel({r[0], r[1], r[2]}, *mapping), r[3], r[4]});
    }
    pipeline::scene::StandFitOptions fo;
    fo.maxRmsM = o.maxRmsMm * 1e-3;
    auto fit = pipeline::scene::fitStand(readings, o.panelWidthM, o.panelHeightM, fo);
    if (!fit) {
        log->error("{}: {}", o.points.empty() ? "stdin" : o.points, fit.error().message);
        return kExitFailure;
    }
    constexpr double kDeg = 180.0 / 3.14159265358979323846;
    for (std::size_t i = 0; i < fit->tiltsRad.size(); ++i) {
        const auto pose = pipeline::scene::panelPose(fit->stand, fit->tiltsRad[i]);
        const glm::dvec3 c0 = pose.cornerM();
        const glm::dvec3 c1 = pose.cornerM() + pose.rightEdgeM();
        const glm::dvec3 c2 = c1 + pose.upEdgeM();
        const glm::dvec3 c3 = c0 + pose.upEdgeM();
        fmt::print(
                "tilt {:5.1f} deg: corners (m) ({:.3f}, {:.3f}, {:.3f}) ({:.3f}, {:.3f}, {:.3f}) "
                "({:.3f}, {:.3f}, {:.3f}) ({:.3f}, {:.3f}, {:.3f})\n",
                fit->tiltsRad[i] * kDeg, c0.x, c0.y, c0.z, c1.x, c1.y, c1.z, c2.x, c2.y, c2.z, c3.x,
                c3.y, c3.z);
    }
    fmt::print("hinge at y {:.3f} m, z {:.3f} m; panel {:.3f} m above it; tape RMS {:.2f} mm; "
               "hinge axis {:.2f} deg off the panel's x axis\n",
               fit->stand.hingeM.y, fit->stand.hingeM.z, fit->stand.hingeToPanelM, fit->rmsM * 1e3,
               fit->axisAngleRad * kDeg);
    // A tape read in centimetres fits as well as one in metres (a stand scaled up has the same
    // residual), so the scale is checked against what a booth's stand can be.
    const glm::dvec3& h = fit->stand.hingeM;
    if (std::abs(h.y) > kStandHingeLimitM || std::abs(h.z) > kStandHingeLimitM ||
        std::abs(fit->stand.hingeToPanelM) > kStandHingeToPanelLimitM) {
        log->error("{}: the fit puts the hinge {:.3f} m up and {:.3f} m out and the panel {:.3f} m "
                   "above it, not a stand in a booth (within {} m; the panel within {} m of the "
                   "hinge): give top_y and top_z in metres; nothing written",
                   o.points.empty() ? "stdin" : o.points, h.y, h.z, fit->stand.hingeToPanelM,
                   kStandHingeLimitM, kStandHingeToPanelLimitM);
        return kExitFailure;
    }
    if (fit->axisAngleRad * kDeg > 3.0) {
        log->warn("the hinge axis is {:.1f} degrees off the panel's x axis as the accelerometer "
                  "sees it: check --accel-axes and how the sensor is mounted",
                  fit->axisAngleRad * kDeg);
    }
    return finish(o, "stand", standSection(*fit));
}

// The spectrometer samples of a recording as the chain reads them (the samples must outlive the
// result's spans).
Expected<std::vector<hal::SpectrumSample>> recordedSpectra(const std::string& file)
{
    auto rec = recordings::readRecording(file);
    if (!rec) {
        return tl::unexpected(rec.error());
    }
    auto samples = rec->samples(recordings::spectrometerKind());
    if (samples.empty()) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: no spectrometer samples; record the booth's fluorescent "
                                     "lamp with 'replica run --record FILE' first",
                                     file));
    }
    return samples;
}

std::vector<pipeline::spectral::RawSpectrum>
rawSpectra(const std::vector<hal::SpectrumSample>& samples)
{
    std::vector<pipeline::spectral::RawSpectrum> raw;
    for (const auto& s : samples) {
        raw.push_back({s.counts, s.integrationTimeUs, s.wavelengthCoeffs, s.nonlinearityCoeffs});
    }
    return raw;
}

// Direct-sensor mode's level (pipeline/spectral/direct_level.h): the metered lamp's readings
// (--level-recording, else --recording) through the live chain with the calibration just found;
// the site file's line, or why not.
Expected<std::string> directLevel(const CalibrateOptions& o,
                                  const pipeline::spectral::InstrumentCalibration& instrument)
{
    const std::string file = o.levelRecording.empty() ? o.recording : o.levelRecording;
    auto samples = recordedSpectra(file);
    if (!samples) {
        return tl::unexpected(samples.error());
    }
    auto observer = pipeline::colour::loadCie1931(dataDir());
    if (!observer) {
        return tl::unexpected(observer.error());
    }
    // The responsivity the appliance converts with (its spectra's Y is what the level scales).
    auto cal = pipeline::spectral::loadSpectrometerCalibration(dataDir() /
                                                               RunConfig{}.spectrometerCalibration);
    if (!cal) {
        return tl::unexpected(cal.error());
    }
    auto level = pipeline::spectral::calibrateDirectLevel(rawSpectra(*samples), *cal, instrument,
                                                          *observer, o.luminanceCdM2);
    if (!level) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: {}", file, level.error().message));
    }
    fmt::print("direct-sensor level {:.6g} cd/m^2 per unit of Y: {} cd/m^2 metered over the "
               "median Y {:.6g} of {} steady readings (spread {:.1f} %)\n",
               level->cdm2PerY, o.luminanceCdM2, level->medianY, level->spectra,
               100.0 * level->spreadFraction);
    if (level->spreadFraction > 0.05) {
        logger("replica")->warn("{}: the readings of the metered lamp vary by {:.1f} % (max - "
                                "min over median): was the lamp warmed up and steady?",
                                file, 100.0 * level->spreadFraction);
    }
    return fmt::format("# direct-sensor level from {} ({} cd/m^2 metered)\n"
                       "direct_cdm2_per_y = {:.6g}\n",
                       file, o.luminanceCdM2, level->cdm2PerY);
}

// The instrument's calibration for the live chain (pipeline/spectral/live_chain.h): the
// wavelength shift from the mercury lines of a fluorescent lamp, recorded; the stray light from a
// recording through a long-pass filter, or the instrument's data (a number), or the data sheet's.
int calibrateSpectrometer(const CalibrateOptions& o)
{
    auto log = logger("replica");
    const pipeline::spectral::SpectrometerCalibration cal; // the dark pixels
    auto lamp = recordedSpectra(o.recording);
    if (!lamp) {
        log->error("{}", lamp.error().message);
        return kExitFailure;
    }
    const auto shift = pipeline::spectral::calibrateWavelengthShift(rawSpectra(*lamp), cal);
    if (!shift) {
        log->error("{}: no run of 10 steady spectra shows two mercury lines (404.66, 435.83, "
                   "546.07 nm) within {} nm of where the instrument's wavelength polynomial puts "
                   "them; record a fluorescent booth lamp, not tungsten or an LED. If this is a "
                   "fluorescent lamp, the polynomial is off by more than that: check the EEPROM's "
                   "wavelength coefficients ('replica probe' prints them) or have the instrument "
                   "recalibrated",
                   o.recording, pipeline::spectral::LineSearchOptions{}.searchNm);
        return kExitFailure;
    }
    double stray = o.strayLight >= 0.0
                           ? o.strayLight
                           : pipeline::spectral::InstrumentCalibration{}.strayLightFraction;
    std::string strayFrom = o.strayLight >= 0.0 ? "the instrument's data" : "the data sheet";
    if (!o.longPass.empty()) {
        auto filtered = recordedSpectra(o.longPass);
        if (!filtered) {
            log->error("{}", filtered.error().message);
            return kExitFailure;
        }
        const auto f =
                pipeline::spectral::strayLightFromLongPass(rawSpectra(*filtered), cal, o.cutOnNm);
        if (!f) {
            log->error("{}: no usable spectrum below the {:.0f} nm cut-on", o.longPass, o.cutOnNm);
            return kExitFailure;
        }
        stray = *f;
        strayFrom = fmt::format("{} through a {:.0f} nm long-pass filter", o.longPass, o.cutOnNm);
    }
    fmt::print("wavelength shift {:+.3f} nm (median of {} runs of 10 spectra, spread {:.3f} nm); "
               "stray light {:.3g} of the peak ({})\n",
               shift->offsetNm, shift->runs, shift->spreadNm, stray, strayFrom);
    std::string body = fmt::format(
            "# 'replica calibrate spectrometer' from {}; stray light from {}\n"
            "stray_light_fraction = {:.6g}\nwavelength_offset_nm = {:.4f}\n"
            "calibration_spectra = {}\ncalibration_spread_nm = {:.4f}\n",
            o.recording, strayFrom, stray, shift->offsetNm, lamp->size(), shift->spreadNm);
    if (o.luminanceCdM2 > 0.0) {
        auto level = directLevel(o, {stray, shift->offsetNm});
        if (!level) {
            log->error("{}", level.error().message);
            return kExitFailure;
        }
        body += *level;
    } // else a level calibrated before stays in the site file as it is (writeSiteSection)
    return finish(o, "spectrometer", body);
}

} // namespace

// --site checked when the command line is read, before a fit the technician would otherwise sit
// through and then lose: the file's folder must exist (writeSiteSection refuses it again, for
// the library's other callers).
const CLI::Validator siteInExistingFolder(
        [](const std::string& site) -> std::string {
            const std::filesystem::path file(site);
            const std::filesystem::path folder = file.has_parent_path() ? file.parent_path() : ".";
            std::error_code ec;
            if (std::filesystem::is_directory(folder, ec)) {
                return {};
            }
            return fmt::format("there is no folder {}; give --site a file in an existing folder",
                               folder.string());
        },
        "FILE in an existing folder");

void registerCalibrateCommand(CLI::App& app, int& exitCode)
{
    auto* cmd = app.add_subcommand(
            "calibrate", "site calibration: the tracker's pose in the booth, the stand's hinge, "
                         "the spectrometer");
    cmd->require_subcommand(1);
    auto o = std::make_shared<CalibrateOptions>();
    auto common = [o](CLI::App* sub, const char* what) {
        sub->add_option("--points", o->points,
                        fmt::format("CSV of the {} (without it, typed in at the terminal)", what));
        sub->add_option("--site", o->site, "site configuration file to write the result into")
                ->check(siteInExistingFolder)
                ->capture_default_str();
        sub->add_option("--max-rms-mm", o->maxRmsMm,
                        "refuse a fit whose RMS residual is larger (mm)")
                ->check(CLI::Range(0.1, 1000.0))
                ->capture_default_str();
        sub->add_flag("--dry-run", o->dryRun, "print the section instead of writing the file");
    };
    auto* tracker = cmd->add_subcommand(
            "tracker", "fit T_booth_tracker from the tracker's readings of a marker held at 3 or "
                       "more tape-measured booth points");
    common(tracker, "points: booth_x,booth_y,booth_z,tracker_x,tracker_y,tracker_z (m)");
    tracker->callback([o, &exitCode] { exitCode = calibrateTracker(*o); });
    auto* stand = cmd->add_subcommand(
            "stand", "fit the hinge and panel offset from accelerometer readings at two or three "
                     "tilts and the tape-measured top edge");
    common(stand, "readings: ax,ay,az (m/s^2),top_y,top_z (m)");
    stand->add_option("--panel-width", o->panelWidthM, "active area width, tape-measured (m)")
            ->required();
    stand->add_option("--panel-height", o->panelHeightM, "active area height, tape-measured (m)")
            ->required();
    stand->add_option("--accel-axes", o->accelAxes,
                      "sensor axis for each panel axis, as for 'replica run'")
            ->capture_default_str();
    stand->callback([o, &exitCode] { exitCode = calibrateStand(*o); });
    auto* spectrometer = cmd->add_subcommand(
            "spectrometer", "the spectrometer's wavelength shift from the mercury lines of a "
                            "fluorescent booth lamp, and its stray light, for the live chain");
    spectrometer
            ->add_option("--recording", o->recording,
                         "a recording ('replica run --record') of a fluorescent booth lamp, "
                         "steady for some seconds")
            ->required();
    spectrometer->add_option("--long-pass", o->longPass,
                             "a recording of the lamp through a long-pass filter: the stray light "
                             "is what reaches the pixels below its cut-on");
    spectrometer->add_option("--cut-on-nm", o->cutOnNm, "the long-pass filter's cut-on (nm)")
            ->check(CLI::Range(400.0, 900.0));
    spectrometer
            ->add_option("--stray-light", o->strayLight,
                         "the stray light from the instrument's data, as a fraction of the peak "
                         "(without it and --long-pass: the data sheet's 0.0005)")
            ->check(CLI::Range(0.0, 0.05));
    spectrometer
            ->add_option("--luminance-cdm2", o->luminanceCdM2,
                         "direct-sensor mode's level: the luminance (cd/m^2) a luminance meter "
                         "reads of the lamp recorded in --level-recording (or --recording), e.g. "
                         "of a white tile under it; writes direct_cdm2_per_y")
            ->check(CLI::Range(1e-3, 1e6));
    spectrometer->add_option("--level-recording", o->levelRecording,
                             "a recording of the metered lamp alone, steady for some seconds "
                             "(default: --recording)");
    spectrometer->add_option("--site", o->site, "site configuration file to write the result into")
            ->check(siteInExistingFolder)
            ->capture_default_str();
    spectrometer->add_flag("--dry-run", o->dryRun, "print the section instead of writing the file");
    spectrometer->callback([o, &exitCode] {
        if (!o->longPass.empty() && !(o->cutOnNm > 0.0)) {
            logger("replica")->error("--long-pass needs --cut-on-nm (the filter's cut-on)");
            exitCode = kExitUsage;
            return;
        }
        exitCode = calibrateSpectrometer(*o);
    });
}

} // namespace replica::platform
