// The refresh schedule of the booth pass's cached diffuse term, in one place: the tilt estimator
// steps it once a frame (state/tilt_estimator.h) and writes what the frame draws (DiffuseDraw:
// the term shown, and "band b of K toward tilt T"); the booth pass draws what that names into the
// buffers it holds (render::BoothDiffuseCache) and keeps no schedule of its own.
#pragma once

#include <limits>
#include <optional>

#include <pipeline/scene/scene_state.h>

namespace replica::pipeline::scene {

// The diffuse term of the frame after 'last' (none: the first frame), whose held tilt is
// 'heldRad', with K = 'slices' bands a refresh (RenderSettings::cacheSlices; below 1 counts as 1):
// - a new light (or the first frame) draws it whole at the held tilt;
// - otherwise a held tilt other than the one shown starts a refresh toward it, drawn in K bands,
//   one a frame (this frame's the first), into a second cache that the K-th frame shows; with
//   K = 1 it is shown at once;
// - a held tilt that moves meanwhile waits for those K frames,
// - unless the term shown is more than 'maxLagRad' from the held tilt: then it is drawn whole at
//   once (a refresh under way is dropped), bounding what a lagging term costs (infinite: never).
// A refresh started here aims at 'aimRad' when given (where a moving panel will be when the
// refresh shows: state/tilt_estimator.h) instead of the held tilt; a whole draw is always at the
// held tilt, since it shows at once.
DiffuseTilt nextDiffuse(const std::optional<DiffuseTilt>& last,
                        double heldRad,
                        bool lightChanged,
                        int slices,
                        double maxLagRad = std::numeric_limits<double>::infinity(),
                        std::optional<double> aimRad = std::nullopt);

// What the frame whose diffuse term is 'now' draws, 'last' being the previous frame's (none: the
// first): the term shown, and the band of a refresh this frame draws (its bands are drawn one a
// frame; the frame that draws the last one shows its tilt). A new light or a first frame draws
// the term whole; so does any frame with K = 1, and a frame that dropped a refresh for its lag.
DiffuseDraw diffuseDraw(const std::optional<DiffuseTilt>& last,
                        const DiffuseTilt& now,
                        bool lightChanged,
                        int slices);

// Tilt nodes (RenderSettings::tiltNodesRad = 'stepRad' > 0): the frame after 'last' (none: the
// first frame) at held tilt 'heldRad'. The diffuse term is linear enough in the tilt that the
// term interpolated between two tilts 2 degrees apart is within ΔE00 p95 0.07, max 0.12, of the
// term itself (tilt_cost_test.cpp, TiltNodes), so a panel that moves needs a new term every 2
// degrees instead of every held tilt, and a panel that turns back within a step or two finds
// its nodes cached:
// - a new light (or the first frame) draws the term whole at the held tilt, the one node;
// - the frame composes the two nodes that bracket the held tilt (at most a step apart; a node at
//   the held tilt itself alone), interpolated linearly;
// - while no two nodes at most a step apart bracket the held tilt, the ends of its step (the
//   multiples of the step around it, the nearer first) are drawn in K = 'slices' bands, one a
//   frame, and cached at the last; once they do, and the panel moves ('direction' -1 or +1: the
//   sign of its trend), the first multiple of the step past them that way;
// - while the bracket lacks a node the frame shows the nearest node alone, unless that is more
//   than 'maxLagRad' from the held tilt: then the held tilt is drawn whole at once (a refresh
//   under way is dropped), as nextDiffuse bounds its lag;
// - past kMaxDiffuseNodes the node farthest from the held tilt is forgotten.
struct DiffuseNodeStep {
    DiffuseNodes nodes;
    DiffuseDraw draw;
};
DiffuseNodeStep nextDiffuseNodes(const std::optional<DiffuseNodes>& last,
                                 double heldRad,
                                 bool lightChanged,
                                 int slices,
                                 double stepRad,
                                 double maxLagRad,
                                 int direction);

} // namespace replica::pipeline::scene
