// IIO accelerometer over sysfs.
#include <atomic>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <sstream>
#include <thread>

#include <fcntl.h>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <glm/geometric.hpp>
#include <poll.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <hal/accel/iio_accel.h>
#include <hal/live_queue.h>
#include <hal/log.h>
#include <hal/log_limiter.h>

namespace replica::hal::accel {
namespace fs = std::filesystem;

Expected<std::string> readSysfsText(const fs::path& file)
{
    // A sysfs attribute is a few bytes: at most 64, so that a wrong path (/dev/zero, a big file)
    // cannot make us read without end.
    return readSysfsFile(file, 64, SysfsRead::FirstLine);
}

Expected<double> readSysfsNumber(const fs::path& file)
{
    auto read = readSysfsText(file);
    if (!read) {
        return tl::unexpected(read.error());
    }
    std::string& text = *read;
    while (!text.empty() && (text.back() == '\n' || text.back() == ' ' || text.back() == '\r')) {
        text.pop_back();
    }
    double v = 0.0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (text.empty() || ec != std::errc{} || end != text.data() + text.size()) {
        return makeError(ErrorCode::DeviceFailure,
                         fmt::format("{}: '{}' is not a number", file.string(), text));
    }
    return v;
}

namespace {

constexpr const char* kAxes[3] = {"x", "y", "z"};

// Per-axis attribute if present, else the shared one, else 'fallback'.
Expected<double> axisAttribute(const fs::path& dir,
                               const char* axis,
                               const char* what,
                               std::optional<double> fallback)
{
    std::error_code ec; // a symlink loop or unreadable directory is "absent", never a throw
    const fs::path perAxis = dir / fmt::format("in_accel_{}_{}", axis, what);
    if (fs::exists(perAxis, ec)) {
        return readSysfsNumber(perAxis);
    }
    const fs::path shared = dir / fmt::format("in_accel_{}", what);
    if (fs::exists(shared, ec)) {
        return readSysfsNumber(shared);
    }
    if (fallback) {
        return *fallback;
    }
    return makeError(ErrorCode::NotFound,
                     fmt::format("{}: no in_accel_{}_{} or in_accel_{}; is this an accelerometer?",
                                 dir.string(), axis, what, what));
}

} // namespace

Expected<IioAccelDevice> IioAccelDevice::open(const fs::path& dir)
{
    IioAccelDevice d;
    d.dir_ = dir;
    if (auto name = readSysfsText(dir / "name")) {
        d.name_ = std::move(*name);
    }
    for (int i = 0; i < 3; ++i) {
        std::error_code ec;
        if (!fs::exists(dir / fmt::format("in_accel_{}_raw", kAxes[i]), ec)) {
            return makeError(ErrorCode::NotFound,
                             fmt::format("{}: no in_accel_{}_raw; not an accelerometer",
                                         dir.string(), kAxes[i]));
        }
        auto scale = axisAttribute(dir, kAxes[i], "scale", std::nullopt);
        if (!scale) {
            return tl::unexpected(scale.error());
        }
        if (!(*scale > 0.0) || !std::isfinite(*scale)) {
            return makeError(ErrorCode::DeviceFailure,
                             fmt::format("{}: accelerometer scale {} is not positive or not finite",
                                         dir.string(), *scale));
        }
        auto offset = axisAttribute(dir, kAxes[i], "offset", 0.0);
        if (!offset) {
            return tl::unexpected(offset.error());
        }
        if (!std::isfinite(*offset)) {
            return makeError(ErrorCode::DeviceFailure,
                             fmt::format("{}: accelerometer offset {} is not finite", dir.string(),
                                         *offset));
        }
        d.scale_[static_cast<std::size_t>(i)] = *scale;
        d.offset_[static_cast<std::size_t>(i)] = *offset;
    }
    return d;
}

Expected<IioAccelDevice> IioAccelDevice::find(const fs::path& root, const std::string& name)
{
    std::error_code ec;
    std::vector<fs::path> dirs;
    for (const auto& e : fs::directory_iterator(root, ec)) {
        dirs.push_back(e.path());
    }
    if (ec) {
        return makeError(ErrorCode::NotFound,
                         fmt::format("{}: cannot list IIO devices ({}); is the IIO subsystem "
                                     "available?",
                                     root.string(), ec.message()));
    }
    std::sort(dirs.begin(), dirs.end());
    for (const auto& dir : dirs) {
        if (!fs::exists(dir / "in_accel_x_raw", ec)) {
            continue;
        }
        auto d = open(dir);
        if (d && (name.empty() || d->name() == name)) {
            return d;
        }
    }
    return makeError(ErrorCode::NotFound,
                     name.empty() ? fmt::format("no accelerometer under {}: check that its kernel "
                                                "driver is loaded",
                                                root.string())
                                  : fmt::format("no accelerometer named '{}' under {}", name,
                                                root.string()));
}

Expected<std::array<double, 3>> IioAccelDevice::readRaw() const
{
    std::array<double, 3> a{};
    for (int i = 0; i < 3; ++i) {
        auto raw = readSysfsNumber(dir_ / fmt::format("in_accel_{}_raw", kAxes[i]));
        if (!raw) {
            return tl::unexpected(raw.error());
        }
        a[static_cast<std::size_t>(i)] = *raw;
    }
    return a;
}

namespace {

std::array<double, 3> scaledReading(const std::array<double, 3>& raw,
                                    const std::array<double, 3>& offset,
                                    const std::array<double, 3>& scale)
{
    std::array<double, 3> a{};
    for (std::size_t k = 0; k < 3; ++k) {
        a[k] = (raw[k] + offset[k]) * scale[k];
    }
    return a;
}

} // namespace

Expected<std::array<double, 3>> IioAccelDevice::read() const
{
    auto raw = readRaw();
    if (!raw) {
        return tl::unexpected(raw.error());
    }
    return scaledReading(*raw, offset_, scale_);
}

glm::dvec3 gravityFromRaw(const RawAccelInput& raw, const AxisMapping& mapping)
{
    return gravityInPanel(scaledReading(raw.raw, raw.offset, raw.scale), mapping);
}

std::string toString(const AxisMapping& m)
{
    std::string out;
    for (std::size_t k = 0; k < 3; ++k) {
        if (k > 0) {
            out += ',';
        }
        if (m.sign[k] < 0.0) {
            out += '-';
        }
        out += static_cast<char>('x' + m.axis[k]);
    }
    return out;
}

Expected<AxisMapping> parseAxisMapping(const std::string& text)
{
    AxisMapping m;
    std::array<bool, 3> used{};
    std::stringstream in(text);
    std::string item;
    int i = 0;
    while (std::getline(in, item, ',')) {
        if (i >= 3) {
            i = 4; // a fourth axis: reported below
            break;
        }
        double sign = 1.0;
        if (!item.empty() && (item[0] == '-' || item[0] == '+')) {
            sign = item[0] == '-' ? -1.0 : 1.0;
            item.erase(0, 1);
        }
        if (item.size() != 1 || item[0] < 'x' || item[0] > 'z' ||
            used[static_cast<std::size_t>(item[0] - 'x')]) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("accelerometer axes '{}': expected three of x, y, z, each "
                                         "once, optionally signed, e.g. '-y,x,z'",
                                         text));
        }
        used[static_cast<std::size_t>(item[0] - 'x')] = true;
        m.axis[static_cast<std::size_t>(i)] = item[0] - 'x';
        m.sign[static_cast<std::size_t>(i)] = sign;
        ++i;
    }
    if (i != 3 || !in.eof()) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("accelerometer axes '{}': expected three of x, y, z, each "
                                     "once, optionally signed, e.g. '-y,x,z'",
                                     text));
    }
    return m;
}

