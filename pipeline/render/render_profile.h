// Render profiles: one recorded number naming a frozen set of the switches that decide how the
// renderer evaluates the equations (which float path, which filter, which tie rule) and so
// change a frame's pixels in the last bits, without being a quality count the planner tunes.
//
// A run records its profile (RunConfig's "render_profile"); replay renders with that profile's
// switches. A profile is never edited once a recording holds it: a better default is a new
// profile, and retiring one is a reviewed golden update. docs/rendering.md ("Render profiles")
// lists each profile and what it fixes; tests/unit/render/render_profile_test.cpp holds every
// profile's settings as literals, so changing one fails there.
//
// The counts stay recorded numbers of their own (lights, specular samples, horizon directions,
// the grids, cache slices, area lights by scene): they are chosen per scene and per budget.
#pragma once

#include <span>
#include <string>

#include <pipeline/base/expected.h>
#include <pipeline/shading/realtime_model.h>

namespace replica::pipeline::render {

// The switches a profile fixes. Each names the setting it sets (shading::RenderSettings unless
// said otherwise); docs/rendering.md says what each one does.
struct RenderSwitches {
    bool hardwareFilter = false;
    bool specularNearestLevel = false;
    bool horizonSpread = false;
    bool horizonHalf = false;
    bool horizonBilinear = false;
    bool specularBranchFree = false;
    bool specularExactLevel = false;
    bool texelExactTies = false;
    bool horizonPick = false;
    double specularLodBias = 0.0;
    // GlesRendererSetup::surroundIlluminance (the XYZ frame around the surface).
    bool surroundIlluminance = false;
    // DisplayPassSetup::viewingFiltered.
    bool viewingFiltered = false;
    bool operator==(const RenderSwitches&) const = default;
};

struct RenderProfile {
    int number;
    const char* name;
    const char* summary;
    RenderSwitches switches;
};

// 0: no profile, the switches recorded one by one (recordings whose switches match no profile;
// their run configuration keeps the individual keys).
inline constexpr int kExplicitRenderProfile = 0;
// What a new run records.
inline constexpr int kCurrentRenderProfile = 2;

// kCurrentRenderProfile's switches: what a new run renders with.
RenderSwitches currentRenderSwitches();
// Every profile, numbered 1, 2, ... in order.
std::span<const RenderProfile> renderProfiles();
// The profile numbered 'number', or an error naming the known numbers (a recording from a newer
// build, or a typo).
Expected<const RenderProfile*> findRenderProfile(int number);
// The profile whose switches are exactly these (compared bit for bit), or kExplicitRenderProfile.
int matchRenderProfile(const RenderSwitches& switches);
// Sets the switches' fields of 's' (all but surroundIlluminance and viewingFiltered, which are
// not shading settings).
void applyRenderSwitches(const RenderSwitches& switches, shading::RenderSettings& s);

} // namespace replica::pipeline::render
