// See run_config_schema.h. Ranges are the physical and format limits the appliance itself keeps
// (frame size, rate, light counts, the site file's geometry ranges widened a little); the checks
// across fields (aspect ratio, names of renderers and inverses) stay in
// RunConfig::fromJson. A key added to RunConfig::toJson must be added here too
// (RunConfigSchema.EveryKeyTheRunWritesIsKnown fails otherwise).
#include <vector>

#include <platform/appliance.h>
#include <platform/run_config_schema.h>

namespace replica::platform {

namespace {

using namespace json_schema;

// Render profile 0's switches, one key each: older render paths, not read (such a recording
// replays on today's path, approximately).
std::vector<JsonSchemaField> legacyRenderKeys()
{
    const auto flag = boolean().optional();
    return {
            {"hardware_filter", flag},        {"specular_lod_bias", number(-8.0, 8.0).optional()},
            {"specular_nearest_level", flag}, {"horizon_spread", flag},
            {"horizon_half", flag},           {"horizon_bilinear", flag},
            {"specular_branch_free", flag},   {"specular_exact_level", flag},
            {"texel_exact_ties", flag},       {"horizon_pick", flag},
            {"surround_illuminance", flag},   {"viewing_filtered", flag},
    };
}

// The keys holding objects: the tracker's transform, the sensing chain, the planner's choices and
// what is kept for people.
std::vector<JsonSchemaField> nestedKeys()
{
    const auto metres3 = array(number(-100.0, 100.0), 3, 3);
    return {
            // A rotation matrix (row-major; entries within [-1, 1] up to rounding) and a
            // translation in metres.
            {"t_booth_tracker", object({{"rotation", array(number(-1.000001, 1.000001), 9, 9)},
                                        {"translation", metres3}})
                                        .optional()},
            // The live spectrometer chain (pipeline/spectral/live_chain.h).
            {"sensing", object({{"stray_light", boolean()},
                                {"wavelength_lines", boolean()},
                                {"average_spectra", integer(1, 1000)},
                                {"steady_distance", number(0.0, 10.0)},
                                {"stray_light_fraction", number(0.0, 0.5)},
                                {"wavelength_offset_nm", number(-5.0, 5.0)},
                                {"direct_cdm2_per_y", number(0.0, 1e12).optional()}})
                                .optional()},
            // The planner's choice per lamp name (platform/render_plan.h).
            {"planned_lamps", map(object({{"lights", integer(1, 256)},
                                          {"specular_samples", integer(0, 256)},
                                          {"horizon_directions", integer(0, 32)},
                                          {"walls", boolean().optional()}}),
                                  64)
                                      .optional()},
            // What 'replica run' adds for people (never read back): any values.
            {"run_options", map(any(), 64).optional()},
            {"site", map(any(), 64).optional()},
            // The estimators' state at the head of a rotated session file
            // (state::SceneEstimator::save; checked field by field by restore).
            {"state_at_start", map(any(), 16).optional()},
    };
}

} // namespace

const JsonSchema& runConfigSchema()
{
    using namespace json_schema;
    static const JsonSchema s = [] {
        const auto metres3 = array(number(-100.0, 100.0), 3, 3);
        const auto flag = boolean().optional();
        const auto name = string(4096);
        std::vector<JsonSchemaField> fields = {
                // Read by every version (required).
                {"width", integer(1, kMaxFrameSide)},
                {"height", integer(1, kMaxFrameSide)},
                {"rate_hz", number(1.0, 1000.0)},
                {"booth", name},
                {"scene", name},
                {"basis", name},
                {"spectrometer_calibration", name},
                {"display", name},
                {"display_peak_cd_m2", number(0.0, 1e5)},
                {"display_black_cd_m2", number(0.0, 1e5)},
                // Optional keys: a recording without one replays with the key's default.
                // "renderer": "booth", or "flat" (absent: made before the booth renderer), which
                // replays on the booth pass, approximately.
                {"renderer", name.optional()},
                // The flat renderer's grid of point lights, in the recordings it made (before
                // that, required); not read.
                {"lights_u", integer(1, 256).optional()},
                {"lights_v", integer(1, 256).optional()},
                {"scene_dir", name.optional()},
                {"scene_digest", string(64).optional()},
                {"booth_dir", name.optional()},
                {"booth_digest", string(64).optional()},
                {"light", string(64).optional()},
                {"booth_lights", integer(1, 256).optional()},
                {"specular_samples", integer(kAutoSpecularSamples, 256).optional()},
                {"specular_grid", integer(kAutoSpecularGrid, 256).optional()},
                {"diffuse_grid", integer(kAutoDiffuseGrid, 256).optional()},
                {"area_lights", integer(kAutoAreaLights, 1).optional()},
                {"cache_slices", integer(1, kMaxCacheSlices).optional()},
                {"tilt_nodes_deg", number(0.0, kMaxTiltNodesDeg).optional()},
                // Seconds between the running appliance's error probes (not replayed).
                {"error_probe_s", number(0.0, 3600.0).optional()},
                // A luminance scale on the booth's lights (0 excluded by fromJson).
                {"booth_dimmer", number(0.0, 1.0).optional()},
                {"booth_dimmer_auto", flag},
                // The render path (pipeline/render/render_profile.h); RunConfig::fromJson
                // refuses one newer than this build's.
                {"render_profile", integer(0, 65535).optional()},
                {"horizon_directions", integer(0, 32).optional()},
                {"display_digest", string(64).optional()},
                {"display_inverse", string(64).optional()},
                {"gamut_mapping", string(64).optional()},
                {"viewing_compensation", flag},
                {"flare_subtraction", flag},
                {"false_colour", flag},
                {"stand_hinge_m", metres3.optional()},
                {"stand_hinge_to_panel_m", number(-10.0, 10.0).optional()},
                {"panel_width_m", number(0.01, 10.0).optional()},
                {"panel_height_m", number(0.01, 10.0).optional()},
                {"tracker_rotation_deg", array(number(-360.0, 360.0), 3, 3).optional()},
                {"tracker_translation_m", metres3.optional()},
                {"default_lamp", string(256).optional()},
                {"default_eye_m", metres3.optional()},
                {"default_tilt_rad", number(-3.2, 3.2).optional()},
        };
        for (auto more : {legacyRenderKeys(), nestedKeys()}) {
            fields.insert(fields.end(), more.begin(), more.end());
        }
        return object(std::move(fields));
    }();
    return s;
}

} // namespace replica::platform