glm::dvec3 gravityInPanel(const std::array<double, 3>& reading, const AxisMapping& m)
{
    glm::dvec3 g;
    for (int i = 0; i < 3; ++i) {
        const auto k = static_cast<std::size_t>(i);
        g[i] = -m.sign[k] * reading[static_cast<std::size_t>(m.axis[k])];
    }
    return g;
}

namespace {

class IioAccelSource final : public AccelSource
{
public:
    IioAccelSource(const Clock& clock, IioAccelSourceOptions options)
        : clock_(clock), options_(std::move(options))
    {
        info_.model = "iio-accel";
        info_.serial = options_.name.empty() ? "first" : options_.name;
        info_.kind = SourceKind::Live;
        axesText_ = toString(options_.mounting);
        thread_ = std::thread([this] { run(); });
    }
    ~IioAccelSource() override
    {
        queue_.stop();
        thread_.join();
    }
    IioAccelSource(const IioAccelSource&) = delete;
    IioAccelSource& operator=(const IioAccelSource&) = delete;

    const DeviceInfo& info() const override { return info_; }
    LinkState state() const override { return state_.load(); }

    void poll(std::int64_t untilNs, std::vector<AccelSample>& out) override
    {
        queue_.drain(untilNs, out);
    }

private:
    bool waitFor(std::int64_t ns) { return queue_.waitFor(ns); }

