// The recording writer: callers enqueue samples; a writer thread encodes them into chunks and
// closes (and syncs) a chunk at least every flush interval, so a power cut loses at most that much.
#include <algorithm>
#include <array>
#include <condition_variable>
#include <csignal>
#include <map>
#include <mutex>
#include <thread>
#include <variant>

#include <fmt/format.h>

#include <recordings/mcap/writer.h>
#include <recordings/recording.h>
#include <recordings/sample_codec.h>
#include <recordings/sample_queue.h>

namespace replica::recordings {
namespace {

// A device's sample: its kind (an index into the writer's kinds) and the sample.
struct DeviceItem {
    std::size_t kind = 0;
    AnySample sample;
};
using Item = std::variant<DeviceItem, FrameRecord, DisplayDigestRecord, PosesRecord, LightRecord>;
// The most device kinds a writer takes (each has its own drop counter).
constexpr std::size_t kMaxDeviceKinds = 32;
// Written from any thread (thumbnail encoder, log sink), through a mutex.
using SharedItem = std::variant<ThumbnailRecord, LogRecord, ErrorProbeRecord>;
// What the shared queue holds at most: a minute of 1 Hz thumbnails and a burst of warnings.
constexpr std::size_t kSharedCapacity = 256;
using Clock = std::chrono::steady_clock;

// How long the writer thread sleeps when the queue is empty (a write() also wakes it).
constexpr auto kPoll = std::chrono::milliseconds(10);
constexpr Clock::time_point kNoChunk = Clock::time_point::min();

std::uint64_t logTime(std::int64_t wallStart, std::int64_t t)
{
    const std::int64_t v = wallStart + t;
    return v > 0 ? static_cast<std::uint64_t>(v) : 0;
}

// Each kind's raw codec state, as the kind makes it, in the kinds' order.
std::vector<AnyWriterState> writerStates(const DeviceKinds& kinds)
{
    std::vector<AnyWriterState> states;
    states.reserve(kinds.size());
    for (const auto* kind : kinds) {
        states.push_back(kind->writerState());
    }
    return states;
}

class ThreadedWriter final : public RecordingWriter
{
public:
    ThreadedWriter(std::unique_ptr<mcap::FileWriter> file,
                   const SessionInfo& session,
                   WriterOptions options)
        : file_(std::move(file)), options_(std::move(options)), queue_(options_.queueCapacity),
          wallStart_(session.wallClockStartNs), kindState_(writerStates(options_.kinds))
    {
        status_.queueCapacity = queue_.capacity();
        bytes_ = file_->bytesWritten();
        chunks_ = file_->chunkCount();
        thread_ = std::thread([this] { loop(); });
    }
    ~ThreadedWriter() override { (void)close(); }

    // Writes the chunk #0 (schemas, channels, session) synchronously, before the thread starts.
    static Expected<void>
    begin(mcap::FileWriter& file, const SessionInfo& session, const DeviceKinds& kinds)
    {
        const std::string sessionJson = encodeSession(session, kFormatVersion, kinds);
        if (auto ok = file.addMetadata(
                    {std::string(kSessionMetadataName), {{"session", sessionJson}}});
            !ok) {
            return ok;
        }
        for (const auto& d : channelDefinitions(kinds)) {
            file.addSchema(d.schema);
            file.addChannel(d.channel);
        }
        const auto t = logTime(session.wallClockStartNs, 0);
        file.addMessage({static_cast<std::uint16_t>(ChannelId::Session), 0, t, t, sessionJson});
        return file.closeChunk(true);
    }

