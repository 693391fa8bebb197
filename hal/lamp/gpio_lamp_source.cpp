// The lamp selector's driver: debounced one-hot decoding on a thread of its own.
#include <atomic>
#include <sstream>
#include <thread>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <hal/lamp/gpio_lamp_source.h>
#include <hal/live_queue.h>
#include <hal/log.h>

namespace replica::hal::lamp {

Expected<GpioLineSpec> parseGpioLineSpec(const std::string& text)
{
    const auto bad = [&](const std::string& why) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("--lamp-gpio '{}': {}; expected CHIP:OFFSET,OFFSET,... with "
                                     "one line per booth lamp in lamp order, e.g. "
                                     "gpiochip0:17,27,22",
                                     text, why));
    };
    const auto colon = text.rfind(':');
    if (colon == std::string::npos || colon == 0) {
        return bad("no chip before ':'");
    }
    GpioLineSpec spec;
    spec.chip = text.substr(0, colon);
    std::stringstream in(text.substr(colon + 1));
    std::string item;
    while (std::getline(in, item, ',')) {
        unsigned v = 0;
        std::size_t used = 0;
        try {
            const unsigned long parsed = std::stoul(item, &used, 10);
            if (parsed > 65535) {
                return bad(fmt::format("line offset {} out of range", item));
            }
            v = static_cast<unsigned>(parsed);
        } catch (const std::exception&) {
            used = 0;
        }
        if (item.empty() || used != item.size() || item[0] == '-' || item[0] == '+') {
            return bad(fmt::format("'{}' is not a line offset", item));
        }
        for (unsigned o : spec.offsets) {
            if (o == v) {
                return bad(fmt::format("line {} given twice", v));
            }
        }
        spec.offsets.push_back(v);
    }
    if (spec.offsets.empty() || text.back() == ',') {
        return bad("no line offsets");
    }
    if (spec.offsets.size() > 32) {
        return bad("more than 32 lines");
    }
    return spec;
}

std::string toString(const GpioLineSpec& spec)
{
    return fmt::format("{}:{}", spec.chip, fmt::join(spec.offsets, ","));
}

LampSelectorReader::LampSelectorReader(std::unique_ptr<GpioLines> lines,
                                       std::size_t lineCount,
                                       const Clock& clock,
                                       std::int64_t debounceNs)
    : lines_(std::move(lines)), lineCount_(static_cast<std::uint32_t>(lineCount)),
      mask_(lineMask(lineCount)), clock_(clock), debouncer_(debounceNs)
{}

Expected<LampSample> LampSelectorReader::start(std::uint32_t sequence)
{
    auto levels = lines_->readLevels();
    if (!levels) {
        return tl::unexpected(levels.error());
    }
    const auto settled = debouncer_.start(*levels & mask_, clock_.nowNs());
    return settledSample(settled, lineCount_, sequence);
}

Expected<std::optional<LampSample>> LampSelectorReader::step(std::int64_t maxWaitNs,
                                                             std::uint32_t sequence)
{
    std::int64_t wait = maxWaitNs;
    if (const auto due = debouncer_.dueNs()) {
        wait = std::clamp<std::int64_t>(*due - clock_.nowNs(), 0, maxWaitNs);
    }
    auto edges = lines_->waitEdges(wait);
    if (!edges) {
        return tl::unexpected(edges.error());
    }
    if (!edges->empty()) {
        // The edges only wake us: the levels read now are the truth (an edge the kernel dropped
        // during a burst of bounces cannot leave us with a wrong level).
        auto levels = lines_->readLevels();
        if (!levels) {
            return tl::unexpected(levels.error());
        }
        debouncer_.observe(*levels & mask_, clock_.nowNs());
    }
    if (const auto settled = debouncer_.settle(clock_.nowNs())) {
        return std::optional<LampSample>(settledSample(*settled, lineCount_, sequence));
    }
    return std::optional<LampSample>();
}

