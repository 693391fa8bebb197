// The written schemas of what a recording carries: the session message (recordings/
// session_schema.h) and the run configuration inside it (platform/run_config_schema.h). What a
// run writes passes with no warning; each refused value is named by its JSON path; unknown keys
// are warned, not refused. The ranges asserted are the site file's and the format's own limits.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <platform/appliance.h>
#include <recordings/recording.h>
#include <recordings/sample_codec.h>
#include <recordings/session_schema.h>

#include <gtest/gtest.h>

namespace replica::platform {
namespace {

// What 'replica run' records: the configuration as built, with a calibrated tracker, plus the
// informational run options and site.
nlohmann::json recordedConfig()
{
    RunConfig c;
    pipeline::RigidTransform t;
    t.rotation = glm::dmat3(1.0);
    t.translation = {0.01, 0.42, 0.05};
    c.trackerInBooth = t;
    auto j = nlohmann::json::parse(c.toJson());
    j["run_options"] = {{"hal", "sim"}, {"kiosk", false}, {"tracker_port", 4242}};
    j["site"] = {{"stand", {{"panel_width_m", 0.52}}}};
    return j;
}

TEST(RunConfigSchema, EveryKeyTheRunWritesIsKnown)
{
    std::vector<std::string> warnings;
    auto c = RunConfig::fromJson(recordedConfig().dump(), &warnings);
    ASSERT_TRUE(c) << c.error().message;
    EXPECT_TRUE(warnings.empty()) << warnings.front();
    EXPECT_EQ(c->trackerInBooth.translation.x, 0.01);
}

// A new run records its tilt nodes; a recording made before them replays without (0: the held
// tilt's own term, as it was drawn).
TEST(RunConfigSchema, TiltNodesAreRecordedAndAbsentMeansNone)
{
    RunConfig fresh;
    EXPECT_EQ(fresh.tiltNodesDeg, kDefaultTiltNodesDeg);
    fresh.tiltNodesDeg = 3.5;
    auto back = RunConfig::fromJson(fresh.toJson());
    ASSERT_TRUE(back) << back.error().message;
    EXPECT_EQ(back->tiltNodesDeg, 3.5);
    auto j = nlohmann::json::parse(fresh.toJson());
    j.erase("tilt_nodes_deg");
    back = RunConfig::fromJson(j.dump());
    ASSERT_TRUE(back) << back.error().message;
    EXPECT_EQ(back->tiltNodesDeg, 0.0);
}

TEST(RunConfigSchema, RefusedValuesNameTheirJsonPath)
{
    struct Case {
        const char* key;
        nlohmann::json value;
        const char* message;
    };
    const std::vector<Case> cases = {
            {"rate_hz", 1e308, "run configuration: /rate_hz: expected a number in [1, 1000]"},
            {"rate_hz", 0.5, "/rate_hz: expected a number in [1, 1000], found 0.5"},
            {"width", "32", "/width: expected an integer in [1, 8192], found a string"},
            {"height", 8193, "/height: expected an integer in [1, 8192], found 8193"},
            {"lights_u", 65536, "/lights_u: expected an integer in [1, 256], found 65536"},
            {"specular_lod_bias", nullptr, "/specular_lod_bias: expected a number in [-8, 8]"},
            {"display_black_cd_m2", -1.0, "/display_black_cd_m2: expected a number in [0, "},
            {"cache_slices", 0, "/cache_slices: expected an integer in [1, 16], found 0"},
            {"tilt_nodes_deg", -1.0, "/tilt_nodes_deg: expected a number in [0, 10], found -1"},
            {"tilt_nodes_deg", 90, "/tilt_nodes_deg: expected a number in [0, 10], found 90"},
            {"hardware_filter", 1, "/hardware_filter: expected true or false, found an integer"},
            {"default_eye_m", {0.0, "x", 0.6}, "/default_eye_m/1: expected a number"},
            {"tracker_rotation_deg",
             {0.0, 720.0, 0.0},
             "/tracker_rotation_deg/1: expected a "
             "number in [-360, 360], found 720"},
            {"stand_hinge_m", {0.0, 0.1}, "/stand_hinge_m: expected an array of 3 items, found 2"},
            {"display", 5, "/display: expected a string, found an integer"},
            {"scene_digest", std::string(100, 'f'), "/scene_digest: string longer than 64"},
    };
    for (const auto& c : cases) {
        auto j = recordedConfig();
        j[c.key] = c.value;
        auto got = RunConfig::fromJson(j.dump());
        ASSERT_FALSE(got) << c.key << " = " << c.value.dump() << " was accepted";
        EXPECT_NE(got.error().message.find(c.message), std::string::npos)
                << got.error().message << "\n  expected: " << c.message;
    }
    // Nested and missing values.
    auto j = recordedConfig();
    j["t_booth_tracker"]["rotation"].erase(0);
    auto got = RunConfig::fromJson(j.dump());
    ASSERT_FALSE(got);
    EXPECT_NE(got.error().message.find("/t_booth_tracker/rotation: expected an array of 9 items, "
                                       "found 8"),
              std::string::npos)
            << got.error().message;
    j = recordedConfig();
    j["t_booth_tracker"]["rotation"][4] = 2.0; // not a rotation
    got = RunConfig::fromJson(j.dump());
    ASSERT_FALSE(got);
    EXPECT_NE(got.error().message.find("/t_booth_tracker/rotation/4"), std::string::npos);
    j = recordedConfig();
    j.erase("width");
    got = RunConfig::fromJson(j.dump());
    ASSERT_FALSE(got);
    EXPECT_NE(got.error().message.find("/width: required but missing"), std::string::npos)
            << got.error().message;
    // A number beyond a double (1e400) never becomes infinity: the parser refuses it.
    std::string text = recordedConfig().dump();
    const auto at = text.find("\"rate_hz\":60.0");
    ASSERT_NE(at, std::string::npos);
    text.replace(at, 14, "\"rate_hz\":1e400");
    got = RunConfig::fromJson(text);
    ASSERT_FALSE(got);
    EXPECT_NE(got.error().message.find("run configuration: [json.exception.out_of_range.406] "
                                       "number overflow parsing '1e400'"),
              std::string::npos)
            << got.error().message;
}

TEST(RunConfigSchema, UnknownKeysAreWarnedNotRefused)
{
    auto j = recordedConfig();
    j["bogus_setting"] = 1;
    j["t_booth_tracker"]["scale"] = 2.0;
    std::vector<std::string> warnings;
    auto c = RunConfig::fromJson(j.dump(), &warnings);
    ASSERT_TRUE(c) << c.error().message;
    ASSERT_EQ(warnings.size(), 2u);
    // Nested objects are checked before their parent's unknown keys are listed.
    EXPECT_EQ(warnings[0], "run configuration: /t_booth_tracker/scale: unknown key, ignored");
    EXPECT_EQ(warnings[1], "run configuration: /bogus_setting: unknown key, ignored");
}

nlohmann::json recordedSession()
{
    recordings::SessionInfo s;
    s.softwareVersion = "replica 0.1.0";
    s.configJson = recordedConfig().dump();
    s.boothModel = "replica-booth-1";
    s.scene = "colorchecker";
    s.displayProfile = "wide-ips-synthetic";
    s.wallClockStartNs = 1'795'445'344'985'983'302;
    s.devices[&recordings::spectrometerKind()] = {"USB2000+", "S1", "fw", hal::SourceKind::Live};
    s.devices[&recordings::trackerKind()] = {"TrackIR", "T1", "", hal::SourceKind::Sim};
    s.devices[&recordings::accelKind()] = {"accel", "A1", "", hal::SourceKind::Replay};
    return nlohmann::json::parse(recordings::encodeSession(s, recordings::kFormatVersion));
}

TEST(SessionSchema, WhatTheWriterWritesPassesAndBadValuesAreNamed)
{
    std::vector<std::string> warnings;
    ASSERT_TRUE(validateJson(recordedSession(), recordings::sessionSchema(), "s", &warnings));
    EXPECT_TRUE(warnings.empty()) << warnings.front();

    struct Case {
        const char* key;
        nlohmann::json value;
        const char* message;
    };
    const std::vector<Case> cases = {
            {"format_version", "4", "s: /format_version: expected an integer in [0, 65535]"},
            {"config", 5, "s: /config: expected a string, found an integer"},
            {"wall_clock_start_ns", -1, "/wall_clock_start_ns: expected an integer in [0, "},
            {"wall_clock_start_ns", 1.5e19, "/wall_clock_start_ns: expected an integer"},
            {"tracker", "TrackIR", "s: /tracker: expected an object, found a string"},
            {"software", nullptr, "s: /software: expected a string, found null"},
    };
    for (const auto& c : cases) {
        auto j = recordedSession();
        j[c.key] = c.value;
        auto got = validateJson(j, recordings::sessionSchema(), "s");
        ASSERT_FALSE(got) << c.key << " = " << c.value.dump() << " was accepted";
        EXPECT_NE(got.error().message.find(c.message), std::string::npos)
                << got.error().message << "\n  expected: " << c.message;
    }
    auto j = recordedSession();
    j["accel"].erase("source");
    auto got = validateJson(j, recordings::sessionSchema(), "s");
    ASSERT_FALSE(got);
    EXPECT_EQ(got.error().message, "s: /accel/source: required but missing");

    j = recordedSession();
    j["owner"] = "x";
    warnings.clear();
    ASSERT_TRUE(validateJson(j, recordings::sessionSchema(), "s", &warnings));
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_EQ(warnings[0], "s: /owner: unknown key, ignored");
}

} // namespace
} // namespace replica::platform