    using RecordingWriter::write;
    void writeDevice(const DeviceKindBase& kind, AnySample sample) override
    {
        const auto& kinds = options_.kinds;
        const auto it = std::find(kinds.begin(), kinds.end(), &kind);
        if (it == kinds.end()) {
            rejected_.fetch_add(1, std::memory_order_relaxed); // no channel for it in this file
            return;
        }
        const auto i = static_cast<std::size_t>(it - kinds.begin());
        push(DeviceItem{i, std::move(sample)}, droppedDevice_[i]);
    }
    void write(const FrameRecord& f) override { push(f, droppedFrames_); }
    void write(const DisplayDigestRecord& d) override { push(d, droppedShown_); }
    void write(const PosesRecord& p) override { push(p, droppedShown_); }
    void write(const LightRecord& l) override { push(l, droppedShown_); }
    void write(const ThumbnailRecord& t) override { pushShared(t); }
    void write(const LogRecord& l) override { pushShared(l); }
    void write(const ErrorProbeRecord& e) override { pushShared(e); }

    Expected<void> close() override
    {
        if (!closed_) {
            closed_ = true;
            stopping_.store(true, std::memory_order_release);
            wake_.notify_one();
            if (thread_.joinable()) {
                thread_.join();
            }
        }
        if (result_) {
            return tl::unexpected(*result_);
        }
        return {};
    }

    std::int64_t wallClockStartNs() const override { return wallStart_; }

    WriterStats stats() const override
    {
        WriterStats s;
        s.messages = messages_.load();
        for (const auto& d : droppedDevice_) {
            s.dropped += d.load();
        }
        s.dropped += droppedFrames_.load() + droppedShown_.load();
        s.rejected = rejected_.load();
        s.chunks = chunks_.load();
        s.bytes = bytes_.load();
        s.failed = failed_.load();
        return s;
    }

private:
    template <typename Sample>
    void push(Sample&& sample, std::atomic<std::uint64_t>& dropCounter)
    {
        if (closed_ || !queue_.tryPush(std::forward<Sample>(sample))) {
            dropCounter.fetch_add(1, std::memory_order_relaxed);
        }
        wake_.notify_one();
    }

    template <typename Record>
    void pushShared(const Record& r)
    {
        {
            std::lock_guard lock(sharedMutex_);
            if (closed_ || shared_.size() >= kSharedCapacity) {
                droppedShown_.fetch_add(1, std::memory_order_relaxed);
                return;
            }
            shared_.emplace_back(r);
        }
        wake_.notify_one();
    }

    // Moves what other threads wrote into the open chunk; returns whether there was any.
    bool drainShared()
    {
        std::vector<SharedItem> items;
        {
            std::lock_guard lock(sharedMutex_);
            items.swap(shared_);
        }
        for (const auto& item : items) {
            if (failed_) {
                break;
            }
            std::visit(
                    [&](const auto& r) {
                        using R = std::decay_t<decltype(r)>;
                        if constexpr (std::is_same_v<R, ThumbnailRecord>) {
                            message(ChannelId::Thumbnail, r.tNs, encodeThumbnail(r, wallStart_));
                        } else if constexpr (std::is_same_v<R, ErrorProbeRecord>) {
                            if (auto payload = encodeErrorProbe(r)) {
                                message(ChannelId::ErrorProbe, r.tNs, std::move(*payload));
                            } else {
                                rejected_.fetch_add(1, std::memory_order_relaxed);
                            }
                        } else {
                            message(ChannelId::Log, r.tNs, encodeLog(r, wallStart_));
                        }
                    },
                    item);
        }
        return !items.empty();
    }

