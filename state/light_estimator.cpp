// Spectrum -> classified (or sensed) light -> encoding decision.
#include <algorithm>
#include <cmath>
#include <numeric>

#include <nlohmann/json.hpp>
#include <state/json_state.h>
#include <state/light_estimator.h>

#include <hal/spectrometer/usb2000_protocol.h>

namespace replica::state {
namespace {

namespace usb2000 = hal::spectrometer::usb2000;

// Why a spectrum is not converted at all ("" when it is).
std::string unusable(const hal::SpectrumSample& s)
{
    if (s.saturated) {
        return "saturated (a pixel at full scale): shorten the integration time or dim the light";
    }
    if (s.integrationTimeUs < usb2000::kMinIntegrationUs ||
        s.integrationTimeUs > usb2000::kMaxIntegrationUs) {
        return fmt::format("an integration time of {} us, outside the USB2000+'s {}..{} us",
                           s.integrationTimeUs, usb2000::kMinIntegrationUs,
                           usb2000::kMaxIntegrationUs);
    }
    return "";
}

std::vector<pipeline::spectral::StoredLight> lampLights(const pipeline::booth::Booth& booth)
{
    std::vector<pipeline::spectral::StoredLight> out;
    for (const auto& lamp : booth.lights) {
        out.push_back({lamp.name, lamp.referenceSpectrum});
    }
    return out;
}

double meanLuminance(const pipeline::booth::Booth& booth)
{
    double sum = 0.0;
    for (const auto& lamp : booth.lights) {
        sum += lamp.nominalLuminanceCdM2;
    }
    return booth.lights.empty() ? 0.0 : sum / static_cast<double>(booth.lights.size());
}

nlohmann::json chainJson(const pipeline::spectral::LiveSpectrometerChain::State& s)
{
    return {{"window", s.window},
            {"offset_nm", s.offsetNm},
            {"integration_time_us", s.integrationTimeUs},
            {"wavelength_coeffs", s.wavelengthCoeffs},
            {"nonlinearity_coeffs", s.nonlinearityCoeffs}};
}

pipeline::spectral::LiveSpectrometerChain::State chainFromJson(const nlohmann::json& j)
{
    pipeline::spectral::LiveSpectrometerChain::State s;
    s.window = j.at("window").get<std::vector<std::vector<std::uint16_t>>>();
    s.offsetNm = finiteFromJson(j.at("offset_nm"));
    s.integrationTimeUs = j.at("integration_time_us").get<std::uint32_t>();
    s.wavelengthCoeffs = j.at("wavelength_coeffs").get<std::array<double, 4>>();
    s.nonlinearityCoeffs = j.at("nonlinearity_coeffs").get<std::array<double, 8>>();
    return s;
}

} // namespace

double directLuminance(const LightEstimatorSetup& setup, const pipeline::colour::Spectrum& spd)
{
    if (setup.directCdM2PerY == 0.0) {
        return meanLuminance(setup.booth);
    }
    // A reading whose Y is negative (noise on no light) renders black, not a negative light.
    return std::max(0.0,
                    setup.directCdM2PerY * pipeline::colour::spectrumToXyz(setup.observer, spd).y);
}

Expected<LightEstimator> LightEstimator::create(LightEstimatorSetup setup)
{
    if (setup.booth.lights.empty()) {
        return LightEstimator(std::move(setup), std::nullopt);
    }
    auto classifier =
            pipeline::spectral::LightClassifier::create(lampLights(setup.booth), setup.classifier);
    if (!classifier) {
        return makeError(classifier.error().code,
                         "booth '" + setup.booth.id + "': " + classifier.error().message);
    }
    return LightEstimator(std::move(setup), std::move(*classifier));
}

pipeline::spectral::Classification LightEstimator::classification() const
{
    return classifier_ ? classifier_->currentClassification()
                       : pipeline::spectral::Classification{};
}

void LightEstimator::showLamp(int lamp)
{
    const auto& l = setup_.booth.lights[static_cast<std::size_t>(lamp)];
    lamp_ = lamp;
    spd_ = l.referenceSpectrum;
    luminance_ = l.nominalLuminanceCdM2;
}

void LightEstimator::start()
{
    if (setup_.defaultLamp >= 0 &&
        setup_.defaultLamp < static_cast<int>(setup_.booth.lights.size())) {
        showLamp(setup_.defaultLamp);
    }
}

void LightEstimator::update(const hal::SpectrumSample* spectrum, const hal::LampSample* selector)
{
    if (selector != nullptr && selector->sequence != lastSelector_) {
        lastSelector_ = selector->sequence;
        // Forced direct-sensor mode: a turn of the switch is not shown (the recording keeps it).
        if (const auto lamp = setup_.forceDirect ? std::nullopt : arbiter_.onSelector(*selector)) {
            showLamp(*lamp); // a turn of the switch shows at once
        }
    }
    if (spectrum != nullptr && spectrum->sequence != lastSpectrum_) {
        lastSpectrum_ = spectrum->sequence;
        pipeline::spectral::RawSpectrum raw{spectrum->counts, spectrum->integrationTimeUs,
                                            spectrum->wavelengthCoeffs,
                                            spectrum->nonlinearityCoeffs};
        // A saturated spectrum has lost its peaks: its shape cannot be trusted, keep the last
        // light (and leave it out of the average). So is one whose integration time no USB2000+
        // takes: the level divides by it (1 us would read a lamp a thousand times too bright).
        const std::string refused = unusable(*spectrum);
        auto spd = refused.empty() ? chain_.add(raw)
                                   : Expected<pipeline::colour::Spectrum>(
                                             makeError(ErrorCode::InvalidArgument, refused));
        if (spd && weak(*spectrum)) {
            showWeak(*spd);
        } else if (spd) {
            showingWeak_ = false;
            const int lamp =
                    setup_.forceDirect
                            ? -1
                            : arbiter_.onClassified(classifier_ ? classifier_->classify(*spd) : -1,
                                                    spectrum->timestampNs);
            haveSpectrum_ = true;
            if (lamp >= 0) {
                showLamp(lamp);
            } else {
                // Direct-sensor mode: the sensed spectrum, at the sensed level.
                lamp_ = -1;
                spd_ = *spd;
                luminance_ = directLuminance(setup_, *spd);
            }
        } else {
            ++rejected_;
            lastRefusal_ = spd.error().message;
        }
    }
}

bool LightEstimator::weak(const hal::SpectrumSample& s) const
{
    const auto level = pipeline::spectral::signalLevel(s.counts, setup_.calibration);
    return level.peakAboveDark <
           pipeline::spectral::kMinPeakOverDarkNoise * std::max(level.darkNoise, 1.0);
}

void LightEstimator::showWeak(const pipeline::colour::Spectrum& reading)
{
    // Too little light to tell its colour, enough to say how much: the colour shown stays (the
    // lamp's spectrum, or the sensed one), at the reading's level in direct-sensor mode, and the
    // classifier is not asked (its noise would pass for a light of its own). A dark room shows
    // the surface dark in the light it last had, not lit, and not in a colour that changes with
    // every spectrum. With nothing shown before, the reading is all there is.
    // The level by Y (the band sum where the setup has no observer: a level is all it is for).
    const bool haveObserver =
            std::any_of(setup_.observer.ybar.v.begin(), setup_.observer.ybar.v.end(),
                        [](double v) { return v > 0.0; });
    const auto level = [&](const pipeline::colour::Spectrum& s) {
        return haveObserver ? pipeline::colour::spectrumToXyz(setup_.observer, s).y
                            : std::accumulate(s.v.begin(), s.v.end(), 0.0);
    };
    const double read = level(reading);
    const double shown = level(spd_);
    pipeline::colour::Spectrum shape = reading;
    if (shown > 0.0 && std::isfinite(read)) {
        shape = spd_;
        for (double& v : shape.v) {
            v *= std::max(read, 0.0) / shown;
        }
    }
    haveSpectrum_ = true;
    ++weak_;
    showingWeak_ = true;
    lamp_ = -1;
    spd_ = shape;
    luminance_ = directLuminance(setup_, shape);
}

std::vector<pipeline::colour::Spectrum> LightEstimator::encodeSpectra(const LightEstimatorSetup& s)
{
    // What the booth pass draws each lamp with: its booth light's spectrum (the booth data).
    std::vector<pipeline::colour::Spectrum> out;
    for (const auto& lamp : s.booth.lights) {
        out.push_back(lamp.spd);
    }
    return out;
}

void EncodingDecision::write(pipeline::scene::SceneState& state)
{
    if (adaptive_ && state.lightChanged) {
        const bool lamp = state.lampIndex >= 0 &&
                          static_cast<std::size_t>(state.lampIndex) < lampSpectra_.size();
        const pipeline::colour::Spectrum& spd =
                lamp ? lampSpectra_[static_cast<std::size_t>(state.lampIndex)] : state.illuminant;
        // A lamp change always re-encodes (unless already encoded for exactly that spectrum);
        // the direct-sensor mode only past reencodeDistance.
        const bool keep = encoding_ > 0 && (lamp ? spd.v == encodedFor_.v
                                                 : pipeline::spectral::spectralShapeDistance(
                                                           spd, encodedFor_) <= reencodeDistance_);
        if (!keep) {
            // No luminance or a non-finite band: keep the encoding there is.
            if (auto basis = adaptive_->basisFor(spd)) {
                basis_ = std::make_shared<const pipeline::colour::ChannelBasis>(std::move(*basis));
                encodedFor_ = spd;
                ++encoding_;
            }
        }
    }
    state.encoding = encoding_;
    state.basis = basis_;
    state.encodedFor = encodedFor_;
}

nlohmann::json EncodingDecision::save() const
{
    return {{"encoding", encoding_}, {"encoded_for", encodedFor_.v}};
}

Expected<void> EncodingDecision::restore(const nlohmann::json& j)
{
    try {
        encoding_ = j.at("encoding").get<int>();
        encodedFor_ = spectrumFromJson(j.at("encoded_for"));
    } catch (const std::exception& e) {
        return makeError(ErrorCode::InvalidArgument, fmt::format("encoding: {}", e.what()));
    }
    basis_.reset();
    if (encoding_ < 0 || (encoding_ > 0 && !adaptive_)) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("encoding {} without a light-adaptive encoder", encoding_));
    }
    if (encoding_ > 0) {
        auto basis = adaptive_->basisFor(encodedFor_);
        if (!basis) {
            return makeError(ErrorCode::InvalidArgument,
                             "the saved encoding's light makes no basis: " + basis.error().message);
        }
        basis_ = std::make_shared<const pipeline::colour::ChannelBasis>(std::move(*basis));
    }
    return {};
}

