// Everything the renderer needs to know about one frame: what the state stage (state/, the light,
// eye and tilt estimators) made of the sensor samples up to this frame. The renderer keeps no
// history of its own: a frame is a function of its SceneState (and the run's fixed setup), so
// frame N renders from its state alone, without the frames before it (docs/architecture.md,
// "The state stage").
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include <glm/vec3.hpp>

#include <pipeline/colour/channel_basis.h>
#include <pipeline/colour/spectrum.h>

namespace replica::pipeline::scene {

// The tilt the booth pass's cached diffuse term shows (the tilt estimator: the hold filter and the
// sliced refresh, state/tilt_estimator.h), as the estimator carries it from frame to frame. A new
// held tilt is drawn into a second cache in K bands over K frames (RenderSettings::cacheSlices);
// the frame that draws the last band shows it.
struct DiffuseTilt {
    double shownRad = 0.0;            // the tilt of the diffuse term shown in this frame
    std::optional<double> refreshRad; // a sliced refresh under way toward this tilt...
    int refreshBands = 0;             // ...with this many of its K bands drawn (this frame's too)
    bool operator==(const DiffuseTilt&) const = default;
};

// This frame's band of a sliced refresh: band 'band' (0-based) of 'bands', toward 'towardRad'.
// The last band (band == bands - 1) completes it: the frame then shows towardRad.
struct DiffuseBand {
    double towardRad = 0.0;
    int band = 0;
    int bands = 1;
    bool operator==(const DiffuseBand&) const = default;
};

// What the frame's cached diffuse term is, as the state stage decided it
// (pipeline/scene/diffuse_schedule.h): the term composed, and the band of a refresh drawn this
// frame. The renderer holds buffers and draws what this names; it keeps no schedule.
// With tilt nodes (DiffuseNodes) the term composed is (1 - mix) times the term at shownRad plus
// mix times the term at mixRad, both of them cached whole.
struct DiffuseDraw {
    double shownRad = 0.0;
    std::optional<DiffuseBand> band;
    std::optional<double> mixRad{};
    double mix = 0.0;
    bool operator==(const DiffuseDraw&) const = default;
    // The tilt the term composed stands for: shownRad, or between it and mixRad by mix.
    double tiltRad() const { return mixRad ? shownRad + mix * (*mixRad - shownRad) : shownRad; }
};

// Tilt nodes (RenderSettings::tiltNodesRad > 0; pipeline/scene/diffuse_schedule.h): the diffuse
// term cached whole at a few tilts, the multiples of the step and the held tilt at a new light,
// and shown interpolated between the two that bracket the held tilt. This is what the tilt
// estimator carries from frame to frame: the tilts cached whole, and a node being drawn in bands.
constexpr std::size_t kMaxDiffuseNodes = 4;
struct DiffuseNodes {
    std::vector<double> nodes;        // at most kMaxDiffuseNodes, each drawn whole
    std::optional<double> refreshRad; // a node drawn in bands...
    int refreshBands = 0;             // ...with this many of its K bands drawn (this frame's too)
    bool operator==(const DiffuseNodes&) const = default;
};

struct SceneState {
    std::uint64_t frameIndex = 0;
    std::int64_t tickNs = 0;
    // The light to render with: the stored SPD of the classified lamp, or the sensed SPD itself
    // when no stored lamp matches (the paper's direct-sensor mode). Relative units.
    colour::Spectrum illuminant{};
    int lampIndex = -1;                // classified lamp, -1 when unknown (direct-sensor mode)
    double emitterLuminanceCdM2 = 0.0; // luminance of the booth emitter for this lamp
    // The light's content key differs from the previous frame's (lightKey: another lamp, or a
    // sensed spectrum or luminance that moved; the first frame's too): the state stage re-takes
    // the held tilt, draws the diffuse term whole and decides the encoding on it.
    bool lightChanged = true;
    // The channel encoding (a light-adaptive encoder only): 0 is the renderer's own basis; n > 0
    // the n-th re-encode, 'basis' its basis (made for 'encodedFor').
    int encoding = 0;
    std::shared_ptr<const colour::ChannelBasis> basis;
    colour::Spectrum encodedFor{};
    glm::dvec3 eyeBoothM{0.0, 0.45, 0.60};
    // The specular term's tilt: the sensed one, finite (a non-finite one is replaced by the held
    // tilt in the tilt estimator, the one place that decides the panel's pose).
    double tiltRad = 0.0;
    double heldTiltRad = 0.0; // the hold filter's tilt (the diffuse term's once refreshed)
    // The diffuse term, which the tilt estimator always sets; none in a state made by hand (a
    // test, a benchmark): the diffuse term whole at tiltRad.
    std::optional<DiffuseDraw> diffuse;
};

// The content key of a state's light: the lamp, or in direct-sensor mode (lampIndex < 0) the
// sensed spectrum and the emitter's luminance (FNV-1a 64 of their bytes). The light estimator
// says a light changed when this key does; the renderer labels the light it holds with it.
std::uint64_t lightKey(const SceneState& state);
std::uint64_t lightKey(int lampIndex, const colour::Spectrum& illuminant, double luminanceCdM2);

} // namespace replica::pipeline::scene