    void loop()
    {
        std::unique_lock lock(mutex_);
        // When the open chunk got its first item; Clock::time_point::min(): no chunk open. (A
        // sentinel rather than std::optional: GCC 12 at -O3 reports the optional's value as
        // maybe-uninitialized behind the has_value() test.)
        Clock::time_point chunkOpened = kNoChunk;
        for (;;) {
            const bool stopping = stopping_.load(std::memory_order_acquire);
            while (auto item = queue_.tryPop()) {
                if (chunkOpened == kNoChunk) {
                    chunkOpened = Clock::now();
                }
                add(*item);
                if (file_->pendingBytes() >= options_.chunkBytes) {
                    flush(chunkOpened);
                }
            }
            if (drainShared()) {
                if (chunkOpened == kNoChunk) {
                    chunkOpened = Clock::now();
                }
                if (file_->pendingBytes() >= options_.chunkBytes) {
                    flush(chunkOpened);
                }
            }
            if (stopping) {
                break;
            }
            // Close a little early so that a sample's queueing delay (at most kPoll) still fits
            // inside the promised interval.
            if (chunkOpened != kNoChunk &&
                Clock::now() - chunkOpened + kPoll >= options_.flushInterval) {
                flush(chunkOpened);
            }
            auto wait = kPoll;
            if (chunkOpened != kNoChunk) {
                const auto due = std::chrono::duration_cast<std::chrono::milliseconds>(
                        chunkOpened + options_.flushInterval - kPoll - Clock::now());
                wait = std::clamp(due, std::chrono::milliseconds(1), kPoll);
            }
            wake_.wait_for(lock, wait);
        }
        recordStatus(true);
        if (!failed_) {
            if (auto ok = file_->finish(); !ok) {
                report(ok.error());
            }
            bytes_ = file_->bytesWritten();
            chunks_ = file_->chunkCount();
        }
    }

    void add(const Item& item)
    {
        if (failed_) {
            return; // keep draining so that the producer never sees a full queue for our sake
        }
        if (const auto* d = std::get_if<DeviceItem>(&item)) {
            addDevice(*d);
            return;
        }
        std::optional<std::string> payload;
        ChannelId channel{};
        std::int64_t t = 0;
        std::visit(
                [&](const auto& s) {
                    using S = std::decay_t<decltype(s)>;
                    if constexpr (std::is_same_v<S, DeviceItem>) {
                        // handled above
                    } else if constexpr (std::is_same_v<S, DisplayDigestRecord>) {
                        payload = encodeDisplayDigest(s);
                        channel = ChannelId::DisplayDigest;
                        t = s.tickNs;
                    } else if constexpr (std::is_same_v<S, LightRecord>) {
                        payload = encodeLight(s);
                        channel = ChannelId::Light;
                        t = s.tNs;
                    } else if constexpr (std::is_same_v<S, PosesRecord>) {
                        // Two messages: the frames for the 3D panel, the eye for plots.
                        payload = encodeEye(s, wallStart_);
                        channel = ChannelId::Eye;
                        t = s.tNs;
                        if (auto tf = encodeTransforms(s, wallStart_)) {
                            message(ChannelId::Transforms, t, std::move(*tf));
                        }
                    } else {
                        payload = encodeFrame(s, options_.kinds);
                        channel = ChannelId::Frame;
                        t = s.tickNs;
                    }
                },
                item);
        if (!payload) {
            rejected_.fetch_add(1, std::memory_order_relaxed);
            return;
        }
        message(channel, t, std::move(*payload));
        lastTime_ = std::max(lastTime_, t);
    }

    // A device's sample: its kind's codec writes its messages (format 5: the raw input after
    // the sample, on the kind's raw channel).
    void addDevice(const DeviceItem& d)
    {
        const DeviceKindBase& kind = *options_.kinds[d.kind];
        bool first = true; // the sample's own message: its time is the recording's latest
        const DeviceEmitter emit{[&](std::uint16_t channel, std::int64_t t, std::string payload) {
                                     message(static_cast<ChannelId>(channel), t,
                                             std::move(payload));
                                     if (first) {
                                         first = false;
                                         lastTime_ = std::max(lastTime_, t);
                                     }
                                 },
                                 [&] { rejected_.fetch_add(1, std::memory_order_relaxed); }};
        if (!kind.encode(d.sample, kindState_[d.kind], emit)) {
            rejected_.fetch_add(1, std::memory_order_relaxed);
        }
    }

