// Sample-to-scene conversion.
#include <cmath>

#include <fmt/format.h>

#include <pipeline/scene/stand.h>
#include <platform/logging.h>
#include <platform/loop/scene_updater.h>

namespace replica::platform {
namespace {

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

} // namespace

Expected<SceneUpdater> SceneUpdater::create(SceneUpdaterSetup setup,
                                            const pipeline::spectral::LightClassifierParams& params)
{
    if (setup.booth.lights.empty()) {
        return SceneUpdater(std::move(setup), std::nullopt);
    }
    auto classifier = pipeline::spectral::LightClassifier::create(lampLights(setup.booth), params);
    if (!classifier) {
        return makeError(classifier.error().code,
                         "booth '" + setup.booth.id + "': " + classifier.error().message);
    }
    return SceneUpdater(std::move(setup), std::move(*classifier));
}

pipeline::spectral::Classification SceneUpdater::classification() const
{
    return classifier_ ? classifier_->currentClassification()
                       : pipeline::spectral::Classification{};
}

void SceneUpdater::showLamp(pipeline::scene::SceneState& state, int lamp) const
{
    const auto& l = setup_.booth.lights[static_cast<std::size_t>(lamp)];
    state.lampIndex = lamp;
    state.illuminant = l.referenceSpectrum;
    state.emitterLuminanceCdM2 = l.nominalLuminanceCdM2;
}

void SceneUpdater::start(pipeline::scene::SceneState& state)
{
    started_ = true;
    state.eyeBoothM = setup_.defaultEyeM;
    state.tiltRad = setup_.defaultTiltRad;
    if (setup_.defaultLamp >= 0 &&
        setup_.defaultLamp < static_cast<int>(setup_.booth.lights.size())) {
        showLamp(state, setup_.defaultLamp);
    }
}

void SceneUpdater::update(pipeline::scene::SceneState& state,
                          const hal::SpectrumSample* spectrum,
                          const hal::PoseSample* pose,
                          const hal::AccelSample* accel,
                          const hal::LampSample* selector)
{
    const bool first = !started_;
    if (first) {
        start(state);
    }
    const bool hadSpectrum = haveSpectrum_;
    const bool hadPose = havePose_;
    const bool hadTilt = haveTilt_;
    if (selector != nullptr && selector->sequence != lastSelector_) {
        lastSelector_ = selector->sequence;
        if (const auto lamp = arbiter_.onSelector(*selector)) {
            showLamp(state, *lamp); // a turn of the switch shows at once
        }
    }
    if (spectrum != nullptr && spectrum->sequence != lastSpectrum_) {
        lastSpectrum_ = spectrum->sequence;
        pipeline::spectral::RawSpectrum raw{spectrum->counts, spectrum->integrationTimeUs,
                                            spectrum->wavelengthCoeffs,
                                            spectrum->nonlinearityCoeffs};
        auto spd = pipeline::spectral::countsToSpectrum(raw, setup_.calibration);
        // A saturated spectrum has lost its peaks: its shape cannot be trusted, keep the last
        // light.
        if (spd && !spectrum->saturated) {
            const int lamp = arbiter_.onClassified(classifier_ ? classifier_->classify(*spd) : -1,
                                                   spectrum->timestampNs);
            if (auto warning = arbiter_.takeWarning()) {
                logger("loop")->warn("{}", *warning);
            }
            haveSpectrum_ = true;
            state.lampIndex = lamp;
            if (lamp >= 0) {
                showLamp(state, lamp);
            } else {
                // Direct-sensor mode: the sensed shape, at the booth's typical luminance.
                state.illuminant = *spd;
                state.emitterLuminanceCdM2 = meanLuminance(setup_.booth);
            }
        } else {
            ++rejectedSpectra_;
        }
    }
    if (pose != nullptr && pose->sequence != lastPose_) {
        lastPose_ = pose->sequence;
        const glm::dvec3 e = pose->eyeTrackerM;
        if (pose->tracked && std::isfinite(e.x) && std::isfinite(e.y) && std::isfinite(e.z)) {
            state.eyeBoothM = setup_.trackerInBooth.apply(e);
            havePose_ = true;
        } else {
            ++rejectedPoses_;
        }
    }
    if (accel != nullptr && accel->sequence != lastAccel_) {
        lastAccel_ = accel->sequence;
        if (auto tilt = pipeline::scene::tiltFromGravity(accel->gravity)) {
            state.tiltRad = *tilt;
            haveTilt_ = true;
        } else {
            ++rejectedTilts_;
        }
    }
    // Says in the log when each sensor first gives the scene a value (before that the defaults
    // show), so that a sensor missing at boot is visible in the journal.
    auto log = logger("loop");
    if (first || (!hadSpectrum && haveSpectrum_) || (!hadPose && havePose_) ||
        (!hadTilt && haveTilt_)) {
        if (!haveSpectrum_ || !havePose_ || !haveTilt_) {
            log->info(
                    "frame {}: {}{}{}", state.frameIndex,
                    haveSpectrum_ ? "light sensed; "
                    : setup_.defaultLamp >= 0
                            ? fmt::format(
                                      "no spectrum yet: showing the default lamp '{}'; ",
                                      setup_.booth
                                              .lights[static_cast<std::size_t>(setup_.defaultLamp)]
                                              .name)
                            : std::string("no spectrum yet and no default lamp: no light; "),
                    havePose_ ? "eye tracked; " : "no head pose yet: default eye; ",
                    haveTilt_ ? "tilt sensed" : "no tilt yet: default tilt");
        } else {
            log->info("frame {}: every sensor now feeds the scene", state.frameIndex);
        }
    }
}

} // namespace replica::platform