    void run()
    {
        std::optional<IioAccelDevice> dev;
        std::uint32_t sequence = 0;
        std::int64_t attributesReadNs = 0;
        while (!queue_.stopping()) {
            if (!dev) {
                auto d = IioAccelDevice::find(options_.root, options_.name);
                if (!d) {
                    if (!lose(d.error().message, "the display keeps its last tilt")) {
                        return;
                    }
                    continue;
                }
                if (!announced_) {
                    deviceLog("hal.accel")->info("'{}' at {}", d->name(), d->dir().string());
                    announced_ = true;
                }
                dev = std::move(*d);
                attributesReadNs = clock_.nowNs();
            }
            const std::int64_t started = clock_.nowNs();
            if (started - attributesReadNs >= options_.attributesNs) {
                // The scale and offset follow the driver: a range change (2 g to 4 g) changes the
                // scale while the device stays open, and a stale one halves gravity silently.
                attributesReadNs = started;
                if (!refreshAttributes(dev)) {
                    if (!lose(lastError_, "the display keeps its last tilt")) {
                        return;
                    }
                    continue;
                }
            }
            auto a = dev->readRaw();
            if (!a) {
                // A value file that exists but reads empty, junk or EIO (a glitching I2C sensor)
                // is handled like an unplugged device: Lost, one line per new error, and a retry
                // every reconnectNs, never a busy loop.
                dev.reset();
                if (!lose(a.error().message,
                          fmt::format("the display keeps its last tilt and retries every {} ms",
                                      options_.reconnectNs / 1'000'000))) {
                    return;
                }
                continue;
            }
            if (!lastError_.empty()) {
                deviceLog("hal.accel")
                        ->info("'{}' at {} reads again", dev->name(), dev->dir().string());
                lastError_.clear();
                lastLogged_.clear();
            }
            state_ = LinkState::Connected;
            if (auto s = sample(*dev, *a, started)) {
                s->sequence = sequence++;
                queue_.push(*s);
            }
            if (!waitFor(options_.periodNs - (clock_.nowNs() - started))) {
                return;
            }
        }
    }

    // The device is lost (not found, or a read failed): one line per new error, Lost, and a wait
    // of reconnectNs. False when the source is stopping.
    bool lose(const std::string& message, const std::string& consequence)
    {
        if (message != lastLogged_) {
            deviceLog("hal.accel")->error("{}; {}", message, consequence);
            lastLogged_ = message;
        }
        lastError_ = message;
        state_ = LinkState::Lost;
        return waitFor(options_.reconnectNs);
    }

    // Re-reads the scale and offset; logs a change. False (dev reset, lastError_ set) when they
    // no longer read or are not usable.
    bool refreshAttributes(std::optional<IioAccelDevice>& dev)
    {
        auto fresh = IioAccelDevice::open(dev->dir());
        if (!fresh) {
            lastError_ = fresh.error().message;
            dev.reset();
            return false;
        }
        if (fresh->scale() != dev->scale() || fresh->offset() != dev->offset()) {
            deviceLog("hal.accel")
                    ->info("'{}' at {}: scale {} -> {}, offset {} -> {} (the driver's range "
                           "changed); following it",
                           dev->name(), dev->dir().string(), fmt::join(dev->scale(), ","),
                           fmt::join(fresh->scale(), ","), fmt::join(dev->offset(), ","),
                           fmt::join(fresh->offset(), ","));
        }
        dev = std::move(*fresh);
        return true;
    }

