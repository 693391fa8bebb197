// Recovery: a resynchronising linear scan, then a fresh writer for everything that survived.
#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <optional>
#include <random>
#include <set>

#include <fcntl.h>
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include <pipeline/base/input_file.h>
#include <pipeline/base/json_limits.h>
#include <recordings/mcap/reader.h>
#include <recordings/mcap/writer.h>
#include <recordings/message_decoder.h>
#include <recordings/recover.h>
#include <recordings/sample_codec.h>

namespace replica::recordings {
namespace {

namespace fs = std::filesystem;

// Everything about OUT that can be refused before the input is read.
Expected<void> checkOutput(const fs::path& in, const fs::path& out, ExistingOutput existing)
{
    const std::string name = out.string();
    std::error_code ec;
    const auto st = fs::symlink_status(out, ec);
    if (ec && ec != std::errc::no_such_file_or_directory) {
        return makeError(ErrorCode::Io,
                         fmt::format("{}: cannot check the output: {}", name, ec.message()));
    }
    if (fs::exists(st)) {
        if (fs::is_symlink(st)) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("{}: is a symbolic link; recover never writes through "
                                         "or replaces one: name the file itself",
                                         name));
        }
        std::error_code same;
        if (fs::equivalent(in, out, same)) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("{}: is the input itself; recover writes a new file: "
                                         "give a different OUT",
                                         name));
        }
        if (!fs::is_regular_file(st)) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("{}: exists and is not a regular file (a directory or "
                                         "device); name a new file",
                                         name));
        }
        if (existing == ExistingOutput::Refuse) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("{}: already exists; pass --force to replace it, or "
                                         "name a new file",
                                         name));
        }
    }
    const fs::path dir = out.parent_path().empty() ? fs::path(".") : out.parent_path();
    if (!fs::is_directory(dir, ec)) {
        return makeError(ErrorCode::NotFound,
                         fmt::format("{}: the folder {} does not exist; create it or name another "
                                     "OUT",
                                     name, dir.string()));
    }
    return {};
}

// A new, empty file beside `out` (same folder, so the rename cannot cross file systems), created
// exclusively and never through a link.
Expected<fs::path> createTemporaryBeside(const fs::path& out)
{
    std::random_device entropy;
    for (int attempt = 0; attempt < 16; ++attempt) {
        fs::path tmp = out;
        tmp.replace_filename(fmt::format(".{}.recover-{}-{:08x}", out.filename().string(),
                                         ::getpid(), entropy()));
        const int fd =
                ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
        if (fd >= 0) {
            ::close(fd);
            return tmp;
        }
        if (errno != EEXIST) {
            const int err = errno;
            return makeError(ErrorCode::Io,
                             fmt::format("{}: cannot create a file in its folder: {}{}",
                                         out.string(), std::strerror(err),
                                         err == EACCES || err == EROFS
                                                 ? " (choose a writable folder)"
                                                 : ""));
        }
    }
    return makeError(ErrorCode::Io,
                     fmt::format("{}: no free temporary name beside it", out.string()));
}

// Puts the finished temporary file at `out`: over an existing regular file only when asked,
// never over anything that appeared there since the check (link fails if `out` exists).
Expected<void> moveIntoPlace(const fs::path& tmp, const fs::path& out, ExistingOutput existing)
{
    if (existing == ExistingOutput::Replace) {
        if (::rename(tmp.c_str(), out.c_str()) != 0) {
            const int err = errno;
            return makeError(ErrorCode::Io, fmt::format("{}: cannot rename the recovered file "
                                                        "onto it: {}",
                                                        out.string(), std::strerror(err)));
        }
    } else {
        if (::link(tmp.c_str(), out.c_str()) != 0) {
            const int err = errno;
            return makeError(err == EEXIST ? ErrorCode::InvalidArgument : ErrorCode::Io,
                             err == EEXIST ? fmt::format("{}: appeared while recovering; pass "
                                                         "--force to replace it, or name a new "
                                                         "file",
                                                         out.string())
                                           : fmt::format("{}: cannot create it: {}", out.string(),
                                                         std::strerror(err)));
        }
        ::unlink(tmp.c_str());
    }
    // The rename itself survives a power cut once the folder is synced.
    const fs::path dir = out.parent_path().empty() ? fs::path(".") : out.parent_path();
    const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dfd >= 0) {
        (void)::fsync(dfd);
        ::close(dfd);
    }
    return {};
}

// What the first pass found that the output needs before its first message.
struct Plan {
    mcap::Scan scan; // the first pass (no messages held)
    mcap::ScanOptions options;
    std::optional<mcap::Message> session; // restored from the metadata, written first
};

// The reader's checks of each message (the decoder readRecording uses): what fails them is dropped
// and counted, so that recover never keeps what inspect and replay would refuse.
class MessageChecks
{
public:
    MessageChecks(const mcap::Scan& scan, std::string name)
        : scan_(scan), decoder_(scratch_, deviceKinds(), std::move(name))
    {}

