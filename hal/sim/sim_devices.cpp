// Simulated devices on virtual time.
#include <algorithm>
#include <cmath>
#include <deque>
#include <utility>

#include <hal/lamp/lamp_debouncer.h>
#include <hal/sim/noise.h>
#include <hal/sim/sim_devices.h>
#include <pipeline/base/interpolate.h>

namespace replica::hal::sim {
namespace {

double pixelWavelength(int p)
{
    const double x = p;
    return kSimWavelengthCoeffs[0] +
           x * (kSimWavelengthCoeffs[1] +
                x * (kSimWavelengthCoeffs[2] + x * kSimWavelengthCoeffs[3]));
}

class SimSpectrometer final : public SpectrometerSource
{
public:
    SimSpectrometer(ScenarioParams scenario, SimSpectrometerParams params)
        : scenario_(scenario), params_(std::move(params)), noise_(params_.seed)
    {
        info_ = DeviceInfo{"USB2000+ (simulated)", "SIM-USB2K-0001", "sim", SourceKind::Sim};
        // Noise-free signal per lamp at the configured integration time, scaled so the brightest
        // pixel reaches peakCounts (the auto-integration target of a real instrument).
        for (const auto& lamp : params_.lamps) {
            std::vector<double> signal(kSimPixels, 0.0);
            double peak = 0.0;
            for (int p = kSimDarkPixelLast + 1; p < kSimPixels; ++p) {
                const double wl = pixelWavelength(p);
                signal[static_cast<std::size_t>(p)] =
                        pipeline::interpolateLinear(lamp.wavelengthNm, lamp.power, wl,
                                                    pipeline::Outside::Zero) *
                        pipeline::interpolateLinear(params_.responsivityNm, params_.responsivity,
                                                    wl, pipeline::Outside::Zero);
                peak = std::max(peak, signal[static_cast<std::size_t>(p)]);
            }
            const double scale = peak > 0.0 ? params_.peakCounts / peak : 0.0;
            for (double& s : signal) {
                s *= scale;
            }
            signals_.push_back(std::move(signal));
        }
    }

    const DeviceInfo& info() const override { return info_; }
    LinkState state() const override { return LinkState::Connected; }

    void poll(std::int64_t untilNs, std::vector<SpectrumSample>& out) override
    {
        const std::int64_t integrationNs = std::int64_t{params_.integrationTimeUs} * 1000;
        while (next_ * params_.periodNs + integrationNs <= untilNs) {
            const std::int64_t startNs = next_ * params_.periodNs;
            out.push_back(acquire(startNs, startNs + integrationNs));
            ++next_;
        }
    }

private:
    SpectrumSample acquire(std::int64_t startNs, std::int64_t endNs)
    {
        SpectrumSample s;
        s.timestampNs = endNs;
        s.sequence = static_cast<std::uint32_t>(next_);
        s.integrationTimeUs = params_.integrationTimeUs;
        s.wavelengthCoeffs = {kSimWavelengthCoeffs[0], kSimWavelengthCoeffs[1],
                              kSimWavelengthCoeffs[2], kSimWavelengthCoeffs[3]};
        s.nonlinearityCoeffs = {1.0, params_.nonlinearityK1, 0, 0, 0, 0, 0, 0};
        const int lamp = scenarioAt(scenario_, (startNs + endNs) / 2).lamp;
        const std::vector<double>* signal =
                lamp >= 0 && static_cast<std::size_t>(lamp) < signals_.size()
                        ? &signals_[static_cast<std::size_t>(lamp)]
                        : nullptr;
        s.counts.resize(kSimPixels);
        for (int p = 0; p < kSimPixels; ++p) {
            const double sig = signal != nullptr ? (*signal)[static_cast<std::size_t>(p)] : 0.0;
            // Shot noise grows with the square root of the signal; read noise is constant.
            const double shot = 0.8 * std::sqrt(std::max(sig, 0.0)) * noise_.gaussian();
            const double read = params_.readNoiseCounts * noise_.gaussian();
            // The collected charge (signal and its shot noise) passes through the detector's
            // compressive response; read noise and the electrical dark offset come after it.
            const double linear = sig + shot;
            const double denom = 1.0 - params_.nonlinearityK1 * linear;
            const double measured = denom > 1e-3 ? linear / denom : linear;
            const double counts = std::round(params_.darkCounts + measured + read);
            const double clamped = std::clamp(counts, 0.0, 65535.0);
            s.saturated = s.saturated || clamped >= 65535.0;
            s.counts[static_cast<std::size_t>(p)] = static_cast<std::uint16_t>(clamped);
        }
        return s;
    }

