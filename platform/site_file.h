// The site configuration file (TOML, /etc/replica/replica.toml on an appliance): what the
// calibration steps write into it. Only the keys a calibration writes are replaced, as text: the
// technician's comments and every other key and section stay byte for byte; the file is checked
// to parse before and after.
#pragma once

#include <filesystem>
#include <map>
#include <string>

#include <pipeline/base/expected.h>
#include <pipeline/scene/calibration.h>

namespace replica::platform {

constexpr const char* kDefaultSiteFile = "/etc/replica/replica.toml";

// Sets the keys of 'body' (key = value lines, with comments) in table [section] of 'file': each
// key already there is replaced where it stands, with the comments an earlier calibration wrote
// above it; a new one goes at the end of the section; [section] is added at the end of the file
// when it has none. Every other line is kept: a calibration never drops a site's port, bind
// address or comments. The file is created when it does not exist, in a folder that does (a
// missing folder is a mistyped --site). Written by writeOutputFile (a temporary file, fsynced,
// renamed; never through a symbolic link: a linked site file is refused, name its target). Fails,
// naming the file and line, when the existing file is not valid TOML or holds one of the keys in a
// form other than one 'key = value' under [section] (a [section.key] table, a dotted key).
Expected<void> writeSiteSection(const std::filesystem::path& file,
                                const std::string& section,
                                const std::string& body);

// [tracker] T_booth_tracker = { rotation = [9, row-major], translation = [3] } and the fit's
// figures, as 'replica calibrate tracker' writes them.
std::string trackerSection(const pipeline::scene::RigidFit& fit, std::size_t points);
// [stand] hinge_m, hinge_to_panel_m, panel_width_m, panel_height_m, hinge_axis_panel, fit figures.
std::string standSection(const pipeline::scene::StandFit& fit);

// [sources]: which implementation each device uses at this site, by device kind name
// (recordings::deviceKinds(): spectrometer, tracker, accel, lamp_selector; the values of 'replica
// run --spectrometer' etc.). Absent keys are not in the map; a site file without [sources] gives
// an empty one.
using SiteSources = std::map<std::string, std::string>;
Expected<SiteSources> readSiteSources(const std::filesystem::path& file);

// Reads T_booth_tracker back from a site file (nullopt-like NotFound when it has none).
Expected<pipeline::RigidTransform> readTrackerTransform(const std::filesystem::path& file);

} // namespace replica::platform