    // Whether `m` passes; a message that does not is counted, the first few named.
    bool accept(const mcap::Message& m)
    {
        auto ok = decoder_.decode(scan_.channels.at(m.channelId).topic, m);
        decoder_.forget(); // checked, not held: memory does not grow with the file
        if (ok) {
            return true;
        }
        ++dropped_;
        if (problems_.size() < kMaxProblems) {
            problems_.push_back(ok.error().message + "; dropped");
        }
        return false;
    }

    std::uint64_t dropped() const { return dropped_; }
    bool haveSession() const { return decoder_.haveSession(); }
    int formatVersion() const { return scratch_.formatVersion; } // the session's, once decoded
    const std::vector<std::string>& problems() const { return problems_; }

private:
    static constexpr std::size_t kMaxProblems = 20;
    const mcap::Scan& scan_;
    Recording scratch_;
    detail::MessageDecoder decoder_;
    std::uint64_t dropped_ = 0;
    std::vector<std::string> problems_;
};

// What the second pass dropped because the reader's checks refused it.
struct Checked {
    std::uint64_t dropped = 0;
    std::vector<std::string> problems;
};

// A recording the reader accepts needs its session: without it, one line that says why it is
// missing.
Expected<void> checkRecoverable(const MessageChecks& checks, const fs::path& in)
{
    if (!checks.haveSession()) {
        std::string why = "its /replica/session message is lost and the copy in its metadata is "
                          "missing or unusable";
        for (const auto& p : checks.problems()) {
            if (p.find(std::string(kSessionTopic)) != std::string::npos) {
                why = p;
                break;
            }
        }
        return makeError(ErrorCode::Corrupt,
                         fmt::format("{}: nothing recoverable: the session could not be rebuilt "
                                     "({}), and a recording without one does not replay",
                                     in.string(), why));
    }
    // A newer format's messages were checked by this build's rules, which may not be its rules:
    // "nothing lost" would be a guess, and inspect and replay refuse the file anyway.
    if (auto ok = checkFormatVersion(in.string(), checks.formatVersion()); !ok) {
        return makeError(ErrorCode::Unsupported,
                         fmt::format("{}; nothing was written", ok.error().message));
    }
    return {};
}

// Every kept message into a fresh, complete recording at `path` (finish() syncs it): the metadata,
// schemas and channels the first pass found, then a second pass over `in` giving its messages to
// the writer as they come, so that nothing grows with the file; those the reader's checks refuse
// are dropped. The second pass must find what the first did.
Expected<Checked>
writeRecovered(const Plan& plan, mcap::Source& in, const fs::path& path, const fs::path& inPath)
{
    const auto& s = plan.scan;
    auto w = mcap::FileWriter::create(path, s.library.empty() ? "replica recover" : s.library,
                                      false);
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
    std::optional<Error> failed;
    MessageChecks checks(s, inPath.string());
    auto add = [&](mcap::Message&& m) {
        if (!checks.accept(m)) {
            return true;
        }
        (*w)->addMessage(m);
        if ((*w)->pendingBytes() >= kChunkBytes) {
            if (auto ok = (*w)->closeChunk(false); !ok) {
                failed = ok.error();
                return false;
            }
        }
        return true;
    };
    if (plan.session) {
        add(mcap::Message(*plan.session));
    }
    const auto again = mcap::scan(in, plan.options, add);
    if (failed) {
        return tl::unexpected(*failed);
    }
    if (!again.readError.empty()) {
        return makeError(ErrorCode::Io, again.readError);
    }
    if (again.messageCount != s.messageCount || again.chunks.size() != s.chunks.size() ||
        again.damageCount != s.damageCount) {
        return makeError(ErrorCode::Io, "the recording changed while it was being recovered "
                                        "(is something still writing it?)");
    }
    if (auto ok = checkRecoverable(checks, inPath); !ok) {
        return tl::unexpected(ok.error());
    }
    if (auto ok = (*w)->finish(); !ok) {
        return tl::unexpected(ok.error());
    }
    return Checked{checks.dropped(), checks.problems()};
}

// How recover scans: resynchronising, chunked records only, and (for a file whose first chunk,
// with the channel definitions, was lost) the fixed channels of Replica's formats assumed.
mcap::ScanOptions recoverOptions(std::string_view head)
{
    mcap::ScanOptions options;
    options.resync = true;
    options.maxDamageReports = 50;
    options.chunkedOnly = true; // the writer chunks every record that carries samples
    // Replica's channel ids are fixed per format version: a file whose first chunk (the channel
    // definitions) was lost can still have its samples recovered.
    // Each format only added channels (3: id 7, 4: ids 8-13, 5: ids 14-15, 6: id 16), so today's
    // definitions serve every chunked format (2 and later) as well.
    const auto probe = head.substr(0, 256);
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
    return options;
}

