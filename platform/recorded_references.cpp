// What a run configuration names on disk: the scene folder and its digest, the display profile's
// name, and the checks that an untrusted recording names only files inside the data folders.
#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <numbers>
#include <span>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <hal/replay/replay_source.h>
#include <hal/sim/sim_devices.h>
#include <pipeline/base/data_dir.h>
#include <pipeline/base/input_file_parts.h>
#include <pipeline/booth/booth_model.h>
#include <pipeline/colour/spectral_table.h>
#include <pipeline/display/display_inverse.h>
#include <pipeline/display/display_profile.h>
#include <pipeline/display/nominal_display.h>
#include <pipeline/render/gles_renderer.h>
#include <pipeline/scene/booth.h>
#include <pipeline/shading/realtime_model.h>
#include <pipeline/spectral/adaptive_encoding.h>
#include <pipeline/spectral/representation_catalogue.h>
#include <platform/appliance.h>
#include <platform/booth_dimmer.h>
#include <platform/logging.h>
#include <platform/loop/frame_digest.h>
#include <platform/render_plan.h>
#include <platform/run_config_schema.h>

namespace replica::platform {

std::filesystem::path resolveSceneDir(const std::string& sceneDir)
{
    const std::filesystem::path p(sceneDir);
    return p.is_relative() ? dataDir() / p : p;
}

namespace {

// 'p' lies inside 'root' once both are made absolute and '..' and links resolved as far as
// they exist.
bool inside(const std::filesystem::path& p, const std::filesystem::path& root)
{
    std::error_code ec;
    const auto a = std::filesystem::weakly_canonical(std::filesystem::absolute(p, ec), ec);
    if (ec) {
        return false;
    }
    const auto r = std::filesystem::weakly_canonical(std::filesystem::absolute(root, ec), ec);
    if (ec) {
        return false;
    }
    const auto rel = a.lexically_relative(r);
    return !rel.empty() && *rel.begin() != ".." && !rel.is_absolute();
}

Expected<void> checkReference(const std::string& key,
                              const std::string& value,
                              const std::vector<std::filesystem::path>& roots)
{
    const std::filesystem::path p(value);
    bool dotdot = false;
    for (const auto& part : p) {
        dotdot = dotdot || part == "..";
    }
    std::string rootList = dataDir().string();
    for (const auto& r : roots) {
        rootList += ", " + r.string();
    }
    if (value.empty() || dotdot || value.find('\0') != std::string::npos) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("the recording's {} '{}' is not a name inside the data "
                                     "folder ('..' or empty); refused",
                                     key, value.substr(0, 200)));
    }
    if (p.is_relative()) {
        return inside(dataDir() / p, dataDir())
                       ? Expected<void>{}
                       : makeError(ErrorCode::InvalidArgument,
                                   fmt::format("the recording's {} '{}' leads out of the data "
                                               "folder {} (a link?); refused",
                                               key, value.substr(0, 200), dataDir().string()));
    }
    bool ok = inside(p, dataDir());
    for (const auto& r : roots) {
        ok = ok || inside(p, r);
    }
    if (!ok) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("the recording's {} is '{}', outside the data folders ({}); "
                                     "replay opens only files there: copy it under one and pass "
                                     "that folder with --data-root DIR",
                                     key, value.substr(0, 200), rootList));
    }
    return {};
}

} // namespace