    void message(ChannelId channel, std::int64_t t, std::string payload)
    {
        const auto id = static_cast<std::uint16_t>(channel);
        const auto lt = logTime(wallStart_, t);
        file_->addMessage({id, sequence_[id]++, lt, lt, std::move(payload)});
        messages_.fetch_add(1, std::memory_order_relaxed);
    }

    // Writes a /replica/recorder message when the drop counts changed (always when `final`).
    void recordStatus(bool final)
    {
        if (failed_) {
            return;
        }
        RecorderStatus now = status_;
        for (std::size_t i = 0; i < options_.kinds.size(); ++i) {
            now.droppedDevices[options_.kinds[i]->names().droppedKey] = droppedDevice_[i].load();
        }
        now.droppedFrames = droppedFrames_.load();
        now.droppedShown = droppedShown_.load();
        now.rejectedNonFinite = rejected_.load();
        const bool changed = now.droppedTotal() != status_.droppedTotal() ||
                             now.rejectedNonFinite != status_.rejectedNonFinite;
        if (changed || final) {
            status_ = now;
            message(ChannelId::Recorder, lastTime_, encodeRecorderStatus(now));
        }
    }

    void flush(Clock::time_point& chunkOpened)
    {
        chunkOpened = kNoChunk;
        if (failed_) {
            return;
        }
        recordStatus(false);
        auto ok = file_->closeChunk(true);
        bytes_ = file_->bytesWritten();
        chunks_ = file_->chunkCount();
        if (!ok) {
            report(ok.error());
        }
    }

    void report(const Error& e)
    {
        failed_ = true;
        result_ = e;
        if (options_.onError) {
            options_.onError(e);
        }
    }

    std::unique_ptr<mcap::FileWriter> file_;
    WriterOptions options_;
    SampleQueue<Item> queue_;
    std::int64_t wallStart_ = 0;
    std::int64_t lastTime_ = 0;
    std::map<std::uint16_t, std::uint32_t> sequence_;
    std::vector<AnyWriterState> kindState_; // each device kind's codec state, writer thread only
    RecorderStatus status_;
    // Per device kind (options_.kinds), frames, and the format 4 channels of what was shown.
    std::array<std::atomic<std::uint64_t>, kMaxDeviceKinds> droppedDevice_{};
    std::atomic<std::uint64_t> droppedFrames_{0}, droppedShown_{0};
    std::mutex sharedMutex_;
    std::vector<SharedItem> shared_;
    std::atomic<std::uint64_t> rejected_{0}, messages_{0}, chunks_{0}, bytes_{0};
    std::atomic<bool> failed_{false}, stopping_{false};
    std::optional<Error> result_;
    std::atomic<bool> closed_{false};
    std::mutex mutex_;
    std::condition_variable wake_;
    std::thread thread_;
};

} // namespace

Expected<std::unique_ptr<RecordingWriter>> RecordingWriter::create(
        const std::filesystem::path& path, const SessionInfo& session, WriterOptions options)
{
    // A write past a file size limit must fail with EFBIG, not kill the appliance with SIGXFSZ.
    struct sigaction current {
    };
    if (::sigaction(SIGXFSZ, nullptr, &current) == 0 && current.sa_handler == SIG_DFL) {
        std::signal(SIGXFSZ, SIG_IGN);
    }
    if (options.kinds.size() > kMaxDeviceKinds) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: {} device kinds; a recording takes at most {}",
                                     path.string(), options.kinds.size(), kMaxDeviceKinds));
    }
    auto file = mcap::FileWriter::create(
            path,
            fmt::format("{} (format {})",
                        session.softwareVersion.empty() ? "replica" : session.softwareVersion,
                        kFormatVersion),
            options.overwrite);
    if (!file) {
        return tl::unexpected(file.error());
    }
    if (auto ok = ThreadedWriter::begin(**file, session, options.kinds); !ok) {
        return tl::unexpected(ok.error());
    }
    return std::unique_ptr<RecordingWriter>(
            std::make_unique<ThreadedWriter>(std::move(*file), session, std::move(options)));
}

} // namespace replica::recordings
