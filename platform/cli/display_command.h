// What the 'replica display' subcommands share: display_command.cpp registers them and runs the
// model's forward and inverse; the fit is in display_fit_command.cpp, the ColorChecker studies in
// display_study_command.cpp, the patch reader in display_patches.cpp.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <pipeline/display/display_inverse.h>
#include <platform/cli/sensed_report.h>

namespace replica::platform {

struct DisplayOptions {
    std::string measurements;
    std::string profile;
    std::string out;
    std::string name;
    std::string measuredIn = "dark";
    std::string triple;
    std::string viewingTable;
    int bits = 0;
    double whiteCdM2 = 0.0; // --white-cdm2: white's luminance for a .ti3 normalised to Y = 100
    bool synthetic = false;
    bool json = false;
    bool clip = false;
    std::uint64_t seed = 1;
    double lux = 2000.0;
    std::string flare = "subtract";
    std::string panel = "model";
    std::string basis = "replica_k6";
    std::string tone = "robust";
    std::string icc;
    int iccVersion = 2; // --icc-version: 2 (v2.4, what ArgyllCMS reads) or 4 (v4.3)
    SensedReportOptions sensed;
};

// The shipped profile, where a command takes the profile as an option.
std::string defaultDisplayProfile();
// The profile at 'path' and its inverse; nullopt (the reason logged) when either fails.
std::optional<pipeline::display::DisplayInverse> loadDisplayInverse(const std::string& path);

int displayFitMain(const DisplayOptions& o);
int displayStudyMain(const DisplayOptions& o);
// How much the screen's own reflection of the booth light matters for dark colours.
int displayFlareMain(const DisplayOptions& o);

} // namespace replica::platform
