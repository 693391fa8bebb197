// Reading recordings of every known format version (1: unchunked, 2: chunked, 3: lamp selector,
// 4: what was shown; of its channels replay reads the display digests and the thumbnails) and
// inspecting files.
#include <algorithm>
#include <fstream>
#include <iterator>
#include <map>

#include <fmt/format.h>

#include <pipeline/base/input_file.h>
#include <pipeline/base/json_limits.h>
#include <recordings/mcap/reader.h>
#include <recordings/recording.h>
#include <recordings/sample_codec.h>
#include <recordings/session_schema.h>

namespace replica::recordings {
namespace {

Expected<std::string> slurp(const std::filesystem::path& path)
{
    // A regular file (not a directory, FIFO or /dev/zero) of at most kMaxRecordingBytes, read
    // whole: the scan below then bounds what it decompresses by the file's size.
    auto bytes = readInputFile(path, kMaxRecordingBytes, "recording");
    if (!bytes) {
        if (bytes.error().code == ErrorCode::NotFound) {
            return makeError(ErrorCode::NotFound,
                             fmt::format("{}: no such recording", path.string()));
        }
        return tl::unexpected(bytes.error());
    }
    if (bytes->empty()) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: file is empty, not a recording", path.string()));
    }
    return bytes;
}

// A format this build reads, or one line saying it is newer.
Expected<void> checkFormatVersion(const std::string& name, int formatVersion)
{
    if (formatVersion < 1 || formatVersion > kFormatVersion) {
        return makeError(ErrorCode::Unsupported,
                         fmt::format("{}: recording format {} is newer than this replica reads "
                                     "(up to {}); update replica",
                                     name, formatVersion, kFormatVersion));
    }
    return {};
}

// One session per recording: a second /replica/session channel or message would change the
// configuration (the frame size, the scene) part way through the file, whichever came last.
Expected<void> checkOneSession(const mcap::Scan& s, const std::string& name)
{
    std::vector<std::uint16_t> ids;
    for (const auto& [id, channel] : s.channels) {
        if (channel.topic == kSessionTopic) {
            ids.push_back(id);
        }
    }
    if (ids.size() > 1) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: {} channels carry {} (ids {} and {}); a recording has "
                                     "one session: not a recording Replica wrote",
                                     name, ids.size(), kSessionTopic, ids[0], ids[1]));
    }
    const auto sessions = std::count_if(s.messages.begin(), s.messages.end(), [&](const auto& m) {
        return !ids.empty() && m.channelId == ids[0];
    });
    if (sessions > 1) {
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: {} {} messages; a recording has one session: not a "
                                     "recording Replica wrote",
                                     name, sessions, kSessionTopic));
    }
    return {};
}

// A thumbnail message (foxglove.CompressedImage): its PNG, tNs its Unix time until
// placeThumbnails.
ThumbnailRecord decodeThumbnailMessage(const nlohmann::json& j)
{
    ThumbnailRecord t;
    t.tNs = j.at("timestamp").at("sec").get<std::int64_t>() * 1'000'000'000 +
            j.at("timestamp").at("nsec").get<std::int64_t>();
    t.png = base64Decode(j.at("data").get<std::string>());
    return t;
}

// A thumbnail's time is its frame's tick after the session's wall-clock start.
void placeThumbnails(Recording& rec)
{
    std::map<std::int64_t, std::uint64_t> frameAtTick;
    for (const FrameRecord& f : rec.frames) {
        frameAtTick.emplace(f.tickNs, f.frameIndex);
    }
    for (ThumbnailRecord& t : rec.thumbnails) {
        t.tNs -= rec.session.wallClockStartNs;
        const auto it = frameAtTick.find(t.tNs);
        t.frameIndex = it != frameAtTick.end() ? it->second : 0;
    }
}

} // namespace

