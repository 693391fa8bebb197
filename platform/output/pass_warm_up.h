// The booth's shading passes compiled around the first frame (issue 35: the first frame within
// 2 s of start): the first frame compiles only the pass of the lamp it shows; after it, a thread
// of its own, in an EGL context of its own, compiles every other lamp's pass, and once it is done
// the loop draws each of those passes once in its idle time after a frame, so that a lamp switch
// does not compile.
//
// Why both: llvmpipe compiles a program's code at its first draw, per context, and cannot share
// compiled shaders between contexts (PIPE_CAP_SHAREABLE_SHADERS is 0: its draw module's state is
// per context), so the thread's compilation reaches the loop's context only through Mesa's shader
// cache (llvmpipe's compiled code on disk, keyed by the shader and its state): the loop's own
// compile of a pass then reads it instead of running LLVM (a few hundred ms, not seconds). With
// the cache off (MESA_SHADER_CACHE_DISABLE) the thread is not started and each pass compiles at
// its first use, as with --no-warm-up.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <future>
#include <memory>
#include <thread>
#include <vector>

#include <pipeline/base/expected.h>
#include <pipeline/render/booth_scene_pass.h>

namespace replica::platform {

// Compiles shading passes of a booth scene on a thread of its own. The thread shares nothing with
// the caller but what start() copies: its own BoothScenePass made from a copy of the scene's
// setup, in its own EGL context (on the calling thread's current display, no objects shared), at
// the lowest priority.
class BackgroundPassCompile
{
public:
    // Starts compiling 'variants' (BoothScenePass variant indices) of 'scene', each drawn once
    // into a width x height target. Needs a current EGL context on the calling thread.
    static Expected<std::unique_ptr<BackgroundPassCompile>>
    start(const pipeline::render::BoothScenePass& scene,
          std::vector<std::size_t> variants,
          int width,
          int height);
    // Asks the thread to stop after the pass it compiles now, and waits for it.
    ~BackgroundPassCompile();
    BackgroundPassCompile(const BackgroundPassCompile&) = delete;
    BackgroundPassCompile& operator=(const BackgroundPassCompile&) = delete;

    // Whether the thread is done (result() then does not wait).
    bool done() const;
    // How long the thread took, ms, or why it failed; waits for the thread.
    Expected<double> result();

private:
    BackgroundPassCompile() = default;
    std::atomic<bool> stop_{false};
    std::future<Expected<double>> result_;
    std::thread thread_;
};

// What the run's loop calls after each frame (on its thread, its GL context current): logs the
// frames that compiled a pass (the first frame, a switch to a pass not compiled yet), starts the
// background compile after the first frame, and once it is done draws one pass the loop has not
// drawn per frame (BoothScenePass::warmUpVariant).
class PassWarmUp
{
public:
    PassWarmUp(std::shared_ptr<pipeline::render::BoothScenePass> scene, int width, int height);
    void afterFrame(std::uint64_t frame);
    // Waits for the thread (a run shorter than the compile), said in the log.
    void finish();

    // The frames that compiled a pass, and the passes drawn in the loop's idle time.
    long compilingFrames() const { return seen_; }
    int idleWarmUps() const { return static_cast<int>(idleWarmUpMs_.size()); }
    // Each idle-time warm-up's time, ms (the delay it gave the next frame), and the thread's.
    const std::vector<double>& idleWarmUpMs() const { return idleWarmUpMs_; }
    double backgroundMs() const { return backgroundMs_; }
    // Whether nothing more will be compiled ahead (all drawn, the thread refused or failed).
    bool settled() const { return started_ && !compile_ && (!background_ || allDrawn()); }

private:
    std::shared_ptr<pipeline::render::BoothScenePass> scene_;
    int width_ = 0;
    int height_ = 0;
    bool started_ = false;
    bool background_ = false; // the thread ran (or runs) and was not refused
    bool allDrawn() const { return scene_->variantsNotDrawn().empty(); }
    long seen_ = 0;
    std::vector<double> idleWarmUpMs_;
    double backgroundMs_ = 0.0;
    std::unique_ptr<BackgroundPassCompile> compile_;
};

// Whether Mesa's shader cache is off (MESA_SHADER_CACHE_DISABLE true, or the older
// MESA_GLSL_CACHE_DISABLE).
bool mesaShaderCacheDisabled();

} // namespace replica::platform
