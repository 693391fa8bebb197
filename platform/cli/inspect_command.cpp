// 'replica inspect': what a recording holds (devices, sample counts, channels, time span) and any
// damage (then it exits non-zero).
#include <algorithm>
#include <cstdint>
#include <ctime>
#include <string>
#include <string_view>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <pipeline/base/printable.h>
#include <platform/cli/commands.h>
#include <platform/logging.h>
#include <recordings/recording.h>

namespace replica::platform {
namespace {

// Text from a recording is untrusted: shown escaped, a field cut at 'max' characters.
std::string shown(std::string_view s, std::size_t max = 200)
{
    return printable(s, max);
}

struct InspectOptions {
    std::string file;
    bool json = false;
};

// Unix time (ns) as ISO 8601 UTC with milliseconds.
std::string isoUtc(std::int64_t unixNs)
{
    const std::time_t secs = static_cast<std::time_t>(unixNs / 1'000'000'000);
    std::tm tm{};
    if (unixNs <= 0 || ::gmtime_r(&secs, &tm) == nullptr) {
        return "unknown";
    }
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%S", &tm);
    return fmt::format("{}.{:03d}Z", buf, static_cast<int>((unixNs / 1'000'000) % 1000));
}

// The lamp timeline: what the appliance decided (format 4's /replica/light), and the booth's
// selector switch where there is one.
nlohmann::json lampTimeline(const recordings::Recording& rec)
{
    nlohmann::json out = nlohmann::json::array();
    for (const auto& l : rec.lights) {
        nlohmann::json e{{"t_s", static_cast<double>(l.tNs) * 1e-9},
                         {"source", "decided"},
                         {"mode", l.mode},
                         {"lamp", l.lamp},
                         {"name", l.name},
                         {"why", l.why}};
        if (l.cctK) {
            e["cct_k"] = *l.cctK;
        }
        out.push_back(e);
    }
    for (const auto& s : rec.samples(recordings::lampSelectorKind())) {
        out.push_back({{"t_s", static_cast<double>(s.timestampNs) * 1e-9},
                       {"source", "selector"},
                       {"lamp", s.lamp},
                       {"state", hal::lampStateName(s.lamp)}});
    }
    std::stable_sort(out.begin(), out.end(), [](const auto& a, const auto& b) {
        return a.at("t_s").template get<double>() < b.at("t_s").template get<double>();
    });
    return out;
}

nlohmann::json streamJson(const recordings::Recording& rec, const recordings::DeviceKindBase& kind)
{
    const auto& info = rec.session.device(kind);
    const std::size_t count = rec.count(kind);
    nlohmann::json j{{"model", info.model},
                     {"serial", info.serial},
                     {"firmware", info.firmware},
                     {"source", hal::toString(info.kind)},
                     {"count", count}};
    if (count > 0) {
        const auto& samples = *rec.samplesOf(kind);
        const auto t = kind.times(samples);
        j["first_ns"] = t.front();
        j["last_ns"] = t.back();
        // The last decoded sample, as its channel's message (its own field names): lets
        // independent MCAP readers check decoded values, not just counts.
        if (auto last = kind.encodeAt(samples, count - 1)) {
            j["last"] = nlohmann::json::parse(*last);
        }
    }
    return j;
}

// What a kind's samples are called: its own word ("poses"), else its name ("accel").
std::string samplesKey(const recordings::DeviceKindBase& kind)
{
    return kind.names().samplesNoun != "samples" ? kind.names().samplesNoun : kind.name();
}

// Format 5: how many samples carry the device's raw input (/replica/raw/*), for each device kind
// with a raw channel.
nlohmann::json rawInputsJson(const recordings::Recording& rec)
{
    nlohmann::json j{{"unmatched", rec.unmatchedRaw}};
    for (const auto* kind : recordings::deviceKinds()) {
        if (kind->names().rawChannel) {
            const auto* samples = rec.samplesOf(*kind);
            j[samplesKey(*kind)] = samples != nullptr ? kind->countWithRaw(*samples) : 0;
        }
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
        fmt::print("{}\n", j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace));
    }
    logger("replica")->error("{}", error);
    if (report != nullptr && !o.json) {
        for (const auto& d : report->damage) {
            fmt::print("  damage: {}\n", shown(d, 2000));
        }
        if (report->damageCount > report->damage.size()) {
            fmt::print("  ... and {} more\n", report->damageCount - report->damage.size());
        }
        fmt::print("  still readable: {} messages in {} intact chunks\n", report->messages,
                   report->chunks);
    }
    return kExitFailure;
}

// The session time the recording spans: its first and last sample or frame (0, 0 when empty).
struct TimeSpan {
    std::int64_t first = INT64_MAX;
    std::int64_t last = INT64_MIN;
    double seconds() const { return static_cast<double>(last - first) * 1e-9; }
};

TimeSpan timeSpan(const recordings::Recording& rec)
{
    TimeSpan s;
    auto span = [&](std::int64_t t) {
        s.first = std::min(s.first, t);
        s.last = std::max(s.last, t);
    };
    for (const auto& [kind, samples] : rec.devices) {
        for (const auto t : kind->times(samples)) {
            span(t);
        }
    }
    for (const auto& f : rec.frames) {
        span(f.tickNs);
    }
    if (s.first > s.last) {
        s.first = s.last = 0;
    }
    return s;
}

nlohmann::json inspectJson(const InspectOptions& o,
                           const recordings::Recording& rec,
                           const recordings::FileReport& report,
                           const TimeSpan& span)
{
    nlohmann::json j{{"file", o.file},
                     {"format_version", rec.formatVersion},
                     {"software", rec.session.softwareVersion},
                     {"config", nlohmann::json::parse(rec.session.configJson, nullptr, false)},
                     {"booth", rec.session.boothModel},
                     {"scene", rec.session.scene},
                     {"display_profile", rec.session.displayProfile},
                     {"wall_clock_start_ns", rec.session.wallClockStartNs},
                     {"wall_clock_start", isoUtc(rec.session.wallClockStartNs)},
                     {"lamp_timeline", lampTimeline(rec)},
                     {"display_digests", rec.displayDigests.size()},
                     {"raw_inputs", rawInputsJson(rec)},
                     {"frames", rec.frames.size()},
                     {"dropped_messages", rec.droppedMessages},
                     {"rejected_nonfinite", rec.rejectedNonFinite},
                     {"file_bytes", report.fileBytes},
                     {"library", report.library},
                     {"messages", report.messages},
                     {"chunks", report.chunks},
                     {"indexed", report.indexed},
                     {"damage", report.damage},
                     {"channels", channelsJson(report)},
                     {"first_ns", span.first},
                     {"last_ns", span.last},
                     {"duration_s", span.seconds()}};
    for (const auto* kind : recordings::deviceKinds()) {
        j[kind->name()] = streamJson(rec, *kind);
    }
    if (!rec.frames.empty()) {
        j["last_frame"] = {{"frame", rec.frames.back().frameIndex},
                           {"tick_ns", rec.frames.back().tickNs}};
    }
    return j;
}

void printLampTimeline(const recordings::Recording& rec)
{
    const auto timeline = lampTimeline(rec);
    if (timeline.empty()) {
        fmt::print("  lamp timeline: none recorded (no selector{})\n",
                   rec.formatVersion < 4 ? "; format < 4 records no decided light" : "");
        return;
    }
    fmt::print("  lamp timeline:\n");
    for (const auto& e : timeline) {
        const double t = e.at("t_s").get<double>();
        if (e.at("source") == "decided") {
            fmt::print("    {:9.3f} s  shown: {}{} ({})\n", t,
                       shown(e.at("name").get<std::string>()),
                       e.contains("cct_k") ? fmt::format(", {:.0f} K", e.at("cct_k").get<double>())
                                           : std::string(),
                       shown(e.at("why").get<std::string>()));
        } else {
            fmt::print("    {:9.3f} s  selector: {} ({})\n", t, e.at("lamp").get<int>(),
                       shown(e.at("state").get<std::string>()));
        }
    }
}

// Every device kind (an optional one only when the session had it), and the raw inputs kept.
void printDevices(const recordings::Recording& rec)
{
    auto line = [](const char* name, const hal::DeviceInfo& info, std::size_t count) {
        fmt::print("  {:<13} {:>7} samples  {} {} ({})\n", name, count, shown(info.model),
                   shown(info.serial), hal::toString(info.kind));
    };
    const auto raw = rawInputsJson(rec);
    std::string rawCounts;
    for (const auto* kind : recordings::deviceKinds()) {
        const auto& info = rec.session.device(*kind);
        const std::size_t count = rec.count(*kind);
        if (!kind->names().optional || !info.model.empty() || count > 0) {
            line(kind->names().displayName.c_str(), info, count);
        }
        if (kind->names().rawChannel) {
            const auto& noun = kind->names().samplesNoun;
            rawCounts +=
                    fmt::format("{}{} of {} {}", rawCounts.empty() ? "" : ", ",
                                raw.at(samplesKey(*kind)).get<std::size_t>(), count,
                                noun != "samples" ? noun : kind->names().displayName + " samples");
        }
    }
    fmt::print("  raw inputs    {}{} ('replay --reprocess' re-derives them)\n", rawCounts,
               rec.unmatchedRaw > 0
                       ? fmt::format("; {} without their sample (dropped)", rec.unmatchedRaw)
                       : std::string());
}

void printInspection(const InspectOptions& o,
                     const recordings::Recording& rec,
                     const recordings::FileReport& report,
                     const TimeSpan& span)
{
    fmt::print("{}: replica recording, format {}, written by {}\n", o.file, rec.formatVersion,
               shown(rec.session.softwareVersion));
    fmt::print("  started {} (UTC), {:.3f} s of session time\n",
               isoUtc(rec.session.wallClockStartNs), span.seconds());
    fmt::print("  booth {}, scene {}, display profile {}\n", shown(rec.session.boothModel),
               shown(rec.session.scene), shown(rec.session.displayProfile));
    printLampTimeline(rec);
    printDevices(rec);
    fmt::print("  {:<13} {:>7} frames\n", "frames", rec.frames.size());
    fmt::print("  time span {:.3f} s ({} .. {} ns); dropped messages {}, rejected (NaN/inf) {}\n",
               span.seconds(), span.first, span.last, rec.droppedMessages, rec.rejectedNonFinite);
    fmt::print("  {} bytes, {} messages in {} chunks, {}; no damage found\n", report.fileBytes,
               report.messages, report.chunks, report.indexed ? "indexed" : "not indexed");
    for (const auto& c : report.channels) {
        fmt::print("  channel {:>2} {:<20} {:>7} messages  {} ({})\n", c.id, shown(c.topic),
                   c.messages, shown(c.schemaName), shown(c.messageEncoding));
    }
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
    const TimeSpan span = timeSpan(*rec);
    if (o.json) {
        const auto j = inspectJson(o, *rec, *report, span);
        fmt::print("{}\n", j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace));
        return kExitOk;
    }
    printInspection(o, *rec, *report, span);
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
    auto files = std::make_shared<std::vector<std::string>>();
    cmd->add_option("files", *files, "recordings (.mcap), one or more")->required();
    cmd->add_flag("--json", opts->json,
                  "print the same as JSON (one object; an array of them for several files)");
    cmd->callback([opts, files, &exitCode] {
        // Several files: each in turn (a JSON array with --json); the exit code is the worst.
        exitCode = kExitOk;
        if (opts->json && files->size() > 1) {
            fmt::print("[\n");
        }
        for (std::size_t i = 0; i < files->size(); ++i) {
            InspectOptions one = *opts;
            one.file = (*files)[i];
            if (i > 0) {
                fmt::print("{}", opts->json ? ",\n" : "\n");
            }
            exitCode = std::max(exitCode, inspectMain(one));
        }
        if (opts->json && files->size() > 1) {
            fmt::print("]\n");
        }
    });
}

} // namespace replica::platform