    ScenarioParams scenario_;
    SimSpectrometerParams params_;
    Noise noise_;
    DeviceInfo info_;
    std::vector<std::vector<double>> signals_;
    std::int64_t next_ = 0;
};

class SimTracker final : public TrackerSource
{
public:
    SimTracker(ScenarioParams scenario, SimTrackerParams params)
        : scenario_(scenario), params_(params), noise_(params.seed)
    {
        info_ = DeviceInfo{"TrackIR (simulated)", "SIM-TRACKIR-0001", "sim", SourceKind::Sim};
    }
    const DeviceInfo& info() const override { return info_; }
    LinkState state() const override { return LinkState::Connected; }
    void poll(std::int64_t untilNs, std::vector<PoseSample>& out) override
    {
        while (next_ * params_.periodNs <= untilNs) {
            const std::int64_t t = next_ * params_.periodNs;
            const ScenarioState st = scenarioAt(scenario_, t);
            PoseSample s;
            s.timestampNs = t;
            s.sequence = static_cast<std::uint32_t>(next_);
            s.tracked = st.tracked;
            if (st.tracked) {
                const glm::dvec3 jitter{noise_.gaussian(), noise_.gaussian(), noise_.gaussian()};
                s.eyeTrackerM = params_.trackerInBooth.applyInverse(st.eyeBoothM) +
                                jitter * params_.jitterM;
            }
            out.push_back(s);
            ++next_;
        }
    }

private:
    ScenarioParams scenario_;
    SimTrackerParams params_;
    Noise noise_;
    DeviceInfo info_;
    std::int64_t next_ = 0;
};

class SimAccel final : public AccelSource
{
public:
    SimAccel(ScenarioParams scenario, SimAccelParams params)
        : scenario_(scenario), params_(params), noise_(params.seed)
    {
        info_ = DeviceInfo{"accelerometer (simulated)", "SIM-ACCEL-0001", "sim", SourceKind::Sim};
    }
    const DeviceInfo& info() const override { return info_; }
    LinkState state() const override { return LinkState::Connected; }
    void poll(std::int64_t untilNs, std::vector<AccelSample>& out) override
    {
        constexpr double kStandardGravity = 9.80665;
        while (next_ * params_.periodNs <= untilNs) {
            const std::int64_t t = next_ * params_.periodNs;
            const double tilt = scenarioAt(scenario_, t).tiltRad;
            AccelSample s;
            s.timestampNs = t;
            s.sequence = static_cast<std::uint32_t>(next_);
            // Panel frame: y up the panel, z out of the screen. Tilting back by theta turns the
            // panel's y axis to (0, cos, -sin) and its normal to (0, sin, cos) in the booth frame.
            s.gravity = glm::dvec3{0.0, -kStandardGravity * std::cos(tilt),
                                   -kStandardGravity * std::sin(tilt)};
            s.gravity += glm::dvec3{noise_.gaussian(), noise_.gaussian(), noise_.gaussian()} *
                         params_.noiseMs2;
            // Raw in, processed out, as an IIO device in m/s^2 would give it: the reading (the
            // reaction to gravity) with scale 1 and offset -0.0, mounted as is. Adding -0.0 and
            // multiplying by 1 change no double (not even +0.0), so the live processing gives
            // back exactly this sample.
            auto raw = std::make_shared<RawAccelInput>();
            raw->raw = {-s.gravity.x, -s.gravity.y, -s.gravity.z};
            raw->scale = {1.0, 1.0, 1.0};
            raw->offset = {-0.0, -0.0, -0.0};
            s.raw = std::move(raw);
            out.push_back(s);
            ++next_;
        }
    }

private:
    ScenarioParams scenario_;
    SimAccelParams params_;
    Noise noise_;
    DeviceInfo info_;
    std::int64_t next_ = 0;
};

class SimLampSelector final : public LampSelectorSource
{
public:
    SimLampSelector(ScenarioParams scenario, SimLampSelectorParams params)
        : scenario_(scenario), params_(std::move(params)), debouncer_(params_.debounceNs)
    {
        info_ = DeviceInfo{"lamp selector (simulated)", "SIM-LAMPSEL-0001", "sim", SourceKind::Sim};
        lineCount_ = std::max(scenario_.lampCount, 1);
        for (int i : params_.wiring) {
            lineCount_ = std::max(lineCount_, i + 1);
        }
        lineCount_ = std::min(lineCount_, 32);
    }
    const DeviceInfo& info() const override { return info_; }
    LinkState state() const override { return LinkState::Connected; }

