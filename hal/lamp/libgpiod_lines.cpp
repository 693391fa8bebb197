// libgpiod 1.6 adapter for the lamp selector's lines.
#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>

#include <fmt/format.h>
#include <gpiod.h>

#include <hal/lamp/libgpiod_lines.h>

namespace replica::hal::lamp {
namespace {

constexpr const char* kConsumer = "replica-lamp-selector";

std::string accessAdvice()
{
    return "install deploy/udev/60-replica.rules (gpiochip access for the plugdev group), "
           "`udevadm control --reload && udevadm trigger`, and add the appliance's user to "
           "plugdev";
}

std::string chipError(const std::string& chip, int err)
{
    if (err == EACCES || err == EPERM) {
        return fmt::format("GPIO chip '{}': permission denied; {}", chip, accessAdvice());
    }
    if (err == ENOENT || err == ENODEV || err == ENOTTY) {
        return fmt::format("GPIO chip '{}' not found ({}): check the chip name with `replica "
                           "probe` or `gpiodetect` and that the board's GPIO driver is loaded",
                           chip, std::strerror(err));
    }
    return fmt::format("GPIO chip '{}': cannot open ({})", chip, std::strerror(err));
}

class LibgpiodLines final : public GpioLines
{
public:
    LibgpiodLines(gpiod_chip* chip, GpioLineSpec spec, gpiod_line_bulk bulk)
        : chip_(chip), spec_(std::move(spec)), bulk_(bulk)
    {
        const char* label = gpiod_chip_label(chip_);
        describe_ = fmt::format("{} [{}] lines {}", gpiod_chip_name(chip_),
                                label != nullptr ? label : "", toString(spec_));
    }
    ~LibgpiodLines() override
    {
        gpiod_line_release_bulk(&bulk_);
        gpiod_chip_close(chip_);
    }
    LibgpiodLines(const LibgpiodLines&) = delete;
    LibgpiodLines& operator=(const LibgpiodLines&) = delete;

    std::string describe() const override { return describe_; }

    Expected<std::uint32_t> readLevels() override
    {
        int values[GPIOD_LINE_BULK_MAX_LINES] = {};
        if (gpiod_line_get_value_bulk(&bulk_, values) != 0) {
            return makeError(ErrorCode::DeviceFailure,
                             fmt::format("{}: reading the lines failed ({})", describe_,
                                         std::strerror(errno)));
        }
        std::uint32_t levels = 0;
        for (std::size_t i = 0; i < spec_.offsets.size(); ++i) {
            levels |= values[i] != 0 ? (1u << i) : 0u;
        }
        return levels;
    }

