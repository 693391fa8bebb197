// The site's [booth] dimmer = "auto" chosen at start from the scene itself (issue 24): the CPU
// model's probe views of every lamp, as the display pass meets them (platform/booth_dimmer.h has
// the rules each view is judged by).
#pragma once

#include <pipeline/display/display_profile.h>
#include <pipeline/render/booth_scene_pass.h>
#include <platform/appliance.h>

namespace replica::platform {

// The largest scale at which, for every lamp, at most 1 % of the surface over all its probe views
// together, and at most 5 % in any one view, is above the panel's peak as the display pass meets
// it; sets config.boothDimmer (and says it was chosen) and logs the scale and each lamp's share
// before and after. The probe views copy setup.prepared's relief when it is set.
void chooseBoothDimmer(RunConfig& config,
                       const pipeline::render::BoothSceneSetup& setup,
                       const pipeline::display::DisplayModel& displayModel);

} // namespace replica::platform