// The session message lives in the first chunk; if that chunk was lost, restores it from the
// copy in the replica.session Metadata record (in plan.session, written before every other
// message). Whether it did.
bool restoreSession(Plan& plan)
{
    auto& s = plan.scan;
    const auto& options = plan.options;
    const auto sessionId = static_cast<std::uint16_t>(ChannelId::Session);
    const bool haveSession = s.channelMessages.contains(sessionId);
    if (haveSession || s.messageCount == 0 || !options.fallbackChannels.contains(sessionId)) {
        return false;
    }
    for (const auto& md : s.metadata) {
        auto it = md.metadata.find("session");
        if (md.name != kSessionMetadataName || it == md.metadata.end()) {
            continue;
        }
        std::uint64_t t = 0;
        try {
            if (!checkJsonLimits(it->second, "session metadata")) {
                return false;
            }
            const auto j = nlohmann::json::parse(it->second);
            t = static_cast<std::uint64_t>(
                    std::max<std::int64_t>(0, j.at("wall_clock_start_ns").get<std::int64_t>()));
        } catch (const std::exception&) {
            return false; // not a usable session description
        }
        const auto& def = options.fallbackChannels.at(sessionId);
        if (!s.channels.contains(sessionId)) {
            s.channels.emplace(sessionId, def);
            s.schemas.emplace(def.schemaId, options.fallbackSchemas.at(def.schemaId));
            s.channelsAssumed.push_back(sessionId);
        }
        plan.session = mcap::Message{sessionId, 0, t, t, it->second};
        return true;
    }
    return false;
}

RecoverReport reportOf(const mcap::Scan& s, bool sessionRestored, const Checked& checked)
{
    const std::uint64_t scanned = s.messageCount + (sessionRestored ? 1 : 0);
    RecoverReport r;
    r.problems = s.damage;
    if (s.damageCount > s.damage.size()) {
        r.problems.push_back(
                fmt::format("... and {} more problems", s.damageCount - s.damage.size()));
    }
    r.problems.insert(r.problems.end(), checked.problems.begin(), checked.problems.end());
    if (checked.dropped > checked.problems.size()) {
        r.problems.push_back(fmt::format("... and {} more messages the reader refuses",
                                         checked.dropped - checked.problems.size()));
    }
    r.messagesKept = scanned - checked.dropped;
    r.chunksKept = s.chunks.size();
    r.chunksDamaged = s.chunksDamaged;
    r.bytesDropped = s.bytesSkipped;
    r.messagesDropped = s.messagesDropped + checked.dropped;
    if (s.summaryMessageCount && *s.summaryMessageCount > scanned) {
        r.messagesDropped += *s.summaryMessageCount - scanned;
    }
    r.channelsAssumed = s.channelsAssumed;
    r.sessionRestored = sessionRestored;
    return r;
}

// Writes the kept messages to a new file beside `out` and puts it in place; whatever goes wrong,
// the temporary file goes and `out` stays as it was.
Expected<Checked> writeInPlace(const Plan& plan,
                               mcap::Source& in,
                               const fs::path& inPath,
                               const fs::path& out,
                               ExistingOutput existing)
{
    auto tmp = createTemporaryBeside(out);
    if (!tmp) {
        return tl::unexpected(tmp.error());
    }
    auto written = writeRecovered(plan, in, *tmp, inPath);
    if (!written) {
        written =
                makeError(written.error().code, fmt::format("{}: not written (left as it was): {}",
                                                            out.string(), written.error().message));
    } else if (auto moved = moveIntoPlace(*tmp, out, existing); !moved) {
        written = tl::unexpected(moved.error());
    }
    if (!written) {
        std::error_code ec;
        std::filesystem::remove(*tmp, ec);
    }
    return written;
}

} // namespace

Expected<RecoverReport> recoverRecording(const std::filesystem::path& in,
                                         const std::filesystem::path& out,
                                         ExistingOutput existing)
{
    std::error_code ec;
    if (!std::filesystem::is_regular_file(in, ec)) {
        return makeError(ErrorCode::NotFound,
                         fmt::format("{}: no such recording (or not a regular file)", in.string()));
    }
    if (auto ok = checkOutput(in, out, existing); !ok) {
        return tl::unexpected(ok.error());
    }
    // Read twice through a bounded window, never whole: once to learn the channels, metadata and
    // damage the output starts with, once to copy the messages (docs/limits.md).
    auto source = mcap::FileSource::open(in, kMaxRecordingBytes, "recording");
    if (!source) {
        return tl::unexpected(source.error());
    }
    Plan plan;
    const auto size = (*source)->size();
    const auto head = (*source)->bytes(0, std::min<std::uint64_t>(size, 256));
    if (!head) {
        return makeError(ErrorCode::Io, (*source)->error());
    }
    plan.options = recoverOptions(*head);
    plan.scan = mcap::scan(**source, plan.options, [](mcap::Message&&) { return true; });
    if (!plan.scan.readError.empty()) {
        return makeError(ErrorCode::Io, plan.scan.readError);
    }
    const bool sessionRestored = restoreSession(plan);
    const auto& s = plan.scan;
    if (s.messageCount == 0) {
        return makeError(
                ErrorCode::Corrupt,
                fmt::format("{}: nothing recoverable: {}", in.string(),
                            s.damage.empty() ? "the file holds no messages" : s.damage.front()));
    }
    auto checked = writeInPlace(plan, **source, in, out, existing);
    if (!checked) {
        return tl::unexpected(checked.error());
    }
    return reportOf(s, sessionRestored, *checked);
}

} // namespace replica::recordings
