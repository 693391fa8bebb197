// Sample-to-scene conversion.
#include <cmath>

#include <pipeline/scene/stand.h>
#include <platform/logging.h>
#include <platform/loop/scene_updater.h>

namespace replica::platform {
namespace {

std::vector<pipeline::spectral::StoredLight> lampLights(const pipeline::scene::Booth& booth)
{
    std::vector<pipeline::spectral::StoredLight> out;
    for (const auto& lamp : booth.lamps) {
        out.push_back({lamp.name, lamp.spectrum});
    }
    return out;
}

double meanLuminance(const pipeline::scene::Booth& booth)
{
    double sum = 0.0;
    for (const auto& lamp : booth.lamps) {
        sum += lamp.luminanceCdM2;
    }
    return booth.lamps.empty() ? 0.0 : sum / static_cast<double>(booth.lamps.size());
}

} // namespace

Expected<SceneUpdater> SceneUpdater::create(SceneUpdaterSetup setup,
                                            const pipeline::spectral::LightClassifierParams& params)
{
    if (setup.booth.lamps.empty()) {
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
    const auto& l = setup_.booth.lamps[static_cast<std::size_t>(lamp)];
    state.lampIndex = lamp;
    state.illuminant = l.spectrum;
    state.emitterLuminanceCdM2 = l.luminanceCdM2;
}

void SceneUpdater::update(pipeline::scene::SceneState& state,
                          const hal::SpectrumSample* spectrum,
                          const hal::PoseSample* pose,
                          const hal::AccelSample* accel,
                          const hal::LampSample* selector)
{
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
            state.eyeBoothM = setup_.trackerInBooth ? setup_.trackerInBooth->apply(e)
                                                    : e + setup_.trackerInBoothM;
        } else {
            ++rejectedPoses_;
        }
    }
    if (accel != nullptr && accel->sequence != lastAccel_) {
        lastAccel_ = accel->sequence;
        if (auto tilt = pipeline::scene::tiltFromGravity(accel->gravity)) {
            state.tiltRad = *tilt;
        } else {
            ++rejectedTilts_;
        }
    }
}

} // namespace replica::platform
