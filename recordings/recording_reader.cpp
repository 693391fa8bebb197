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

// A scan with damage, or of a file that is not one session, is refused before decoding.
Expected<void> checkScan(const mcap::Scan& s, const std::string& name)
{
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
    return checkOneSession(s, name);
}

// Decodes a recording's messages into 'rec' by topic: the session, each device kind's samples by
// its topic and (format 5) its raw inputs by its raw topic, attached to their samples by sequence
// number once all are read.
class MessageDecoder
{
public:
    MessageDecoder(Recording& rec, const DeviceKinds& kinds, std::string name)
        : rec_(rec), kinds_(kinds), name_(std::move(name))
    {
        rec.devices.clear();
        for (std::size_t i = 0; i < kinds.size(); ++i) {
            const auto& n = kinds[i]->names();
            rec.devices.push_back({kinds[i], kinds[i]->emptySamples()});
            rawState_.push_back(kinds[i]->readerState());
            sampleTopics_[n.channel.topic] = i;
            if (n.rawChannel) {
                rawTopics_[n.rawChannel->topic] = i;
            }
        }
    }

    Expected<void> decode(const std::string& topic, const mcap::Message& m)
    {
        if (m.data.size() > kMaxMessageBytes) {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("{}: {} message (sequence {}) of {} bytes; Replica's are "
                                         "at most {} KiB: not a recording Replica wrote",
                                         name_, topic, m.sequence, m.data.size(),
                                         kMaxMessageBytes >> 10));
        }
        if (auto ok = checkJsonLimits(
                    m.data, fmt::format("{}: {} message (sequence {})", name_, topic, m.sequence));
            !ok) {
            return ok;
        }
        try {
            return decodeJson(topic, nlohmann::json::parse(m.data));
        } catch (const std::exception& e) {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("{}: damaged {} message (sequence {}): {}", name_, topic,
                                         m.sequence, e.what()));
        }
    }

    bool haveSession() const { return haveSession_; }

    // The raw inputs attached to their samples; those that matched none are counted.
    void attachRaw()
    {
        rec_.unmatchedRaw = unusableRaw_;
        for (std::size_t i = 0; i < kinds_.size(); ++i) {
            rec_.unmatchedRaw += kinds_[i]->attachRaw(rec_.devices[i].samples, rawState_[i]);
        }
    }

private:
    Expected<void> decodeSessionMessage(const std::string& topic, const nlohmann::json& j)
    {
        if (auto ok = validateJson(j, sessionSchema(), fmt::format("{}: {} message", name_, topic));
            !ok) {
            return ok;
        }
        rec_.session = decodeSession(j, rec_.formatVersion, kinds_);
        // The run configuration is JSON inside the session's JSON: held to the same limits
        // before anything (replay, inspect --json) parses it.
        if (auto ok = checkJsonLimits(rec_.session.configJson,
                                      fmt::format("{}: run configuration", name_));
            !ok) {
            return ok;
        }
        haveSession_ = true;
        return {};
    }

    Expected<void> decodeJson(const std::string& topic, const nlohmann::json& j)
    {
        if (topic == kSessionTopic) {
            return decodeSessionMessage(topic, j);
        }
        if (auto k = sampleTopics_.find(topic); k != sampleTopics_.end()) {
            kinds_[k->second]->decode(j, rec_.devices[k->second].samples);
        } else if (auto rk = rawTopics_.find(topic); rk != rawTopics_.end()) { // format 5
            if (!kinds_[rk->second]->decodeRaw(j, rawState_[rk->second])) {
                ++unusableRaw_;
            }
        } else if (topic == kFrameTopic) {
            rec_.frames.push_back(decodeFrame(j, kinds_));
        } else if (topic == kDisplayDigestTopic) { // format 4
            rec_.displayDigests.push_back(decodeDisplayDigest(j));
        } else if (topic == kLightTopic) { // format 4
            rec_.lights.push_back(decodeLight(j));
        } else if (topic == kThumbnailTopic) { // format 4
            rec_.thumbnails.push_back(decodeThumbnailMessage(j));
        } else if (topic == kRecorderTopic) {
            const auto r = decodeRecorderStatus(j, kinds_);
            rec_.droppedMessages = r.droppedTotal();
            rec_.rejectedNonFinite = r.rejectedNonFinite;
        }
        return {};
    }

    Recording& rec_;
    const DeviceKinds& kinds_;
    std::string name_;
    std::map<std::string, std::size_t> sampleTopics_, rawTopics_;
    std::vector<AnyReaderState> rawState_; // in the kinds' order, as rec_.devices
    std::uint64_t unusableRaw_ = 0;
    bool haveSession_ = false;
};

} // namespace

Expected<Recording> readRecording(const std::filesystem::path& path, const DeviceKinds& kinds)
{
    const std::string name = path.string();
    auto bytes = slurp(path);
    if (!bytes) {
        return tl::unexpected(bytes.error());
    }
    const auto s = mcap::scan(*bytes);
    if (auto ok = checkScan(s, name); !ok) {
        return tl::unexpected(ok.error());
    }
    Recording rec;
    MessageDecoder decoder(rec, kinds, name);
    for (const auto& m : s.messages) {
        if (auto ok = decoder.decode(s.channels.at(m.channelId).topic, m); !ok) {
            return tl::unexpected(ok.error());
        }
    }
    if (!decoder.haveSession()) {
        return makeError(
                ErrorCode::Corrupt,
                fmt::format("{}: MCAP file without a replica session; not a replica recording",
                            name));
    }
    if (auto ok = checkFormatVersion(name, rec.formatVersion); !ok) {
        return tl::unexpected(ok.error());
    }
    placeThumbnails(rec);
    decoder.attachRaw();
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
