#include <array>

#include <fmt/format.h>

#include <pipeline/render/render_profile.h>

namespace replica::pipeline::render {

namespace {

// Frozen: a recording may hold any of these numbers. Append, never edit (render_profile_test).
constexpr std::array<RenderProfile, 2> kProfiles{{
        {1,
         "before-switches",
         "Every switch off, as the booth renderer was before the switches existed: the shader's "
         "own mip filter, trilinear specular levels with a level bias of 1, one "
         "fixed horizon softness, float horizon sines read at each texel, early returns, log2 "
         "levels, u * texels, tent-weighted horizon directions; the XYZ frame shades the "
         "surround; the viewing gain from the table's rows. What a recording without the "
         "switches' keys replays with.",
         {.hardwareFilter = false,
          .specularNearestLevel = false,
          .horizonSpread = false,
          .horizonHalf = false,
          .horizonBilinear = false,
          .specularBranchFree = false,
          .specularExactLevel = false,
          .texelExactTies = false,
          .horizonPick = false,
          .specularLodBias = 1.0,
          .surroundIlluminance = true,
          .viewingFiltered = false}},
        {2,
         "switches-2026-12-03",
         "Every switch on (the defaults of 2026-12-03): the sampler filters the mip chain, the "
         "nearest specular level from the footprint's exponent with a level bias of 0, each "
         "light's horizon softness from its region's spread, half-float horizon sines read "
         "bilinearly for eq. (1), branch-free specular samples, the exact texel tie rule, "
         "horizon directions picked; the surround is left to the display pass; the viewing gain "
         "filtered from its half-degree grid.",
         {.hardwareFilter = true,
          .specularNearestLevel = true,
          .horizonSpread = true,
          .horizonHalf = true,
          .horizonBilinear = true,
          .specularBranchFree = true,
          .specularExactLevel = true,
          .texelExactTies = true,
          .horizonPick = true,
          .specularLodBias = 0.0,
          .surroundIlluminance = false,
          .viewingFiltered = true}},
}};

static_assert(kProfiles[kCurrentRenderProfile - 1].number == kCurrentRenderProfile);

} // namespace

RenderSwitches currentRenderSwitches()
{
    return kProfiles[static_cast<std::size_t>(kCurrentRenderProfile - 1)].switches;
}

std::span<const RenderProfile> renderProfiles()
{
    return kProfiles;
}

Expected<const RenderProfile*> findRenderProfile(int number)
{
    for (const RenderProfile& p : kProfiles) {
        if (p.number == number) {
            return &p;
        }
    }
    return makeError(ErrorCode::InvalidArgument,
                     fmt::format("render profile {} is not known to this build (it knows {} to "
                                 "{}); replay the recording with the build that made it or a "
                                 "newer one",
                                 number, kProfiles.front().number, kProfiles.back().number));
}

int matchRenderProfile(const RenderSwitches& switches)
{
    for (const RenderProfile& p : kProfiles) {
        if (p.switches == switches) {
            return p.number;
        }
    }
    return kExplicitRenderProfile;
}

void applyRenderSwitches(const RenderSwitches& switches, shading::RenderSettings& s)
{
    s.hardwareFilter = switches.hardwareFilter;
    s.specularNearestLevel = switches.specularNearestLevel;
    s.horizonSpread = switches.horizonSpread;
    s.horizonHalf = switches.horizonHalf;
    s.horizonBilinear = switches.horizonBilinear;
    s.specularBranchFree = switches.specularBranchFree;
    s.specularExactLevel = switches.specularExactLevel;
    s.texelExactTies = switches.texelExactTies;
    s.horizonPick = switches.horizonPick;
    s.specularLodBias = switches.specularLodBias;
}

} // namespace replica::pipeline::render