namespace {

class GpioLampSource final : public LampSelectorSource
{
public:
    GpioLampSource(GpioOpener opener, const Clock& clock, GpioLampSourceOptions options)
        : opener_(std::move(opener)), clock_(clock), options_(std::move(options)), queue_(256)
    {
        info_.model = "lamp selector (GPIO)";
        info_.serial = toString(options_.lines);
        info_.kind = SourceKind::Live;
        thread_ = std::thread([this] { run(); });
    }
    ~GpioLampSource() override
    {
        queue_.stop();
        thread_.join();
    }
    GpioLampSource(const GpioLampSource&) = delete;
    GpioLampSource& operator=(const GpioLampSource&) = delete;

    const DeviceInfo& info() const override { return info_; }
    LinkState state() const override { return state_.load(); }
    void poll(std::int64_t untilNs, std::vector<LampSample>& out) override
    {
        queue_.drain(untilNs, out);
    }

private:
    void lost(const std::string& message, std::string& lastError)
    {
        const bool wasConnected = state_.load() == LinkState::Connected;
        state_ = LinkState::Lost;
        if (wasConnected || sequence_ == 0) {
            // Tell the loop (and the recording) that the switch no longer speaks.
            LampSample s;
            s.timestampNs = clock_.nowNs();
            s.sequence = sequence_++;
            s.lamp = kLampLost;
            s.lineCount = static_cast<std::uint32_t>(options_.lines.offsets.size());
            queue_.push(s);
        }
        if (message != lastError) {
            deviceLog("hal.lamp")
                    ->error("{}; the light is taken from the spectrometer alone, "
                            "retrying every {} ms",
                            message, options_.reconnectNs / 1'000'000);
            lastError = message;
        }
    }

    void run()
    {
        std::string lastError;
        while (!queue_.stopping()) {
            auto lines = opener_(options_.lines);
            if (!lines) {
                lost(lines.error().message, lastError);
                if (!queue_.waitFor(options_.reconnectNs)) {
                    return;
                }
                continue;
            }
            const std::string where = (*lines)->describe();
            LampSelectorReader reader(std::move(*lines), options_.lines.offsets.size(), clock_,
                                      options_.debounceNs);
            auto first = reader.start(sequence_);
            if (!first) {
                lost(first.error().message, lastError);
                if (!queue_.waitFor(options_.reconnectNs)) {
                    return;
                }
                continue;
            }
            ++sequence_;
            deviceLog("hal.lamp")
                    ->info("lamp selector on {}: {} (lines {:0{}b})", where, describe(first->lamp),
                           first->lineLevels, first->lineCount);
            lastError.clear();
            state_ = LinkState::Connected;
            queue_.push(*first);
            while (!queue_.stopping()) {
                auto s = reader.step(options_.maxWaitNs, sequence_);
                if (!s) {
                    lost(s.error().message, lastError);
                    break;
                }
                if (*s) {
                    ++sequence_;
                    deviceLog("hal.lamp")->debug("selector: {}", describe((*s)->lamp));
                    queue_.push(**s);
                }
            }
            if (!queue_.waitFor(options_.reconnectNs)) {
                return;
            }
        }
    }

    static std::string describe(int lamp)
    {
        return lamp >= 0 ? fmt::format("lamp {}", lamp) : lampStateName(lamp);
    }

    GpioOpener opener_;
    const Clock& clock_;
    GpioLampSourceOptions options_;
    DeviceInfo info_;
    std::atomic<LinkState> state_{LinkState::Lost};
    std::uint32_t sequence_ = 0; // driver thread only
    LiveQueue<LampSample> queue_;
    std::thread thread_;
};

} // namespace

std::unique_ptr<LampSelectorSource>
makeGpioLampSource(GpioOpener opener, const Clock& clock, GpioLampSourceOptions options)
{
    return std::make_unique<GpioLampSource>(std::move(opener), clock, std::move(options));
}

} // namespace replica::hal::lamp
