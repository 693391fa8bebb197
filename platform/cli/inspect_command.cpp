// 'replica inspect': what a recording holds (devices, sample counts, channels, time span) and any
// damage (then it exits non-zero).
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

nlohmann::json channelsJson(const recordings::FileReport& report)
{
    nlohmann::json channels = nlohmann::json::object();
    for (const auto& c : report.channels) {
        channels[c.topic] = {{"id", c.id},
                             {"schema", c.schemaName},
                             {"encoding", c.messageEncoding},
                             {"count", c.messages},
                             {"first_log_time_ns", c.firstLogTime},
                             {"last_log_time_ns", c.lastLogTime}};
    }
    return channels;
}

// A file that cannot be read as a sound recording: say what is wrong and what still scans.
int reportDamage(const InspectOptions& o,
                 const std::string& error,
                 const recordings::FileReport* report)
{
    if (o.json) {
        nlohmann::json j{{"file", o.file}, {"error", error}};
        if (report != nullptr) {
            j["damage"] = report->damage;
            j["damage_count"] = report->damageCount;
            j["channels"] = channelsJson(*report);
            j["chunks"] = report->chunks;
            j["messages"] = report->messages;
            j["indexed"] = report->indexed;
        }
        fmt::print("{}\n", j.dump(2));
    }
    logger("replica")->error("{}", error);
    if (report != nullptr && !o.json) {
        for (const auto& d : report->damage) {
            fmt::print("  damage: {}\n", d);
        }
        if (report->damageCount > report->damage.size()) {
            fmt::print("  ... and {} more\n", report->damageCount - report->damage.size());
        }
        fmt::print("  still readable: {} messages in {} intact chunks\n", report->messages,
                   report->chunks);
    }
    return kExitFailure;
}

int inspectMain(const InspectOptions& o)
{
    auto report = recordings::inspectRecording(o.file);
    if (!report) {
        return reportDamage(o, report.error().message, nullptr);
    }
    auto rec = recordings::readRecording(o.file);
    if (!rec) {
        return reportDamage(o, rec.error().message, &*report);
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
    for (const auto& s : rec->lampSelector) {
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
                     {"config", nlohmann::json::parse(rec->session.configJson, nullptr, false)},
                     {"booth", rec->session.boothModel},
                     {"scene", rec->session.scene},
                     {"display_profile", rec->session.displayProfile},
                     {"spectrometer", streamJson(rec->session.spectrometer, rec->spectra)},
                     {"tracker", streamJson(rec->session.tracker, rec->poses)},
                     {"accel", streamJson(rec->session.accel, rec->accel)},
                     {"lamp_selector", streamJson(rec->session.lampSelector, rec->lampSelector)},
                     {"frames", rec->frames.size()},
                     {"dropped_messages", rec->droppedMessages},
                     {"rejected_nonfinite", rec->rejectedNonFinite},
                     {"file_bytes", report->fileBytes},
                     {"library", report->library},
                     {"messages", report->messages},
                     {"chunks", report->chunks},
                     {"indexed", report->indexed},
                     {"damage", report->damage},
                     {"channels", channelsJson(*report)},
                     {"first_ns", first},
                     {"last_ns", last},
                     {"duration_s", static_cast<double>(last - first) * 1e-9}};
    // The last decoded sample of each stream, in the channels' own field names: lets independent
    // MCAP readers check decoded values, not just counts.
    if (!rec->spectra.empty()) {
        const auto& s = rec->spectra.back();
        j["spectrometer"]["last"] = {{"seq", s.sequence},
                                     {"integration_time_us", s.integrationTimeUs},
                                     {"counts", s.counts},
                                     {"wavelength_coeffs", s.wavelengthCoeffs},
                                     {"nonlinearity_coeffs", s.nonlinearityCoeffs}};
    }
    if (!rec->poses.empty()) {
        const auto& p = rec->poses.back();
        j["tracker"]["last"] = {
                {"seq", p.sequence},
                {"tracked", p.tracked},
                {"eye", {{"x", p.eyeTrackerM.x}, {"y", p.eyeTrackerM.y}, {"z", p.eyeTrackerM.z}}}};
    }
    if (!rec->accel.empty()) {
        const auto& a = rec->accel.back();
        j["accel"]["last"] = {
                {"seq", a.sequence},
                {"gravity", {{"x", a.gravity.x}, {"y", a.gravity.y}, {"z", a.gravity.z}}}};
    }
    if (!rec->lampSelector.empty()) {
        const auto& l = rec->lampSelector.back();
        std::vector<int> levels;
        for (std::uint32_t i = 0; i < l.lineCount; ++i) {
            levels.push_back((l.lineLevels >> i) & 1u ? 1 : 0);
        }
        j["lamp_selector"]["last"] = {{"seq", l.sequence},
                                      {"lamp", l.lamp},
                                      {"state", hal::lampStateName(l.lamp)},
                                      {"levels", levels}};
    }
    if (!rec->frames.empty()) {
        j["last_frame"] = {{"frame", rec->frames.back().frameIndex},
                           {"tick_ns", rec->frames.back().tickNs}};
    }
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
    if (!rec->session.lampSelector.model.empty() || !rec->lampSelector.empty()) {
        line("lamp selector", rec->session.lampSelector, rec->lampSelector.size());
    }
    fmt::print("  {:<13} {:>7} frames\n", "frames", rec->frames.size());
    fmt::print("  time span {:.3f} s ({} .. {} ns); dropped messages {}, rejected (NaN/inf) {}\n",
               static_cast<double>(last - first) * 1e-9, first, last, rec->droppedMessages,
               rec->rejectedNonFinite);
    fmt::print("  {} bytes, {} messages in {} chunks, {}; no damage found\n", report->fileBytes,
               report->messages, report->chunks, report->indexed ? "indexed" : "not indexed");
    for (const auto& c : report->channels) {
        fmt::print("  channel {:>2} {:<20} {:>7} messages  {} ({})\n", c.id, c.topic, c.messages,
                   c.schemaName, c.messageEncoding);
    }
    return kExitOk;
}

} // namespace

void registerInspectCommand(CLI::App& app, int& exitCode)
{
    auto opts = std::make_shared<InspectOptions>();
    auto* cmd = app.add_subcommand(
            "inspect",
            "print what a recording holds: devices, sample counts per channel, time span, and any "
            "damage (exit 1 if damaged)");
    cmd->add_option("file", opts->file, "recording (.mcap)")->required();
    cmd->add_flag("--json", opts->json, "print the same as JSON");
    cmd->callback([opts, &exitCode] { exitCode = inspectMain(*opts); });
}

} // namespace replica::platform
