// The scripted scenario the simulated devices play: the booth light cycles through its lamps, the
// viewer walks past the display, and the display tilts on its stand.
#pragma once

#include <cstdint>

#include <glm/vec3.hpp>

namespace replica::hal::sim {

struct ScenarioParams {
    int lampCount = 3;            // lamps cycle 0, 1, 2, 0, ...
    double lampPeriodS = 2.0;     // each lamp stays on this long
    double walkPeriodS = 6.0;     // one full walk left-right-left
    double walkAmplitudeM = 0.40; // eye x swings +-0.40 m about the display centre
    glm::dvec3 eyeCentreBoothM{0.0, 0.45, 0.60};
    double tiltMeanRad = 0.35; // about 20 degrees back
    double tiltAmplitudeRad = 0.25;
    double tiltPeriodS = 5.0;
    double trackLostFromS = 4.0; // within each walk period the markers leave view briefly
    double trackLostForS = 0.3;
};

struct ScenarioState {
    int lamp = 0;
    glm::dvec3 eyeBoothM{0.0};
    double tiltRad = 0.0;
    bool tracked = true;
};

// The scenario at session time t: a pure function, so every simulated device agrees on it.
ScenarioState scenarioAt(const ScenarioParams& p, std::int64_t tNs);

} // namespace replica::hal::sim
