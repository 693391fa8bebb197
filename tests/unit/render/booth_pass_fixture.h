// The fixture of the GLES booth pass tests (booth_shading_pass_test.cpp,
// booth_pass_budget_test.cpp, booth_pass_hard_cases_test.cpp): the shipped scenes, booth and
// observer loaded once, and the comparisons with the CPU model and the exact reference that those
// files share.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include <pipeline/base/data_dir.h>
#include <pipeline/booth/booth_model.h>
#include <pipeline/reference/frame_error.h>
#include <pipeline/reference/reference_integrator.h>
#include <pipeline/render/booth_shading_pass.h>
#include <pipeline/spectral/adaptive_encoding.h>

#include <gtest/gtest.h>

#include "../support/headless_gl.h"
#include "render_fixtures.h"

namespace replica::pipeline::render {

// Float (shader) against double (model): the largest relative difference of any pixel's Y,
// counted over pixels brighter than 1% of the white, and CIEDE2000 between the two frames.
struct Agreement {
    double maxRelY = 0.0;
    double fracOverTol = 0.0; // share of pixels with a relative Y difference above kRelTol
    reference::FrameError de;
};
inline constexpr double kRelTol = 1e-4;

inline Agreement agree(const shading::XyzFrame& cpu, const shading::XyzFrame& gl)
{
    Agreement a;
    long over = 0, counted = 0;
    for (std::size_t i = 0; i < cpu.xyz.size(); ++i) {
        const double ref = cpu.xyz[i].y;
        if (ref < 0.01 * cpu.whiteY) {
            continue;
        }
        const double rel = std::abs(gl.xyz[i].y - ref) / ref;
        a.maxRelY = std::max(a.maxRelY, rel);
        over += rel > kRelTol ? 1 : 0;
        ++counted;
    }
    a.fracOverTol = counted > 0 ? static_cast<double>(over) / static_cast<double>(counted) : 1.0;
    a.de = reference::compareFrames(cpu, gl);
    return a;
}

class BoothPassTest : public tests::HeadlessGlTest
{
protected:
    static void SetUpTestSuite()
    {
        obs_ = new colour::Observer(*colour::loadCie1931(dataDir()));
        booth_ = new booth::Booth(*booth::loadBooth(dataDir() / "booth"));
        basis_ = new colour::ChannelBasis(*colour::loadDefaultChannelBasis(dataDir()));
        for (const char* name : {"colorchecker", "metamer", "painting", "glossy-cylinder"}) {
            auto s = surface::loadScene(dataDir() / "scenes" / name);
            ASSERT_TRUE(s) << s.error().message;
            scenes_[name] = *s;
        }
    }
    static void TearDownTestSuite()
    {
        delete obs_;
        delete booth_;
        delete basis_;
        scenes_.clear();
    }
    // The default settings with the painting's specular sample count: what the horizon tests
    // below vary one setting of.
    static shading::RenderSettings paintingSettings()
    {
        shading::RenderSettings settings;
        settings.specularSamples = shading::defaultSpecularSamples(scenes_.at("painting"));
        return settings;
    }

    static shading::View view(int w, int h, double tiltDeg = 30.0)
    {
        shading::View v;
        v.panel = scene::panelPose(scene::degreesToRadians(tiltDeg));
        v.pixelsX = w;
        v.pixelsY = h;
        return v;
    }

    // The GL pass's frame of 'light' (already set on the pass) against the exact reference's.
    static reference::FrameError errorAgainstReference(BoothShadingPass& pass,
                                                       const shading::PreparedLight& pl,
                                                       const surface::SurfaceScene& scene,
                                                       const booth::BoothLight& light,
                                                       const shading::View& v)
    {
        auto gl = renderBoothFrame(pass, pl, v);
        EXPECT_TRUE(gl) << gl.error().message;
        if (!gl) {
            return {1e9, 1e9, 1e9}; // fails every budget below
        }
        return reference::compareFrames(reference::renderReference(scene, light, v, *obs_), *gl);
    }

