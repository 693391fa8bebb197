// Everything the renderer needs to know about one frame: what the state stage (state/, the light,
// eye and tilt estimators) made of the sensor samples up to this frame. The renderer keeps no
// history of its own: a frame is a function of its SceneState (and the run's fixed setup), so
// frame N renders from its state alone, without the frames before it (docs/architecture.md,
// "The state stage").
#pragma once

#include <cstdint>
#include <memory>
#include <optional>

#include <glm/vec3.hpp>

#include <pipeline/colour/channel_basis.h>
#include <pipeline/colour/spectrum.h>

namespace replica::pipeline::scene {

// The tilt the booth pass's cached diffuse term shows (the tilt estimator: the hold filter and the
// sliced refresh, state/tilt_estimator.h). A new held tilt is drawn into a second cache in K bands
// over K frames (RenderSettings::cacheSlices); the frame that draws the last band shows it.
struct DiffuseTilt {
    double shownRad = 0.0;            // the tilt of the diffuse term shown in this frame
    std::optional<double> refreshRad; // a sliced refresh under way toward this tilt...
    int refreshBands = 0;             // ...with this many of its K bands drawn (this frame's too)
    bool operator==(const DiffuseTilt&) const = default;
};

struct SceneState {
    std::uint64_t frameIndex = 0;
    std::int64_t tickNs = 0;
    // The light to render with: the stored SPD of the classified lamp, or the sensed SPD itself
    // when no stored lamp matches (the paper's direct-sensor mode). Relative units.
    colour::Spectrum illuminant{};
    int lampIndex = -1;                // classified lamp, -1 when unknown (direct-sensor mode)
    double emitterLuminanceCdM2 = 0.0; // luminance of the booth emitter for this lamp
    // The light differs from the previous frame's (another lamp, or a sensed spectrum or
    // luminance that moved; the first frame's too): the renderer uploads it and draws its cached
    // diffuse term whole.
    bool lightChanged = true;
    // The channel encoding (a light-adaptive encoder only): 0 is the renderer's own basis; n > 0
    // the n-th re-encode, 'basis' its basis (made for 'encodedFor').
    int encoding = 0;
    std::shared_ptr<const colour::ChannelBasis> basis;
    colour::Spectrum encodedFor{};
    glm::dvec3 eyeBoothM{0.0, 0.45, 0.60};
    double tiltRad = 0.0;     // the sensed tilt: the specular term's
    double heldTiltRad = 0.0; // the hold filter's tilt (the diffuse term's once refreshed)
    // The diffuse term's tilt, which the tilt estimator always sets; none in a state made by
    // hand (a test, a benchmark): the diffuse term at tiltRad.
    std::optional<DiffuseTilt> diffuse;
};

} // namespace replica::pipeline::scene
