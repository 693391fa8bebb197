// Simulated devices on virtual time.
#include <algorithm>
#include <cmath>

#include <hal/sim/noise.h>
#include <hal/sim/sim_devices.h>

namespace replica::hal::sim {
namespace {

// Linear interpolation on an increasing grid; zero outside it (no light, no response).
double interpolate(const std::vector<double>& x, const std::vector<double>& y, double at)
{
    if (x.size() < 2 || at < x.front() || at > x.back()) {
        return 0.0;
    }
    const auto it = std::upper_bound(x.begin(), x.end(), at);
    if (it == x.end()) {
        return y.back();
    }
    const auto i = static_cast<std::size_t>(it - x.begin());
    const double t = (at - x[i - 1]) / (x[i] - x[i - 1]);
    return y[i - 1] + t * (y[i] - y[i - 1]);
}

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
                        interpolate(lamp.wavelengthNm, lamp.power, wl) *
                        interpolate(params_.responsivityNm, params_.responsivity, wl);
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
                s.eyeTrackerM = st.eyeBoothM - params_.trackerInBoothM + jitter * params_.jitterM;
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

} // namespace

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
