// Reading recordings of every known format version (1: unchunked, 2: chunked, 3: lamp selector,
// 4: what was shown; of its channels replay reads the display digests and the thumbnails) and
// inspecting files.
#include <algorithm>
#include <fstream>
#include <iterator>
#include <map>

#include <fmt/format.h>

#include <pipeline/base/input_file.h>
#include <recordings/mcap/reader.h>
#include <recordings/message_decoder.h>
#include <recordings/recording.h>
#include <recordings/sample_codec.h>

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
    detail::MessageDecoder decoder(rec, kinds, name);
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

} // namespace replica::recordings