    // The GL pass with 'settings' on 'scene' against the CPU model under tungsten and
    // d65-fluorescent (every booth light with 'everyLight'). Stated tolerance: float against
    // double agrees to 1e-4 in Y on all but 0.2% of the pixels (where a cosine or horizon test may
    // sit on its threshold), and to 0.01 dE00 at most, 0.001 on average; the white the frame is
    // judged against is the same. 'label' names the case in a failure. 'hardwareFilter', when
    // given, receives whether the pass filters the luminance chain with the sampler; 'glFrames',
    // the GL frames in the order of the lights.
    static void expectMatchesTheCpuModel(const surface::SurfaceScene& scene,
                                         const shading::RenderSettings& settings,
                                         const shading::View& v,
                                         const std::string& label,
                                         bool everyLight = false,
                                         bool* hardwareFilter = nullptr,
                                         std::vector<shading::XyzFrame>* glFrames = nullptr)
    {
        const auto ps = shading::prepareScene(scene, settings.horizonDirections, 0.01, *basis_);
        auto pass = BoothShadingPass::create(ps, settings, *obs_);
        ASSERT_TRUE(pass) << pass.error().message;
        if (hardwareFilter != nullptr) {
            *hardwareFilter = (*pass)->hardwareFilter();
        }
        for (std::size_t i = 0; i < booth_->lights.size(); ++i) {
            if (!everyLight && i != 0 && i != 2) {
                continue; // tungsten and d65-fluorescent
            }
            const auto& light = booth_->lights[i];
            const auto pl = shading::prepareLight(light, *obs_, settings.lights, *basis_);
            ASSERT_TRUE((*pass)->setLight(pl));
            const auto cpu = shading::renderRealtime(ps, pl, v, *obs_, settings);
            auto gl = renderBoothFrame(**pass, pl, v);
            ASSERT_TRUE(gl) << gl.error().message;
            EXPECT_EQ(gl->nonFinite, 0);
            EXPECT_DOUBLE_EQ(gl->whiteY, cpu.whiteY) << label << " / " << light.name;
            const Agreement a = agree(cpu, *gl);
            EXPECT_LE(a.fracOverTol, 0.002)
                    << label << " / " << light.name << " max rel " << a.maxRelY;
            EXPECT_LE(a.de.max, 0.01) << label << " / " << light.name;
            EXPECT_LE(a.de.mean, 0.001) << label << " / " << light.name;
            if (glFrames != nullptr) {
                glFrames->push_back(std::move(*gl));
            }
        }
    }

    // The GL pass with 'settings' on 'scene' under every booth light (or only the one named
    // 'onlyLight') against the exact reference from each of 'views': the budget, dE00 p95
    // <= 1 and max <= 3.
    static void expectWithinBudget(const surface::SurfaceScene& scene,
                                   const shading::RenderSettings& settings,
                                   const std::vector<shading::View>& views,
                                   const std::string& onlyLight = {})
    {
        const auto ps = shading::prepareScene(scene, settings.horizonDirections, 0.01, *basis_);
        auto pass = BoothShadingPass::create(ps, settings, *obs_);
        ASSERT_TRUE(pass) << pass.error().message;
        int lights = 0;
        for (const auto& light : booth_->lights) {
            if (!onlyLight.empty() && light.name != onlyLight) {
                continue;
            }
            ++lights;
            const auto pl = shading::prepareLight(light, *obs_, settings.lights, *basis_);
            ASSERT_TRUE((*pass)->setLight(pl));
            for (const shading::View& v : views) {
                const auto e = errorAgainstReference(**pass, pl, scene, light, v);
                EXPECT_LE(e.p95, 1.0) << scene.name << ", " << light.name << ", eye x " << v.eye.x;
                EXPECT_LE(e.max, 3.0) << scene.name << ", " << light.name << ", eye x " << v.eye.x;
            }
        }
        EXPECT_GT(lights, 0) << "no booth light named " << onlyLight;
    }

    // Alpha 0 to 2, a single hot texel, a zero image, a light almost in the surface plane, tilts
    // 0-135 deg, an eye behind the screen: no NaN or Inf in a read-back pixel, no negative Y.
    static void expectHardCasesFinite(surface::SurfaceScene scene,
                                      const shading::RenderSettings& settings);

    inline static colour::Observer* obs_ = nullptr;
    inline static booth::Booth* booth_ = nullptr;
    inline static colour::ChannelBasis* basis_ = nullptr;
    inline static std::map<std::string, surface::SurfaceScene> scenes_;
};

} // namespace replica::pipeline::render