void LightEstimator::write(pipeline::scene::SceneState& state)
{
    // Changed: another content key (pipeline::scene::lightKey: another lamp, or in direct-sensor
    // mode another spectrum or luminance), the key the renderer labels the light it holds with.
    const bool changed = !written_ || pipeline::scene::lightKey(lamp_, spd_, luminance_) !=
                                              pipeline::scene::lightKey(writtenLamp_, writtenSpd_,
                                                                        writtenLuminance_);
    written_ = true;
    writtenLamp_ = lamp_;
    writtenSpd_ = spd_;
    writtenLuminance_ = luminance_;
    state.lampIndex = lamp_;
    state.illuminant = spd_;
    state.emitterLuminanceCdM2 = luminance_;
    state.lightChanged = changed;
    encoding_.write(state);
}

nlohmann::json LightEstimator::save() const
{
    const auto c = classifier_ ? classifier_->state() : pipeline::spectral::LightClassifierState{};
    const auto a = arbiter_.state();
    return {{"last_spectrum", optionalJson(lastSpectrum_)},
            {"last_selector", optionalJson(lastSelector_)},
            {"have_spectrum", haveSpectrum_},
            {"rejected", rejected_},
            {"lamp", lamp_},
            {"spd", spd_.v},
            {"luminance", luminance_},
            {"written", written_},
            {"written_lamp", writtenLamp_},
            {"written_spd", writtenSpd_.v},
            {"written_luminance", writtenLuminance_},
            {"classifier",
             {{"current", c.current.index},
              {"distance", c.current.distance},
              {"candidate", c.candidate},
              {"count", c.candidateCount}}},
            {"arbiter",
             {{"selected", a.selected},
              {"trusted", a.trusted},
              {"disagree_since_ns", optionalJson(a.disagreeSinceNs)},
              {"overruled", a.overruled},
              {"warned", a.warned}}},
            {"encoding", encoding_.save()},
            {"chain", chainJson(chain_.state())}};
}

