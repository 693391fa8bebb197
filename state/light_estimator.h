// The light estimator: spectrometer counts -> spectrum (the calibration chain) -> the classifier's
// lamp (with its hysteresis) reconciled with the lamp selector (LampArbiter) -> the light to render
// with, and, with a light-adaptive encoder, whether the surface is re-encoded for it. Every
// decision depends only on the samples it was given, so replay reproduces it.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>
#include <state/lamp_arbiter.h>

#include <hal/samples.h>
#include <pipeline/base/expected.h>
#include <pipeline/booth/booth_model.h>
#include <pipeline/colour/xyz.h>
#include <pipeline/scene/scene_state.h>
#include <pipeline/spectral/adaptive_encoding.h>
#include <pipeline/spectral/light_classifier.h>
#include <pipeline/spectral/live_chain.h>
#include <pipeline/spectral/spectrometer_chain.h>

namespace replica::state {

// The re-encode decision of a light-adaptive encoder (basis "adaptive_k6"): each new lamp (unless
// already encoded for exactly its spectrum) or a sensed shape moved by more than reencodeDistance
// gets a basis of its own (pipeline/spectral/adaptive_encoding.h); a light the encoder refuses (no
// luminance, a non-finite band) keeps the encoding there is.
class EncodingDecision
{
public:
    EncodingDecision() = default;
    // lampSpectra[i]: what lamp i is encoded for (the spectrum of its booth light).
    EncodingDecision(std::shared_ptr<const pipeline::spectral::AdaptiveEncoder> adaptive,
                     std::vector<pipeline::colour::Spectrum> lampSpectra,
                     double reencodeDistance = pipeline::spectral::kAdaptiveReencodeDistance)
        : adaptive_(std::move(adaptive)), lampSpectra_(std::move(lampSpectra)),
          reencodeDistance_(reencodeDistance)
    {}
    // For a frame whose light changed (state.lightChanged; its lamp, illuminant): decides, then
    // writes the encoding into the state (every frame).
    void write(pipeline::scene::SceneState& state);

    nlohmann::json save() const;
    Expected<void> restore(const nlohmann::json& j);

private:
    std::shared_ptr<const pipeline::spectral::AdaptiveEncoder> adaptive_;
    std::vector<pipeline::colour::Spectrum> lampSpectra_;
    double reencodeDistance_ = pipeline::spectral::kAdaptiveReencodeDistance;
    // How many re-encodes, and the light the last one was made for.
    int encoding_ = 0;
    pipeline::colour::Spectrum encodedFor_{};
    std::shared_ptr<const pipeline::colour::ChannelBasis> basis_;
};

struct LightEstimatorSetup {
    pipeline::booth::Booth booth;
    pipeline::spectral::SpectrometerCalibration calibration;
    // The live chain's corrections and averaging, and the instrument's calibration they use
    // (pipeline/spectral/live_chain.h; the run configuration's "sensing").
    pipeline::spectral::LiveChainOptions chain = pipeline::spectral::LiveChainOptions::none();
    pipeline::spectral::InstrumentCalibration instrument;
    pipeline::spectral::LightClassifierParams classifier;
    // Shown until the first usable spectrum: a booth lamp index (-1: no light).
    int defaultLamp = -1;
    // A light-adaptive encoder (basis "adaptive_k6"), none for a fixed basis: each new lamp (or a
    // sensed shape moved by more than reencodeDistance) gets a basis of its own, made for the
    // spectrum of the lamp's booth light (booth.lights[lamp].spd, what the booth pass draws it
    // with) or for the sensed spectrum (pipeline/spectral/adaptive_encoding.h).
    std::shared_ptr<const pipeline::spectral::AdaptiveEncoder> adaptive;
    double reencodeDistance = pipeline::spectral::kAdaptiveReencodeDistance;
    // Direct-sensor mode forced (the run's light "direct", the paper's mode 1): every usable
    // spectrum is rendered as it is on the booth's uniform emitter; neither the classifier nor
    // the lamp selector is consulted. Otherwise ("auto") only a spectrum the classifier does not
    // recognise is.
    bool forceDirect = false;
    // Direct-sensor mode's level: the emitter's luminance (cd/m^2) is directCdM2PerY times the
    // reading's Y (pipeline::colour::spectrumToXyz with 'observer' of the calibrated spectrum), so
    // it follows the sensed light: twice the light, twice the luminance. 0: the booth's mean
    // nominal luminance whatever the reading (what recordings made before it replay with).
    double directCdM2PerY = 0.0;
    pipeline::colour::Observer observer;
};

// The luminance (cd/m^2) direct-sensor mode renders a reading 'spd' at: directCdM2PerY times its
// Y, or with directCdM2PerY 0 the booth's mean nominal luminance.
double directLuminance(const LightEstimatorSetup& setup, const pipeline::colour::Spectrum& spd);

class LightEstimator
{
public:
    // Fails for a lamp without energy or classifier thresholds out of order. A booth without
    // lamps is always in direct-sensor mode.
    static Expected<LightEstimator> create(LightEstimatorSetup setup);

