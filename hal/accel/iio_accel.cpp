// IIO accelerometer over sysfs.
#include <atomic>
#include <charconv>
#include <fstream>
#include <sstream>
#include <thread>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <hal/accel/iio_accel.h>
#include <hal/live_queue.h>
#include <hal/log.h>

namespace replica::hal::accel {
namespace fs = std::filesystem;

Expected<double> readSysfsNumber(const fs::path& file)
{
    std::ifstream in(file);
    if (!in) {
        return makeError(ErrorCode::NotFound, fmt::format("{}: cannot be read", file.string()));
    }
    // A sysfs attribute is a few bytes; read at most 64 so that a wrong path (/dev/zero, a big
    // file) cannot make us read without end.
    std::string text(64, '\0');
    in.read(text.data(), static_cast<std::streamsize>(text.size()));
    text.resize(static_cast<std::size_t>(in.gcount()));
    if (const auto nl = text.find('\n'); nl != std::string::npos) {
        text.resize(nl);
    }
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
    std::ifstream nameFile(dir / "name");
    std::getline(nameFile, d.name_);
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
        if (!(*scale > 0.0)) {
            return makeError(ErrorCode::DeviceFailure,
                             fmt::format("{}: accelerometer scale {} is not positive", dir.string(),
                                         *scale));
        }
        auto offset = axisAttribute(dir, kAxes[i], "offset", 0.0);
        if (!offset) {
            return tl::unexpected(offset.error());
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
        std::string lastError;
        std::uint32_t sequence = 0;
        bool announced = false;
        while (!queue_.stopping()) {
            if (!dev) {
                auto d = IioAccelDevice::find(options_.root, options_.name);
                if (!d) {
                    state_ = LinkState::Lost;
                    if (d.error().message != lastError) {
                        deviceLog("hal.accel")
                                ->error("{}; the display keeps its last tilt", d.error().message);
                        lastError = d.error().message;
                    }
                    if (!waitFor(options_.reconnectNs)) {
                        return;
                    }
                    continue;
                }
                if (!announced) {
                    deviceLog("hal.accel")->info("'{}' at {}", d->name(), d->dir().string());
                    announced = true;
                }
                dev = std::move(*d);
            }
            const std::int64_t started = clock_.nowNs();
            auto a = dev->readRaw();
            if (!a) {
                // A value file that exists but reads empty, junk or EIO (a glitching I2C sensor)
                // is handled like an unplugged device: Lost, one line per new error, and a retry
                // every reconnectNs, never a busy loop.
                if (a.error().message != lastError) {
                    deviceLog("hal.accel")
                            ->error("{}; the display keeps its last tilt and retries every {} ms",
                                    a.error().message, options_.reconnectNs / 1'000'000);
                    lastError = a.error().message;
                }
                dev.reset();
                state_ = LinkState::Lost;
                if (!waitFor(options_.reconnectNs)) {
                    return;
                }
                continue;
            }
            if (!lastError.empty()) {
                deviceLog("hal.accel")
                        ->info("'{}' at {} reads again", dev->name(), dev->dir().string());
                lastError.clear();
            }
            state_ = LinkState::Connected;
            auto raw = std::make_shared<RawAccelInput>();
            raw->raw = *a;
            raw->scale = dev->scale();
            raw->offset = dev->offset();
            raw->axes = axesText_;
            AccelSample s;
            s.timestampNs = clock_.nowNs();
            s.sequence = sequence++;
            s.gravity = gravityFromRaw(*raw, options_.mounting);
            s.raw = std::move(raw);
            queue_.push(s);
            if (!waitFor(options_.periodNs - (clock_.nowNs() - started))) {
                return;
            }
        }
    }

    const Clock& clock_;
    IioAccelSourceOptions options_;
    std::string axesText_;
    DeviceInfo info_;
    std::atomic<LinkState> state_{LinkState::Lost};
    LiveQueue<AccelSample> queue_{1024};
    std::thread thread_;
};

} // namespace

std::unique_ptr<AccelSource> makeIioAccelSource(const Clock& clock, IioAccelSourceOptions options)
{
    return std::make_unique<IioAccelSource>(clock, std::move(options));
}

} // namespace replica::hal::accel
