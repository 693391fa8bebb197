// 'replica inspect': what a recording holds (devices, sample counts, time span).
#include <algorithm>
#include <cstdint>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <platform/cli/commands.h>
#include <platform/logging.h>
#include <recordings/recording.h>

namespace replica::platform {
namespace {

struct InspectOptions {
    std::string file;
    bool json = false;
};

template <typename Sample>
nlohmann::json streamJson(const hal::DeviceInfo& info, const std::vector<Sample>& samples)
{
    nlohmann::json j{{"model", info.model},
                     {"serial", info.serial},
                     {"firmware", info.firmware},
                     {"source", hal::toString(info.kind)},
                     {"count", samples.size()}};
    if (!samples.empty()) {
        j["first_ns"] = samples.front().timestampNs;
        j["last_ns"] = samples.back().timestampNs;
    }
    return j;
}

int inspectMain(const InspectOptions& o)
{
    auto rec = recordings::readRecording(o.file);
    if (!rec) {
        if (o.json) {
            fmt::print("{}\n", nlohmann::json{{"error", rec.error().message}}.dump());
        }
        logger("replica")->error("{}", rec.error().message);
        return kExitFailure;
    }
    std::int64_t first = INT64_MAX;
    std::int64_t last = INT64_MIN;
    auto span = [&](std::int64_t t) {
        first = std::min(first, t);
        last = std::max(last, t);
    };
    for (const auto& s : rec->spectra) {
        span(s.timestampNs);
    }
    for (const auto& s : rec->poses) {
        span(s.timestampNs);
    }
    for (const auto& s : rec->accel) {
        span(s.timestampNs);
    }
    for (const auto& f : rec->frames) {
        span(f.tickNs);
    }
    if (first > last) {
        first = last = 0;
    }
    nlohmann::json j{{"file", o.file},
                     {"format_version", rec->formatVersion},
                     {"software", rec->session.softwareVersion},
                     {"booth", rec->session.boothModel},
                     {"scene", rec->session.scene},
                     {"display_profile", rec->session.displayProfile},
                     {"spectrometer", streamJson(rec->session.spectrometer, rec->spectra)},
                     {"tracker", streamJson(rec->session.tracker, rec->poses)},
                     {"accel", streamJson(rec->session.accel, rec->accel)},
                     {"frames", rec->frames.size()},
                     {"dropped_messages", rec->droppedMessages},
                     {"first_ns", first},
                     {"last_ns", last},
                     {"duration_s", static_cast<double>(last - first) * 1e-9}};
    if (o.json) {
        fmt::print("{}\n", j.dump(2));
        return kExitOk;
    }
    fmt::print("{}: replica recording, format {}, written by {}\n", o.file, rec->formatVersion,
               rec->session.softwareVersion);
    fmt::print("  booth {}, scene {}, display profile {}\n", rec->session.boothModel,
               rec->session.scene, rec->session.displayProfile);
    auto line = [](const char* name, const hal::DeviceInfo& info, std::size_t count) {
        fmt::print("  {:<13} {:>7} samples  {} {} ({})\n", name, count, info.model, info.serial,
                   hal::toString(info.kind));
    };
    line("spectrometer", rec->session.spectrometer, rec->spectra.size());
    line("tracker", rec->session.tracker, rec->poses.size());
    line("accelerometer", rec->session.accel, rec->accel.size());
    fmt::print("  {:<13} {:>7} frames\n", "frames", rec->frames.size());
    fmt::print("  time span {:.3f} s ({} .. {} ns); dropped messages {}\n",
               static_cast<double>(last - first) * 1e-9, first, last, rec->droppedMessages);
    return kExitOk;
}

} // namespace

void registerInspectCommand(CLI::App& app, int& exitCode)
{
    auto opts = std::make_shared<InspectOptions>();
    auto* cmd = app.add_subcommand(
            "inspect", "print what a recording holds: devices, sample counts, time span");
    cmd->add_option("file", opts->file, "recording (.mcap)")->required();
    cmd->add_flag("--json", opts->json, "print the same as JSON");
    cmd->callback([opts, &exitCode] { exitCode = inspectMain(*opts); });
}

} // namespace replica::platform