    // The first frame's light: the default lamp, else none.
    void start();
    // A new selector sample and/or spectrum (nullptr = none; a sequence number already used
    // changes nothing).
    void update(const hal::SpectrumSample* spectrum, const hal::LampSample* selector);
    // Writes the light, whether it changed since the previous frame's, and the encoding.
    void write(pipeline::scene::SceneState& state);

    bool sensed() const { return haveSpectrum_; }
    std::uint64_t rejectedSpectra() const { return rejected_; }
    // Why the last refused spectrum was refused ("" before the first).
    const std::string& lastRefusal() const { return lastRefusal_; }
    // Spectra too weak to tell a colour by (shown at their level in the colour there was).
    std::uint64_t weakSpectra() const { return weak_; }
    // Whether the light shown comes from such a reading.
    bool showingWeak() const { return showingWeak_; }
    pipeline::spectral::Classification classification() const;
    const LampArbiter& lampArbiter() const { return arbiter_; }
    // A warning to log (the arbiter's), once.
    std::optional<std::string> takeWarning() { return arbiter_.takeWarning(); }

    nlohmann::json save() const;
    Expected<void> restore(const nlohmann::json& j);

private:
    explicit LightEstimator(LightEstimatorSetup setup,
                            std::optional<pipeline::spectral::LightClassifier> classifier)
        : setup_(std::move(setup)), classifier_(std::move(classifier)),
          arbiter_(static_cast<int>(setup_.booth.lights.size())),
          chain_(setup_.calibration, setup_.instrument, setup_.chain),
          encoding_(setup_.adaptive, encodeSpectra(setup_), setup_.reencodeDistance)
    {}
    static std::vector<pipeline::colour::Spectrum> encodeSpectra(const LightEstimatorSetup& s);
    void showLamp(int lamp);
    // Whether the spectrum's brightest pixel is too close to the detector's noise to tell its
    // colour (pipeline::spectral::kMinPeakOverDarkNoise), and what is shown for such a reading.
    bool weak(const hal::SpectrumSample& s) const;
    void showWeak(const pipeline::colour::Spectrum& reading);

    LightEstimatorSetup setup_;
    std::optional<pipeline::spectral::LightClassifier> classifier_; // none: no lamps
    LampArbiter arbiter_;
    pipeline::spectral::LiveSpectrometerChain chain_;
    std::optional<std::uint32_t> lastSpectrum_;
    std::optional<std::uint32_t> lastSelector_;
    bool haveSpectrum_ = false;
    std::uint64_t rejected_ = 0;
    std::string lastRefusal_;
    std::uint64_t weak_ = 0;
    bool showingWeak_ = false;
    // The light now, and the one the previous frame rendered (none before the first frame).
    int lamp_ = -1;
    pipeline::colour::Spectrum spd_{};
    double luminance_ = 0.0;
    bool written_ = false;
    int writtenLamp_ = -1;
    pipeline::colour::Spectrum writtenSpd_{};
    double writtenLuminance_ = 0.0;
    EncodingDecision encoding_;
};

} // namespace replica::state
