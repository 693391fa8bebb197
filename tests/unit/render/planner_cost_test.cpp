// The planner's cost model (shading::settingCost) against the frames it was fitted to: the
// committed output of tests/benchmarks/replica_bench_cost_model (tests/benchmarks/measured/, the
// runs docs/rendering.md's table cites). The model must order two measured settings as their
// measured times do wherever the runs tell them apart (every run of one faster than every run of
// the other: on the shared 2-core machine one setting's median moved by up to 25 % between runs),
// and price what the measurements show: every count costs something, a specular sample costs more
// on relief (per-pixel specular) than on a flat surface (shaded on the 8-texel grid).
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include <pipeline/tuning/planner.h>

#include <gtest/gtest.h>

namespace replica::pipeline {
namespace {

using CostSetting = std::tuple<int, int, int>; // lights, specular samples, horizon directions

// scene -> setting -> the tilt-moving CPU medians of every committed run ("| L | S | D | measured
// | fitted | settingCost |" rows after the "SCENE fit" line that heads them).
std::map<std::string, std::map<CostSetting, std::vector<double>>> committedCostRuns()
{
    std::map<std::string, std::map<CostSetting, std::vector<double>>> out;
    const auto dir = std::filesystem::path(REPLICA_SOURCE_DIR) / "tests/benchmarks/measured";
    for (const auto& entry : std::filesystem::directory_iterator(dir)) {
        if (entry.path().filename().string().rfind("cost_model-", 0) != 0) {
            continue;
        }
        std::ifstream in(entry.path());
        std::string line;
        std::string scene;
        while (std::getline(in, line)) {
            if (const auto at = line.find(" fit ("); at != std::string::npos) {
                scene = line.substr(0, at);
            }
            int l = 0;
            int s = 0;
            int d = 0;
            double ms = 0.0;
            if (!scene.empty() &&
                std::sscanf(line.c_str(), "| %d | %d | %d | %lf |", &l, &s, &d, &ms) == 4) {
                out[scene][{l, s, d}].push_back(ms);
            }
        }
    }
    return out;
}

// 'grids': the glossy cylinder's (specular every 2 texels, diffuse every 4), with which its runs
// were timed; else per pixel on relief (the painting's).
shading::RenderSettings costSettings(const CostSetting& k, bool grids = false)
{
    shading::RenderSettings s;
    s.specularGrid = grids ? 2 : 0;
    s.diffuseGrid = grids ? 4 : 0;
    s.lights = std::get<0>(k);
    s.specularSamples = std::get<1>(k);
    s.horizonDirections = std::get<2>(k);
    s.walls = false;
    return s;
}

// Every pair of settings where each run of one was faster than each run of the other is ordered
// the same way by settingCost. Returns how many pairs were compared.
int checkCostOrder(const std::string& scene, bool glossy, bool relief, bool grids = false)
{
    const auto runs = committedCostRuns();
    const auto it = runs.find(scene);
    EXPECT_NE(it, runs.end()) << "no committed cost_model run for " << scene;
    if (it == runs.end()) {
        return 0;
    }
    int compared = 0;
    for (const auto& [a, ra] : it->second) {
        EXPECT_GE(ra.size(), 2u) << scene << ": a single run cannot say what its noise is";
        for (const auto& [b, rb] : it->second) {
            const double slowestA = *std::max_element(ra.begin(), ra.end());
            const double fastestB = *std::min_element(rb.begin(), rb.end());
            if (!(slowestA < fastestB)) {
                continue; // the runs do not tell a from b
            }
            ++compared;
            EXPECT_LT(shading::settingCost(costSettings(a, grids), glossy, relief),
                      shading::settingCost(costSettings(b, grids), glossy, relief))
                    << scene << ": " << std::get<0>(a) << "/" << std::get<1>(a) << "/"
                    << std::get<2>(a) << " measured at most " << slowestA << " ms, "
                    << std::get<0>(b) << "/" << std::get<1>(b) << "/" << std::get<2>(b)
                    << " at least " << fastestB << " ms";
        }
    }
    return compared;
}

// The painting's runs tell 99 of its 153 pairs apart; the cost model before this refit (0.43
// ms a light, 0.46 a direction, 1.35 a sample) put 32 lights / 4 samples / 16 directions below
// 8 / 16 / 8, which every run measured the other way round.
TEST(PlannerCost, OrdersThePaintingsMeasuredSettingsAsTheFrameTimesDo)
{
    EXPECT_GE(checkCostOrder("painting", true, true), 90);
}

// The ColorChecker's runs tell only lights apart (16 pairs, 8 or 32 against 128; the samples
// not at all).
TEST(PlannerCost, OrdersTheColorCheckersMeasuredSettingsAsTheFrameTimesDo)
{
    EXPECT_GE(checkCostOrder("colorchecker", true, false), 10);
}

// The glossy cylinder on its grids: the runs tell lights and samples apart at their ends (8
// against 128 lights, 4 against 48 samples); the per-pixel relief model (1.58 ms a sample, 0.625 a
// light) priced its 128 lights / 48 samples at 166 ms against 25 measured.
TEST(PlannerCost, OrdersTheGlossyCylindersMeasuredSettingsAsTheFrameTimesDo)
{
    EXPECT_GE(checkCostOrder("glossy-cylinder", true, true, true), 40);
    // Its frame with 128 lights and 48 samples: the grid model within a quarter of the runs'
    // median (25.1 ms with t0 about 15: what the counts add, 10 ms, against the model's).
    const double added = shading::settingCost(costSettings({128, 48, 8}, true), true, true) -
                         shading::settingCost(costSettings({8, 4, 8}, true), true, true);
    EXPECT_NEAR(added, 25.1 - 15.4, 0.25 * (25.1 - 15.4));
}

TEST(PlannerCost, EveryCountCostsAndASampleCostsMoreOnRelief)
{
    for (const bool relief : {false, true}) {
        const shading::RenderSettings base = costSettings({32, 8, 8});
        for (const auto& more :
             {costSettings({33, 8, 8}), costSettings({32, 9, 8}), costSettings({32, 8, 9})}) {
            if (!relief && more.horizonDirections != base.horizonDirections) {
                continue; // flat surfaces have no horizons
            }
            EXPECT_GT(shading::settingCost(more, true, relief),
                      shading::settingCost(base, true, relief))
                    << (relief ? "relief " : "flat ") << more.lights << "/" << more.specularSamples
                    << "/" << more.horizonDirections;
        }
        shading::RenderSettings walled = base;
        walled.walls = true;
        EXPECT_GT(shading::settingCost(walled, true, relief),
                  shading::settingCost(base, true, relief));
    }
    const auto perSample = [](bool relief) {
        return shading::settingCost(costSettings({32, 9, 8}), true, relief) -
               shading::settingCost(costSettings({32, 8, 8}), true, relief);
    };
    EXPECT_LT(perSample(false), perSample(true));
}

} // namespace
} // namespace replica::pipeline