    // The sample of one reading, or none for a reading that is not finite (a raw "nan" or "inf",
    // or a product that overflows) or out of range (kMinGravityMs2..kMaxGravityMs2): each kind
    // counted and logged at most once per logIntervalNs.
    std::optional<AccelSample>
    sample(const IioAccelDevice& dev, const std::array<double, 3>& reading, std::int64_t nowNs)
    {
        auto raw = std::make_shared<RawAccelInput>();
        raw->raw = reading;
        raw->scale = dev.scale();
        raw->offset = dev.offset();
        raw->axes = axesText_;
        AccelSample s;
        s.timestampNs = clock_.nowNs();
        s.gravity = gravityFromRaw(*raw, options_.mounting);
        const bool finite = std::isfinite(s.gravity.x) && std::isfinite(s.gravity.y) &&
                            std::isfinite(s.gravity.z);
        // A line may come with a later reading (the limiter's interval passed): it names the
        // last bad one, kept here, not the reading at hand.
        const auto readingText = [&] {
            return fmt::format("raw {} scale {} offset {}", fmt::join(reading, ","),
                               fmt::join(dev.scale(), ","), fmt::join(dev.offset(), ","));
        };
        if (!finite) {
            lastNonFinite_ = readingText();
        }
        if (const auto n = nonFinite_.add(finite ? 0 : 1, nowNs); n > 0) {
            deviceLog("hal.accel")
                    ->warn("'{}' at {}: {} reading{} not finite (the last: {}), {} in all: not "
                           "used, the display keeps its last tilt (at most one line per {:g} s)",
                           dev.name(), dev.dir().string(), n, n == 1 ? "" : "s", lastNonFinite_,
                           nonFinite_.total(), static_cast<double>(options_.logIntervalNs) * 1e-9);
        }
        const double g = finite ? glm::length(s.gravity) : 0.0;
        const bool inRange = !finite || (g >= kMinGravityMs2 && g <= kMaxGravityMs2);
        if (!inRange) {
            lastOutOfRange_ = fmt::format("{:.4g} m/s^2 from {}", g, readingText());
        }
        if (const auto n = outOfRange_.add(inRange ? 0 : 1, nowNs); n > 0) {
            deviceLog("hal.accel")
                    ->warn("'{}' at {}: {} reading{} out of range (the last: {}; a panel reads "
                           "9.81, {:.4g}..{:.4g} is used), {} in all: not used, the display keeps "
                           "its last tilt (at most one line per {:g} s)",
                           dev.name(), dev.dir().string(), n, n == 1 ? "" : "s", lastOutOfRange_,
                           kMinGravityMs2, kMaxGravityMs2, outOfRange_.total(),
                           static_cast<double>(options_.logIntervalNs) * 1e-9);
        }
        if (!finite || !inRange) {
            return std::nullopt;
        }
        s.raw = std::move(raw);
        return s;
    }

    const Clock& clock_;
    IioAccelSourceOptions options_;
    std::string axesText_;
    DeviceInfo info_;
    std::atomic<LinkState> state_{LinkState::Lost};
    // The source's thread only:
    std::string lastError_;  // the error the device is lost on (empty: reading)
    std::string lastLogged_; // the last error logged: a repeated one is not logged again
    std::string lastNonFinite_, lastOutOfRange_; // the last bad reading of each kind, as logged
    bool announced_ = false;
    LogLimiter nonFinite_{options_.logIntervalNs};
    LogLimiter outOfRange_{options_.logIntervalNs};
    LiveQueue<AccelSample> queue_{1024};
    std::thread thread_;
};

} // namespace

std::unique_ptr<AccelSource> makeIioAccelSource(const Clock& clock, IioAccelSourceOptions options)
{
    return std::make_unique<IioAccelSource>(clock, std::move(options));
}

} // namespace replica::hal::accel
