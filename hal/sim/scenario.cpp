// The scripted sim scenario.
#include <cmath>
#include <numbers>

#include <hal/sim/scenario.h>

namespace replica::hal::sim {

ScenarioState scenarioAt(const ScenarioParams& p, std::int64_t tNs)
{
    const double t = static_cast<double>(tNs) * 1e-9;
    const double twoPi = 2.0 * std::numbers::pi;
    ScenarioState s;
    const auto step = static_cast<std::int64_t>(std::floor(t / p.lampPeriodS));
    s.lamp = p.lampCount > 0 ? static_cast<int>(((step % p.lampCount) + p.lampCount) % p.lampCount)
                             : 0;
    s.eyeBoothM = p.eyeCentreBoothM;
    s.eyeBoothM.x += p.walkAmplitudeM * std::sin(twoPi * t / p.walkPeriodS);
    s.tiltRad = p.tiltMeanRad + p.tiltAmplitudeRad * std::sin(twoPi * t / p.tiltPeriodS);
    const double inWalk = std::fmod(t, p.walkPeriodS);
    s.tracked = !(inWalk >= p.trackLostFromS && inWalk < p.trackLostFromS + p.trackLostForS);
    return s;
}

} // namespace replica::hal::sim
