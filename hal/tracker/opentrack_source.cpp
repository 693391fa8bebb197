// UDP receiver thread for opentrack poses.
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <deque>
#include <mutex>
#include <span>
#include <thread>
#include <vector>

#include <arpa/inet.h>
#include <fmt/format.h>
#include <netinet/in.h>
#include <poll.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <unistd.h>

#include <hal/log.h>
#include <hal/log_limiter.h>
#include <hal/tracker/opentrack_source.h>

namespace replica::hal::tracker {
namespace {

class OpentrackUdpSource final : public OpentrackSource
{
public:
    OpentrackUdpSource(int fd,
                       std::uint16_t port,
                       const Clock& clock,
                       OpentrackSourceOptions options)
        : fd_(fd), port_(port), clock_(clock), options_(std::move(options))
    {
        info_.model = "opentrack-udp";
        info_.serial = fmt::format("{}:{}", options_.bindAddress, port_);
        info_.kind = SourceKind::Live;
        thread_ = std::thread([this] { run(); });
    }

    ~OpentrackUdpSource() override
    {
        stop_ = true;
        thread_.join();
        ::close(fd_);
    }

    OpentrackUdpSource(const OpentrackUdpSource&) = delete;
    OpentrackUdpSource& operator=(const OpentrackUdpSource&) = delete;

    const DeviceInfo& info() const override { return info_; }
    std::uint16_t boundPort() const override { return port_; }
    long rejectedDatagrams() const override { return rejected_.load(); }
    long coalescedDatagrams() const override { return coalesced_.load(); }

    LinkState state() const override
    {
        const std::int64_t last = lastGoodNs_.load();
        if (last < 0) {
            return LinkState::Lost;
        }
        return clock_.nowNs() - last > options_.staleNs ? LinkState::Stalled : LinkState::Connected;
    }

    void poll(std::int64_t untilNs, std::vector<PoseSample>& out) override
    {
        std::lock_guard lock(mutex_);
        while (!queue_.empty() && queue_.front().timestampNs <= untilNs) {
            out.push_back(queue_.front());
            queue_.pop_front();
        }
        // A tracker that went quiet must not leave the last pose standing as if still tracked.
        const std::int64_t last = lastGoodNs_.load();
        if (last >= 0 && untilNs - last > options_.staleNs && !reportedStale_) {
            PoseSample s;
            s.timestampNs = last + options_.staleNs;
            s.sequence = sequence_++;
            s.tracked = false;
            out.push_back(s);
            reportedStale_ = true;
        }
    }

private:
    static constexpr int kMaxDrain = 4096; // datagrams read per wake-up, at most

    // What one wake-up read from the socket without waiting.
    struct Drained {
        std::vector<std::uint8_t> latest; // the last good datagram not yet pushed (empty: none)
        HeadPose pose;                    // and its pose
        long good = 0;
        long rejected = 0;
        long lastRejectedBytes = 0;
        int error = 0;
    };

    void run()
    {
        std::vector<std::uint8_t> buf(512);
        int lastErrno = 0;
        while (!stop_) {
            pollfd p{fd_, POLLIN, 0};
            if (::poll(&p, 1, 50) <= 0) {
                report();
                continue;
            }
            Drained d = drain(buf);
            if (d.error != 0 && d.good + d.rejected == 0) {
                // A socket that keeps failing must not spin nor flood the log: one line per new
                // error, then a pause as long as the poll timeout.
                if (d.error != lastErrno) {
                    deviceLog("hal.tracker")
                            ->warn("UDP receive on port {} failed: {}", port_,
                                   std::strerror(d.error));
                    lastErrno = d.error;
                }
                std::this_thread::sleep_for(std::chrono::milliseconds(50));
                continue;
            }
            lastErrno = 0;
            rejected_ += d.rejected;
            rejectedLog_.count(static_cast<std::uint64_t>(d.rejected));
            if (d.rejected > 0) {
                lastRejectedBytes_ = d.lastRejectedBytes;
            }
            if (!d.latest.empty()) {
                push(d.latest, d.pose);
                const long coalesced = d.good - 1;
                coalesced_ += coalesced;
                coalescedLog_.count(static_cast<std::uint64_t>(coalesced));
            }
            report();
            if (!d.latest.empty() && options_.minIntervalNs > 0) {
                // A flood waits in the socket's buffer (the kernel drops what does not fit) and
                // is read as one batch, its latest pose kept: the receiver costs at most one
                // wake-up per interval and the loop sees at most one pose per interval.
                std::this_thread::sleep_for(std::chrono::nanoseconds(options_.minIntervalNs));
            }
        }
    }

