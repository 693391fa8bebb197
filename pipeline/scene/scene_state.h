// Everything the renderer needs to know about one frame, updated from the latest sensor samples.
#pragma once

#include <cstdint>

#include <glm/vec3.hpp>

#include <pipeline/colour/spectrum.h>

namespace replica::pipeline::scene {

struct SceneState {
    std::uint64_t frameIndex = 0;
    std::int64_t tickNs = 0;
    // The light to render with: the stored SPD of the classified lamp, or the sensed SPD itself
    // when no stored lamp matches (the paper's direct-sensor mode). Relative units.
    colour::Spectrum illuminant{};
    int lampIndex = -1;                // classified lamp, -1 when unknown (direct-sensor mode)
    double emitterLuminanceCdM2 = 0.0; // luminance of the booth emitter for this lamp
    glm::dvec3 eyeBoothM{0.0, 0.45, 0.60};
    double tiltRad = 0.0;
};

} // namespace replica::pipeline::scene