Expected<void> LightEstimator::restore(const nlohmann::json& j)
{
    try {
        const int lamps = static_cast<int>(setup_.booth.lights.size());
        const auto lampIndex = [&](const nlohmann::json& v, const char* what) {
            const int i = v.get<int>();
            if (i < -1 || i >= lamps) {
                throw std::out_of_range(
                        fmt::format("{} {} is not one of the booth's {} lamps", what, i, lamps));
            }
            return i;
        };
        lastSpectrum_ = optionalFromJson<std::uint32_t>(j.at("last_spectrum"));
        lastSelector_ = optionalFromJson<std::uint32_t>(j.at("last_selector"));
        haveSpectrum_ = j.at("have_spectrum").get<bool>();
        rejected_ = j.at("rejected").get<std::uint64_t>();
        lamp_ = lampIndex(j.at("lamp"), "lamp");
        spd_ = spectrumFromJson(j.at("spd"));
        luminance_ = finiteFromJson(j.at("luminance"));
        written_ = j.at("written").get<bool>();
        writtenLamp_ = lampIndex(j.at("written_lamp"), "lamp");
        writtenSpd_ = spectrumFromJson(j.at("written_spd"));
        writtenLuminance_ = finiteFromJson(j.at("written_luminance"));
        const auto& c = j.at("classifier");
        if (classifier_) {
            pipeline::spectral::LightClassifierState s;
            const int current = lampIndex(c.at("current"), "classified lamp");
            if (current >= 0) {
                s.current.index = current;
                s.current.name = setup_.booth.lights[static_cast<std::size_t>(current)].name;
            }
            s.current.distance = finiteFromJson(c.at("distance"));
            s.candidate = lampIndex(c.at("candidate"), "candidate lamp");
            s.candidateCount = c.at("count").get<int>();
            classifier_->restore(s);
        }
        const auto& a = j.at("arbiter");
        LampArbiterState s;
        s.selected = lampIndex(a.at("selected"), "selected lamp");
        s.trusted = a.at("trusted").get<bool>();
        s.disagreeSinceNs = optionalFromJson<std::int64_t>(a.at("disagree_since_ns"));
        s.overruled = a.at("overruled").get<std::uint64_t>();
        s.warned = a.at("warned").get<bool>();
        arbiter_.restore(s);
        // Absent in states saved before the live chain averaged: an empty average.
        chain_.restore(j.contains("chain") ? chainFromJson(j.at("chain"))
                                           : pipeline::spectral::LiveSpectrometerChain::State{});
        if (auto ok = encoding_.restore(j.at("encoding")); !ok) {
            return makeError(ok.error().code, "light: " + ok.error().message);
        }
    } catch (const std::exception& e) {
        return makeError(ErrorCode::InvalidArgument, fmt::format("light: {}", e.what()));
    }
    return {};
}

} // namespace replica::state