Expected<void> checkRecordedReferences(const RunConfig& config,
                                       const std::vector<std::filesystem::path>& roots,
                                       bool allowUndigested)
{
    // The flat renderer's recordings draw the shipped ColorChecker (RunConfig::fromJson): no
    // scene of theirs to check.
    if (!config.drawnByFlatRenderer) {
        if (auto ok = checkReference("scene_dir", config.sceneDir, roots); !ok) {
            return ok;
        }
        if (config.sceneDigest.empty() && !allowUndigested) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("the recording holds no digest of its scene '{}', so "
                                         "the scene replayed cannot be checked against the one "
                                         "recorded; pass --allow-undigested to replay it anyway",
                                         config.sceneDir.substr(0, 200)));
        }
    }
    if (auto ok = checkReference("booth_dir", config.boothDir, roots); !ok) {
        return ok;
    }
    if (config.display != kUncalibratedDisplay) {
        if (auto ok = checkReference("display", config.display, roots); !ok) {
            return ok;
        }
        if (config.displayDigest.empty() && !allowUndigested) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("the recording holds no digest of its display profile "
                                         "'{}'; pass --allow-undigested to replay it anyway",
                                         config.display.substr(0, 200)));
        }
    }
    if (auto ok = checkReference("spectrometer_calibration", config.spectrometerCalibration, {});
        !ok) {
        return ok;
    }
    if (std::filesystem::path(config.spectrometerCalibration).is_absolute()) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("the recording's spectrometer_calibration '{}' is not a "
                                     "name inside the data folder; refused",
                                     config.spectrometerCalibration.substr(0, 200)));
    }
    return {};
}

Expected<std::string> sceneDigest(const std::filesystem::path& dir)
{
    std::uint64_t h = 14695981039346656037ull;
    for (const char* name : {"scene.json", "channels.exr", "height.exr", "material.exr"}) {
        for (const char c : std::string(name)) {
            h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ull;
        }
        // Regular files only, opened once and hashed piece by piece: a FIFO would block a stream
        // and a directory throw from it.
        auto read = readInputFilePieces(
                dir / name, kMaxImageBytes, "scene", [&h](std::string_view piece) {
                    for (const char c : piece) {
                        h = (h ^ static_cast<unsigned char>(c)) * 1099511628211ull;
                    }
                });
        if (!read) {
            if (read.error().code == ErrorCode::NotFound) {
                return makeError(ErrorCode::NotFound, fmt::format("{}: cannot read the scene file",
                                                                  (dir / name).string()));
            }
            return tl::unexpected(read.error());
        }
    }
    return fmt::format("{:016x}", h);
}

Expected<void> checkAndRecordDigest(std::string& recorded,
                                    const std::string& now,
                                    std::string_view what,
                                    const std::string& where)
{
    if (!recorded.empty() && recorded != now) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: the {} has changed since it was recorded (digest {}, "
                                     "recorded {}); replay needs the recorded {}: restore that "
                                     "file or folder to replay the recording as it was",
                                     where, what, now, recorded, what));
    }
    recorded = now;
    return {};
}

Expected<pipeline::booth::Booth> loadRunBooth(RunConfig& config)
{
    const auto dir = resolveSceneDir(config.boothDir);
    std::error_code ec;
    if (!std::filesystem::is_regular_file(dir / "booth.json", ec)) {
        return makeError(ErrorCode::NotFound,
                         fmt::format("{}: no booth.json there; name a booth folder as 'replica "
                                     "booth build' writes it (docs/booth-capture.md), e.g. {}",
                                     dir.string(), (dataDir() / "booth").string()));
    }
    auto digest = boothDigest(dir);
    if (!digest) {
        return tl::unexpected(digest.error());
    }
    if (auto same = checkAndRecordDigest(config.boothDigest, *digest, "booth", dir.string());
        !same) {
        return tl::unexpected(same.error());
    }
    return pipeline::scene::loadApplianceBooth(dir, dataDir().string());
}

std::string displayProfileId(const RunConfig& config, const std::string& profileName)
{
    if (config.display == kUncalibratedDisplay) {
        return fmt::format("{} (uncalibrated nominal model)", kUncalibratedDisplay);
    }
    return fmt::format("{} ({}, fnv1a64 {})", profileName, config.display, config.displayDigest);
}

std::string missingDisplayProfileMessage(const std::string& path)
{
    return fmt::format("no display profile at {}: characterise the panel ('replica display fit "
                       "MEAS.csv --out PROFILE') and pass --display-profile PROFILE, or run "
                       "--uncalibrated",
                       path);
}

} // namespace replica::platform