Expected<Recording> readRecording(const std::filesystem::path& path, const DeviceKinds& kinds)
{
    const std::string name = path.string();
    auto bytes = slurp(path);
    if (!bytes) {
        return tl::unexpected(bytes.error());
    }
    const auto s = mcap::scan(*bytes);
    if (!s.damage.empty()) {
        if (s.damage.front().starts_with("not an MCAP file")) {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("{}: not an MCAP recording (bad magic bytes)", name));
        }
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: damaged recording: {}{}; 'replica recover {} OUT' "
                                     "rebuilds what is intact",
                                     name, s.damage.front(),
                                     s.damageCount > 1 ? fmt::format(" (and {} more problems)",
                                                                     s.damageCount - 1)
                                                       : "",
                                     name));
    }
    if (auto ok = checkOneSession(s, name); !ok) {
        return tl::unexpected(ok.error());
    }
    Recording rec;
    bool haveSession = false;
    // Each device kind's samples, by its topic; format 5: its raw inputs, by its raw topic,
    // attached to their samples by sequence number once all are read.
    std::map<std::string, std::size_t> sampleTopics, rawTopics;
    std::vector<std::any> rawState(kinds.size());
    for (std::size_t i = 0; i < kinds.size(); ++i) {
        const auto& n = kinds[i]->names();
        rec.devices[n.name] = kinds[i]->emptySamples();
        sampleTopics[n.channel.topic] = i;
        if (n.rawChannel) {
            rawTopics[n.rawChannel->topic] = i;
        }
    }
    std::uint64_t unusableRaw = 0;
    for (const auto& m : s.messages) {
        const std::string& topic = s.channels.at(m.channelId).topic;
        if (m.data.size() > kMaxMessageBytes) {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("{}: {} message (sequence {}) of {} bytes; Replica's are "
                                         "at most {} KiB: not a recording Replica wrote",
                                         name, topic, m.sequence, m.data.size(),
                                         kMaxMessageBytes >> 10));
        }
        if (auto ok = checkJsonLimits(
                    m.data, fmt::format("{}: {} message (sequence {})", name, topic, m.sequence));
            !ok) {
            return tl::unexpected(ok.error());
        }
        try {
            const auto j = nlohmann::json::parse(m.data);
            if (topic == kSessionTopic) {
                if (auto ok = validateJson(j, sessionSchema(),
                                           fmt::format("{}: {} message", name, topic));
                    !ok) {
                    return tl::unexpected(ok.error());
                }
                rec.session = decodeSession(j, rec.formatVersion, kinds);
                // The run configuration is JSON inside the session's JSON: held to the same
                // limits before anything (replay, inspect --json) parses it.
                if (auto ok = checkJsonLimits(rec.session.configJson,
                                              fmt::format("{}: run configuration", name));
                    !ok) {
                    return tl::unexpected(ok.error());
                }
                haveSession = true;
            } else if (auto k = sampleTopics.find(topic); k != sampleTopics.end()) {
                const auto* kind = kinds[k->second];
                kind->decode(j, rec.devices[kind->name()]);
            } else if (auto rk = rawTopics.find(topic); rk != rawTopics.end()) { // format 5
                if (!kinds[rk->second]->decodeRaw(j, rawState[rk->second])) {
                    ++unusableRaw;
                }
            } else if (topic == kFrameTopic) {
                rec.frames.push_back(decodeFrame(j, kinds));
            } else if (topic == kDisplayDigestTopic) { // format 4
                rec.displayDigests.push_back(decodeDisplayDigest(j));
            } else if (topic == kLightTopic) { // format 4
                rec.lights.push_back(decodeLight(j));
            } else if (topic == kThumbnailTopic) { // format 4
                rec.thumbnails.push_back(decodeThumbnailMessage(j));
            } else if (topic == kRecorderTopic) {
                const auto r = decodeRecorderStatus(j, kinds);
                rec.droppedMessages = r.droppedTotal();
                rec.rejectedNonFinite = r.rejectedNonFinite;
            }
        } catch (const std::exception& e) {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("{}: damaged {} message (sequence {}): {}", name, topic,
                                         m.sequence, e.what()));
        }
    }
    if (!haveSession) {
        return makeError(
                ErrorCode::Corrupt,
                fmt::format("{}: MCAP file without a replica session; not a replica recording",
                            name));
    }
    if (auto ok = checkFormatVersion(name, rec.formatVersion); !ok) {
        return tl::unexpected(ok.error());
    }
    placeThumbnails(rec);
    rec.unmatchedRaw = unusableRaw;
    for (std::size_t i = 0; i < kinds.size(); ++i) {
        if (rawState[i].has_value()) {
            rec.unmatchedRaw += kinds[i]->attachRaw(rec.devices[kinds[i]->name()], rawState[i]);
        }
    }
    return rec;
}

Expected<FileReport> inspectRecording(const std::filesystem::path& path)
{
    auto bytes = slurp(path);
    if (!bytes) {
        return tl::unexpected(bytes.error());
    }
    const auto s = mcap::scan(*bytes);
    FileReport r;
    r.fileBytes = bytes->size();
    r.library = s.library;
    r.messages = s.messages.size();
    r.chunks = s.chunks.size();
    r.indexed = s.summary;
    r.damage = s.damage;
    r.damageCount = s.damageCount;
    std::map<std::uint16_t, ChannelReport> channels;
    for (const auto& [id, c] : s.channels) {
        auto& cr = channels[id];
        cr.id = id;
        cr.topic = c.topic;
        cr.messageEncoding = c.messageEncoding;
        if (auto it = s.schemas.find(c.schemaId); it != s.schemas.end()) {
            cr.schemaName = it->second.name;
        }
    }
    for (const auto& m : s.messages) {
        auto& cr = channels[m.channelId];
        if (cr.messages == 0 || m.logTime < cr.firstLogTime) {
            cr.firstLogTime = m.logTime;
        }
        cr.lastLogTime = std::max(cr.lastLogTime, m.logTime);
        ++cr.messages;
    }
    for (auto& [id, cr] : channels) {
        r.channels.push_back(std::move(cr));
    }
    return r;
}

} // namespace replica::recordings