    // Reads what the socket holds, up to kMaxDrain datagrams. With minIntervalNs 0 every good one
    // is pushed; otherwise only the latest is kept, for run() to push.
    Drained drain(std::vector<std::uint8_t>& buf)
    {
        Drained d;
        for (int i = 0; i < kMaxDrain; ++i) {
            const ssize_t got = ::recv(fd_, buf.data(), buf.size(), MSG_DONTWAIT);
            if (got < 0) {
                if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) {
                    d.error = errno;
                }
                break;
            }
            const std::span<const std::uint8_t> bytes{buf.data(), static_cast<std::size_t>(got)};
            const auto pose = decodeOpentrack(bytes);
            if (!pose) {
                ++d.rejected;
                d.lastRejectedBytes = got;
                continue;
            }
            ++d.good;
            if (options_.minIntervalNs <= 0) {
                push(bytes, *pose);
            } else {
                d.latest.assign(bytes.begin(), bytes.end());
                d.pose = *pose;
            }
        }
        return d;
    }

    void push(std::span<const std::uint8_t> bytes, const HeadPose& pose)
    {
        PoseSample s;
        s.timestampNs = clock_.nowNs();
        s.eyeTrackerM = eyeFromHeadPose(pose, options_.mounting);
        s.tracked = true;
        // Raw in, processed out: the datagram as received, with the mounting it was read with.
        auto raw = std::make_shared<RawTrackerInput>();
        raw->kind = RawTrackerInput::Kind::OpentrackDatagram;
        raw->arrivalNs = s.timestampNs;
        raw->bytes.assign(bytes.begin(), bytes.end());
        raw->zSign = options_.mounting.zSign;
        raw->eyeOffsetHeadM = options_.mounting.eyeOffsetHeadM;
        s.raw = std::move(raw);
        std::lock_guard lock(mutex_);
        s.sequence = sequence_++;
        queue_.push_back(s);
        if (queue_.size() > 1024) { // a loop that stopped polling must not grow us forever
            queue_.pop_front();
        }
        lastGoodNs_ = s.timestampNs;
        reportedStale_ = false;
    }

    // The rate-limited lines: the first rejected or coalesced datagram at once, then at most one
    // line per logIntervalNs for each, with the count since the last line (and the size of the
    // last datagram dropped, which may have come before the wake-up that says so).
    void report()
    {
        const std::int64_t now = clock_.nowNs();
        const double seconds = static_cast<double>(options_.logIntervalNs) * 1e-9;
        if (const auto n = rejectedLog_.flush(now); n > 0) {
            deviceLog("hal.tracker")
                    ->warn("dropped {} datagram{} on port {} (the last {} bytes; opentrack sends "
                           "48 finite bytes), {} in all; is another program sending here? (at "
                           "most one line per {:g} s)",
                           n, n == 1 ? "" : "s", port_, lastRejectedBytes_, rejected_.load(),
                           seconds);
        }
        if (const auto n = coalescedLog_.flush(now); n > 0) {
            deviceLog("hal.tracker")
                    ->warn("{} pose{} on port {} skipped for a later one (more than one per {} "
                           "ms: a flood, or a second sender?), {} in all; the latest pose is "
                           "used (at most one line per {:g} s)",
                           n, n == 1 ? "" : "s", port_, options_.minIntervalNs / 1'000'000,
                           coalesced_.load(), seconds);
        }
    }

    int fd_;
    std::uint16_t port_;
    const Clock& clock_;
    OpentrackSourceOptions options_;
    DeviceInfo info_;
    std::atomic<bool> stop_{false};
    std::atomic<std::int64_t> lastGoodNs_{-1};
    std::atomic<long> rejected_{0};
    std::atomic<long> coalesced_{0};
    LogLimiter rejectedLog_{options_.logIntervalNs}; // receiver thread only
    long lastRejectedBytes_ = 0; // the size of the last datagram dropped (receiver thread only)
    LogLimiter coalescedLog_{options_.logIntervalNs}; // receiver thread only
    std::mutex mutex_;
    std::deque<PoseSample> queue_;
    std::uint32_t sequence_ = 0; // under mutex_
    bool reportedStale_ = false; // under mutex_
    std::thread thread_;
};

} // namespace

Expected<std::unique_ptr<OpentrackSource>> makeOpentrackSource(const Clock& clock,
                                                               OpentrackSourceOptions options)
{
    const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    if (fd < 0) {
        return makeError(ErrorCode::Io, fmt::format("tracker: cannot create a UDP socket: {}",
                                                    std::strerror(errno)));
    }
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(options.port);
    if (::inet_pton(AF_INET, options.bindAddress.c_str(), &addr.sin_addr) != 1) {
        ::close(fd);
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("tracker: '{}' is not an IPv4 address", options.bindAddress));
    }
    if (::bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
        const int err = errno;
        ::close(fd);
        return makeError(ErrorCode::Io,
                         fmt::format("tracker: cannot listen on UDP {}:{}: {}; is another "
                                     "program (a second replica?) using the port?",
                                     options.bindAddress, options.port, std::strerror(err)));
    }
    socklen_t len = sizeof addr;
    ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
    const std::uint16_t port = ntohs(addr.sin_port);
    return std::unique_ptr<OpentrackSource>(
            std::make_unique<OpentrackUdpSource>(fd, port, clock, std::move(options)));
}

} // namespace replica::hal::tracker
