// The three estimators in order: light, eye, tilt (the held tilt follows the light's changes).
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>
#include <state/scene_estimator.h>

namespace replica::state {
namespace {

// The platform's "loop" logger (platform/logging.h) when it is set up; spdlog's default otherwise.
std::shared_ptr<spdlog::logger> loopLog()
{
    auto l = spdlog::get("loop");
    return l ? l : spdlog::default_logger();
}

constexpr int kSaveVersion = 1;

} // namespace

Expected<SceneEstimator> SceneEstimator::create(SceneEstimatorSetup setup)
{
    auto light = LightEstimator::create(setup.light);
    if (!light) {
        return tl::unexpected(light.error());
    }
    return SceneEstimator(std::move(setup), std::move(*light));
}

void SceneEstimator::update(pipeline::scene::SceneState& state,
                            const hal::SpectrumSample* spectrum,
                            const hal::PoseSample* pose,
                            const hal::AccelSample* accel,
                            const hal::LampSample* selector)
{
    const bool first = !started_;
    if (first) {
        started_ = true;
        light_.start();
    }
    const bool hadSpectrum = light_.sensed();
    const bool hadPose = eye_.tracked();
    const bool hadTilt = tilt_.sensed();
    light_.update(spectrum, selector);
    if (auto warning = light_.takeWarning()) {
        loopLog()->warn("{}", *warning);
    }
    eye_.update(pose);
    tilt_.update(accel);
    light_.write(state);
    state.eyeBoothM = eye_.eyeBoothM();
    tilt_.write(state);

    // Says in the log when each sensor first gives the scene a value (before that the defaults
    // show), so that a sensor missing at boot is visible in the journal.
    const bool haveSpectrum = light_.sensed();
    const bool havePose = eye_.tracked();
    const bool haveTilt = tilt_.sensed();
    if (first || (!hadSpectrum && haveSpectrum) || (!hadPose && havePose) ||
        (!hadTilt && haveTilt)) {
        auto log = loopLog();
        const int lamp = setup_.light.defaultLamp;
        if (!haveSpectrum || !havePose || !haveTilt) {
            log->info(
                    "frame {}: {}{}{}", state.frameIndex,
                    haveSpectrum ? "light sensed; "
                    : lamp >= 0 && lamp < static_cast<int>(setup_.light.booth.lights.size())
                            ? fmt::format("no spectrum yet: showing the default lamp '{}'; ",
                                          setup_.light.booth.lights[static_cast<std::size_t>(lamp)]
                                                  .name)
                            : std::string("no spectrum yet and no default lamp: no light; "),
                    havePose ? "eye tracked; " : "no head pose yet: default eye; ",
                    haveTilt ? "tilt sensed" : "no tilt yet: default tilt");
        } else {
            log->info("frame {}: every sensor now feeds the scene", state.frameIndex);
        }
    }
}

nlohmann::json SceneEstimator::save() const
{
    return {{"version", kSaveVersion},
            {"started", started_},
            {"light", light_.save()},
            {"eye", eye_.save()},
            {"tilt", tilt_.save()}};
}

Expected<void> SceneEstimator::restore(const nlohmann::json& j)
{
    if (!j.is_object() || !j.contains("version") || !j["version"].is_number_integer() ||
        j["version"].get<int>() != kSaveVersion || !j.contains("started") ||
        !j["started"].is_boolean()) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("the saved estimator state is not version {} (replay it with "
                                     "the build that made it)",
                                     kSaveVersion));
    }
    if (!j.contains("light") || !j.contains("eye") || !j.contains("tilt")) {
        return makeError(ErrorCode::InvalidArgument,
                         "the saved estimator state needs light, eye and tilt");
    }
    if (auto ok = light_.restore(j["light"]); !ok) {
        return ok;
    }
    if (auto ok = eye_.restore(j["eye"]); !ok) {
        return ok;
    }
    if (auto ok = tilt_.restore(j["tilt"]); !ok) {
        return ok;
    }
    started_ = j["started"].get<bool>();
    return {};
}

} // namespace replica::state
