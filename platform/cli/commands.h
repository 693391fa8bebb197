// Registration of each 'replica' subcommand; each sets exitCode when it runs.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include <platform/output/output.h>

namespace replica::platform {

constexpr int kExitOk = 0;
constexpr int kExitFailure = 1;
constexpr int kExitUsage = 2;
constexpr int kExitLossy = 3;

void registerRunCommand(CLI::App& app, int& exitCode);
void registerReplayCommand(CLI::App& app, int& exitCode);
void registerInspectCommand(CLI::App& app, int& exitCode);
void registerRenderCommand(CLI::App& app, int& exitCode);
void registerPlanCommand(CLI::App& app, int& exitCode);
void registerBoothCommand(CLI::App& app, int& exitCode);
// 'replica booth walls' under 'booth' (booth_walls_command.cpp).
void registerBoothWallsCommand(CLI::App& booth, int& exitCode);
void registerSceneCommand(CLI::App& app, int& exitCode);
void registerDisplayCommand(CLI::App& app, int& exitCode);
void registerRecoverCommand(CLI::App& app, int& exitCode);
void registerColorCommand(CLI::App& app, int& exitCode);
void registerSpectralCommand(CLI::App& app, int& exitCode);
void registerProbeCommand(CLI::App& app, int& exitCode);
void registerCalibrateCommand(CLI::App& app, int& exitCode);
void registerConfigCommand(CLI::App& app, int& exitCode);
void registerFiguresCommand(CLI::App& app, int& exitCode);

// --kms-device, --kms-connector, --kms-mode, --kms-modeset, --kms-path (run and replay).
void addKmsOptions(CLI::App& cmd, KmsOptions& kms);

// --no-warm-up (run and replay): RunConfig::warmUp false. 'also' ends the help text.
void addWarmUpOption(CLI::App& cmd, bool& noWarmUp, const std::string& also = "");

} // namespace replica::platform