    Expected<std::vector<GpioEdge>> waitEdges(std::int64_t timeoutNs) override
    {
        const std::int64_t t = std::max<std::int64_t>(timeoutNs, 0);
        const timespec timeout{static_cast<time_t>(t / 1'000'000'000),
                               static_cast<long>(t % 1'000'000'000)};
        gpiod_line_bulk ready;
        gpiod_line_bulk_init(&ready);
        const int rc = gpiod_line_event_wait_bulk(&bulk_, &timeout, &ready);
        std::vector<GpioEdge> edges;
        if (rc == 0) {
            return edges;
        }
        if (rc < 0) {
            return makeError(ErrorCode::NotFound,
                             fmt::format("{}: waiting for edges failed ({}); was the GPIO chip "
                                         "removed?",
                                         describe_, std::strerror(errno)));
        }
        for (unsigned k = 0; k < gpiod_line_bulk_num_lines(&ready); ++k) {
            gpiod_line* line = gpiod_line_bulk_get_line(&ready, k);
            gpiod_line_event ev{};
            if (gpiod_line_event_read(line, &ev) != 0) {
                return makeError(ErrorCode::NotFound, fmt::format("{}: reading an edge failed ({})",
                                                                  describe_, std::strerror(errno)));
            }
            const unsigned offset = gpiod_line_offset(line);
            const auto it = std::find(spec_.offsets.begin(), spec_.offsets.end(), offset);
            edges.push_back({static_cast<std::size_t>(it - spec_.offsets.begin()),
                             ev.event_type == GPIOD_LINE_EVENT_RISING_EDGE});
        }
        return edges;
    }

private:
    gpiod_chip* chip_;
    GpioLineSpec spec_;
    gpiod_line_bulk bulk_;
    std::string describe_;
};

Expected<std::unique_ptr<GpioLines>> openLines(const GpioLineSpec& spec)
{
    errno = 0;
    gpiod_chip* chip = gpiod_chip_open_lookup(spec.chip.c_str());
    if (chip == nullptr) {
        return makeError(errno == EACCES || errno == EPERM ? ErrorCode::Io : ErrorCode::NotFound,
                         chipError(spec.chip, errno != 0 ? errno : ENOENT));
    }
    const unsigned count = gpiod_chip_num_lines(chip);
    for (unsigned o : spec.offsets) {
        if (o >= count) {
            const std::string name = gpiod_chip_name(chip);
            gpiod_chip_close(chip);
            return makeError(ErrorCode::NotFound,
                             fmt::format("GPIO chip '{}' ({}) has lines 0..{}, no line {}: fix "
                                         "--lamp-gpio",
                                         spec.chip, name, count == 0 ? 0 : count - 1, o));
        }
    }
    gpiod_line_bulk bulk;
    std::vector<unsigned> offsets = spec.offsets;
    if (gpiod_chip_get_lines(chip, offsets.data(), static_cast<unsigned>(offsets.size()), &bulk) !=
        0) {
        const int err = errno;
        gpiod_chip_close(chip);
        return makeError(ErrorCode::NotFound, fmt::format("GPIO chip '{}': lines {}: {}", spec.chip,
                                                          toString(spec), std::strerror(err)));
    }
    int rc = gpiod_line_request_bulk_both_edges_events_flags(
            &bulk, kConsumer,
            GPIOD_LINE_REQUEST_FLAG_ACTIVE_LOW | GPIOD_LINE_REQUEST_FLAG_BIAS_PULL_UP);
    if (rc != 0 && (errno == EOPNOTSUPP || errno == EINVAL)) {
        // Kernels before 5.5 cannot set bias: the board's own pull-ups must do.
        rc = gpiod_line_request_bulk_both_edges_events_flags(&bulk, kConsumer,
                                                             GPIOD_LINE_REQUEST_FLAG_ACTIVE_LOW);
    }
    if (rc != 0) {
        const int err = errno;
        gpiod_chip_close(chip);
        if (err == EBUSY) {
            return makeError(ErrorCode::Io,
                             fmt::format("GPIO chip '{}': lines {} are in use by another program "
                                         "(see `gpioinfo {}`); stop it or pick free lines",
                                         spec.chip, toString(spec), spec.chip));
        }
        if (err == EACCES || err == EPERM) {
            return makeError(ErrorCode::Io, chipError(spec.chip, err));
        }
        return makeError(ErrorCode::DeviceFailure,
                         fmt::format("GPIO chip '{}': requesting lines {} for edge events failed "
                                     "({})",
                                     spec.chip, toString(spec), std::strerror(err)));
    }
    return std::unique_ptr<GpioLines>(std::make_unique<LibgpiodLines>(chip, spec, bulk));
}

} // namespace

GpioOpener libgpiodOpener()
{
    return openLines;
}

std::vector<GpioChipInfo> listGpioChips(const std::string& devDir)
{
    std::vector<GpioChipInfo> out;
    std::error_code ec;
    for (const auto& e : std::filesystem::directory_iterator(devDir, ec)) {
        const std::string name = e.path().filename().string();
        if (!name.starts_with("gpiochip")) {
            continue;
        }
        GpioChipInfo info;
        info.path = e.path().string();
        info.name = name;
        errno = 0;
        if (gpiod_chip* chip = gpiod_chip_open(info.path.c_str())) {
            const char* label = gpiod_chip_label(chip);
            info.label = label != nullptr ? label : "";
            info.lines = gpiod_chip_num_lines(chip);
            gpiod_chip_close(chip);
        } else {
            info.error = chipError(info.path, errno != 0 ? errno : ENOENT);
        }
        out.push_back(std::move(info));
    }
    std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.path < b.path; });
    return out;
}

} // namespace replica::hal::lamp