    void poll(std::int64_t untilNs, std::vector<LampSample>& out) override
    {
        if (untilNs < 0) {
            return;
        }
        if (!started_) {
            started_ = true;
            const auto s = debouncer_.start(levelsOf(scenarioAt(scenario_, 0).lamp), 0);
            out.push_back(make(s));
        }
        const auto periodNs = static_cast<std::int64_t>(std::llround(scenario_.lampPeriodS * 1e9));
        // Generate the raw edges of every turn of the knob that has begun by untilNs.
        while (periodNs > 0 && scenario_.lampCount > 1 && nextTurn_ * periodNs <= untilNs) {
            addTurn(nextTurn_ * periodNs, nextTurn_);
            ++nextTurn_;
        }
        while (!edges_.empty() && edges_.front().first <= untilNs) {
            const auto [t, levels] = edges_.front();
            edges_.pop_front();
            if (auto s = debouncer_.settle(t)) {
                out.push_back(make(*s));
            }
            debouncer_.observe(levels, t);
        }
        if (auto s = debouncer_.settle(untilNs)) {
            out.push_back(make(*s));
        }
    }

private:
    std::uint32_t levelsOf(int lamp) const
    {
        if (lamp < 0) {
            return 0;
        }
        const int line = static_cast<std::size_t>(lamp) < params_.wiring.size()
                                 ? params_.wiring[static_cast<std::size_t>(lamp)]
                                 : lamp;
        return line >= 0 && line < lineCount_ ? (1u << line) : 0u;
    }

    LampSample make(const lamp::SettledLevels& s)
    {
        return lamp::settledSample(s, static_cast<std::uint32_t>(lineCount_), sequence_++);
    }

    // The edges of turn k at tNs, from its own noise stream so that they do not depend on how the
    // loop happened to poll.
    void addTurn(std::int64_t tNs, std::int64_t k)
    {
        const std::uint32_t from = levelsOf(scenarioAt(scenario_, tNs - 1).lamp);
        const std::uint32_t to = levelsOf(scenarioAt(scenario_, tNs).lamp);
        if (from == to) {
            return;
        }
        Noise noise(params_.seed * 0x9e3779b97f4a7c15ULL + static_cast<std::uint64_t>(k));
        const auto bounce = static_cast<double>(params_.bounceNs);
        const auto at = [&](double fraction) {
            return tNs + static_cast<std::int64_t>(std::llround(fraction * bounce));
        };
        // Break: the old contact opens, touches once more, opens for good.
        edges_.push_back({tNs, 0});
        edges_.push_back({at(0.05 + 0.05 * noise.uniform()), from});
        edges_.push_back({at(0.12 + 0.05 * noise.uniform()), 0});
        // Make: the new contact closes after a gap and chatters an odd number of times.
        double f = 0.25 + 0.1 * noise.uniform();
        const int chatter = 2 * (1 + static_cast<int>(noise.uniform() * 3.0)) + 1;
        for (int i = 0; i < chatter; ++i) {
            edges_.push_back({at(f), (i % 2 == 0) ? to : 0});
            f += (0.95 - f) / static_cast<double>(chatter - i) * (0.5 + noise.uniform());
            f = std::min(f, 1.0);
        }
        // Keep the edges in time order (rounding can tie, never reverse).
        std::stable_sort(edges_.begin(), edges_.end(),
                         [](const auto& a, const auto& b) { return a.first < b.first; });
    }

    ScenarioParams scenario_;
    SimLampSelectorParams params_;
    lamp::LampDebouncer debouncer_;
    DeviceInfo info_;
    int lineCount_ = 1;
    bool started_ = false;
    std::int64_t nextTurn_ = 1;
    std::uint32_t sequence_ = 0;
    std::deque<std::pair<std::int64_t, std::uint32_t>> edges_;
};

} // namespace

std::unique_ptr<LampSelectorSource> makeSimLampSelector(ScenarioParams scenario,
                                                        SimLampSelectorParams params)
{
    return std::make_unique<SimLampSelector>(scenario, std::move(params));
}

std::unique_ptr<SpectrometerSource> makeSimSpectrometer(ScenarioParams scenario,
                                                        SimSpectrometerParams params)
{
    return std::make_unique<SimSpectrometer>(scenario, std::move(params));
}

std::unique_ptr<TrackerSource> makeSimTracker(ScenarioParams scenario, SimTrackerParams params)
{
    return std::make_unique<SimTracker>(scenario, params);
}

std::unique_ptr<AccelSource> makeSimAccel(ScenarioParams scenario, SimAccelParams params)
{
    return std::make_unique<SimAccel>(scenario, params);
}

} // namespace replica::hal::sim
