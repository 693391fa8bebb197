// The refresh schedule of the booth pass's cached diffuse term, in one place: the tilt estimator
// steps it once a frame to say what each frame's diffuse term shows (state/tilt_estimator.h), and
// the booth pass asks it whether the cache it holds is one frame of it behind what a state wants
// (render::BoothScenePass::draw), so that it draws one band instead of the whole cache.
#pragma once

#include <optional>

#include <pipeline/scene/scene_state.h>

namespace replica::pipeline::scene {

// The diffuse term of the frame after 'last' (none: the first frame), whose held tilt is
// 'heldRad', with K = 'slices' bands a refresh (RenderSettings::cacheSlices; below 1 counts as 1):
// - a new light (or the first frame) draws it whole at the held tilt;
// - otherwise a held tilt other than the one shown starts a refresh toward it, drawn in K bands,
//   one a frame (this frame's the first), into a second cache that the K-th frame shows; with
//   K = 1 it is shown at once;
// - a held tilt that moves meanwhile waits for those K frames.
DiffuseTilt
nextDiffuse(const std::optional<DiffuseTilt>& last, double heldRad, bool lightChanged, int slices);

// Whether 'want' is one frame of the schedule after 'had' under the same light: the frame's one
// draw is then the diffuse term at diffuseTarget(want) (the same term, or a refresh's next band).
bool diffuseFollows(const DiffuseTilt& had, const DiffuseTilt& want, int slices);

// The tilt a frame's draw of the cache is for: the refresh under way, else the tilt shown.
inline double diffuseTarget(const DiffuseTilt& d)
{
    return d.refreshRad.value_or(d.shownRad);
}

} // namespace replica::pipeline::scene
