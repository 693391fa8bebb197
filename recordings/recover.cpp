// Recovery: a resynchronising linear scan, then a fresh writer for everything that survived.
#include <algorithm>
#include <fstream>
#include <iterator>
#include <set>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <pipeline/base/input_file.h>
#include <recordings/mcap/reader.h>
#include <recordings/mcap/writer.h>
#include <recordings/recover.h>
#include <recordings/sample_codec.h>

namespace replica::recordings {

Expected<RecoverReport> recoverRecording(const std::filesystem::path& in,
                                         const std::filesystem::path& out)
{
    std::error_code ec;
    if (!std::filesystem::is_regular_file(in, ec)) {
        return makeError(ErrorCode::NotFound,
                         fmt::format("{}: no such recording (or not a regular file)", in.string()));
    }
    std::error_code ec2;
    if (std::filesystem::equivalent(in, out, ec2)) {
        return makeError(
                ErrorCode::InvalidArgument,
                fmt::format("{}: recover writes a new file; give a different OUT", out.string()));
    }
    auto read = readInputFile(in, kMaxRecordingBytes, "recording");
    if (!read) {
        return tl::unexpected(read.error());
    }
    const std::string& bytes = *read;
    mcap::ScanOptions options;
    options.resync = true;
    options.maxDamageReports = 50;
    options.chunkedOnly = true; // the writer chunks every record that carries samples
    // Replica's channel ids are fixed per format version: a file whose first chunk (the channel
    // definitions) was lost can still have its samples recovered.
    // Each format only added channels (3: id 7, 4: ids 8-13, 5: ids 14-15), so today's
    // definitions serve every chunked format (2 and later) as well.
    const auto probe = bytes.substr(0, 256);
    bool knownFormat = false;
    for (int v = 2; v <= kFormatVersion; ++v) {
        knownFormat = knownFormat || probe.find(fmt::format("(format {})", v)) != std::string::npos;
    }
    if (knownFormat) {
        for (const auto& d : channelDefinitions()) {
            options.fallbackChannels[d.channel.id] = d.channel;
            options.fallbackSchemas[d.schema.id] = d.schema;
        }
    }
    auto s = mcap::scan(bytes, options);
    // The session message lives in the first chunk; if that chunk was lost, restore it from the
    // copy in the replica.session Metadata record.
    const auto sessionId = static_cast<std::uint16_t>(ChannelId::Session);
    const bool haveSession = std::any_of(s.messages.begin(), s.messages.end(),
                                         [&](const auto& m) { return m.channelId == sessionId; });
    bool sessionRestored = false;
    if (!haveSession && !s.messages.empty() && options.fallbackChannels.contains(sessionId)) {
        for (const auto& md : s.metadata) {
            auto it = md.metadata.find("session");
            if (md.name != kSessionMetadataName || it == md.metadata.end()) {
                continue;
            }
            std::uint64_t t = 0;
            try {
                const auto j = nlohmann::json::parse(it->second);
                t = static_cast<std::uint64_t>(
                        std::max<std::int64_t>(0, j.at("wall_clock_start_ns").get<std::int64_t>()));
            } catch (const std::exception&) {
                break; // not a usable session description
            }
            const auto& def = options.fallbackChannels.at(sessionId);
            if (!s.channels.contains(sessionId)) {
                s.channels.emplace(sessionId, def);
                s.schemas.emplace(def.schemaId, options.fallbackSchemas.at(def.schemaId));
                s.channelsAssumed.push_back(sessionId);
            }
            s.messages.insert(s.messages.begin(), mcap::Message{sessionId, 0, t, t, it->second});
            sessionRestored = true;
            break;
        }
    }
    if (s.messages.empty()) {
        return makeError(
                ErrorCode::Corrupt,
                fmt::format("{}: nothing recoverable: {}", in.string(),
                            s.damage.empty() ? "the file holds no messages" : s.damage.front()));
    }
    RecoverReport r;
    r.problems = s.damage;
    if (s.damageCount > s.damage.size()) {
        r.problems.push_back(
                fmt::format("... and {} more problems", s.damageCount - s.damage.size()));
    }
    r.messagesKept = s.messages.size();
    r.chunksKept = s.chunks.size();
    r.chunksDamaged = s.chunksDamaged;
    r.bytesDropped = s.bytesSkipped;
    r.messagesDropped = s.messagesDropped;
    if (s.summaryMessageCount && *s.summaryMessageCount > s.messages.size()) {
        r.messagesDropped += *s.summaryMessageCount - s.messages.size();
    }
    r.channelsAssumed = s.channelsAssumed;
    r.sessionRestored = sessionRestored;

    auto w = mcap::FileWriter::create(out, s.library.empty() ? "replica recover" : s.library);
    if (!w) {
        return tl::unexpected(w.error());
    }
    for (const auto& md : s.metadata) {
        if (auto ok = (*w)->addMetadata(md); !ok) {
            return tl::unexpected(ok.error());
        }
    }
    std::set<std::uint16_t> schemasUsed;
    for (const auto& [id, c] : s.channels) {
        schemasUsed.insert(c.schemaId);
    }
    for (const auto& [id, schema] : s.schemas) {
        if (schemasUsed.contains(id)) {
            (*w)->addSchema(schema);
        }
    }
    for (const auto& [id, c] : s.channels) {
        (*w)->addChannel(c);
    }
    constexpr std::size_t kChunkBytes = 256 * 1024;
    for (const auto& m : s.messages) {
        (*w)->addMessage(m);
        if ((*w)->pendingBytes() >= kChunkBytes) {
            if (auto ok = (*w)->closeChunk(false); !ok) {
                return tl::unexpected(ok.error());
            }
        }
    }
    if (auto ok = (*w)->finish(); !ok) {
        return tl::unexpected(ok.error());
    }
    return r;
}

} // namespace replica::recordings
