// The booth's shading passes compiled around the first frame: the background thread and the
// loop's idle-time warm-ups.
#include <chrono>
#include <cstdlib>
#include <string>

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <fmt/format.h>
#include <sys/resource.h>
#include <unistd.h>

#include <platform/logging.h>
#include <platform/output/egl_util.h>
#include <platform/output/pass_warm_up.h>

namespace replica::platform {
namespace {

// Made, drawn and destroyed with the thread's context current.
Expected<void> compileVariants(const pipeline::render::BoothSceneSetup& setup,
                               const std::vector<std::size_t>& variants,
                               int width,
                               int height,
                               const std::atomic<bool>& stop)
{
    auto pass = pipeline::render::BoothScenePass::create(setup);
    if (!pass) {
        return tl::unexpected(pass.error());
    }
    for (std::size_t i = 0; i < variants.size() && !stop.load(); ++i) {
        if (auto ms = (*pass)->warmUpVariant(variants[i], width, height); !ms) {
            return tl::unexpected(ms.error());
        }
    }
    return {};
}

// The thread's body, in a context of its own on 'display'.
Expected<double> compileInContext(EGLDisplay display,
                                  const pipeline::render::BoothSceneSetup& setup,
                                  const std::vector<std::size_t>& variants,
                                  int width,
                                  int height,
                                  const std::atomic<bool>& stop)
{
    const auto start = std::chrono::steady_clock::now();
    // The lowest priority: the loop's frames (and llvmpipe's raster threads, which this thread's
    // context starts and which inherit it) come first.
    if (setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), 19) != 0) {
        // Refused (a sandbox): the thread compiles at the loop's priority.
    }
    if (eglBindAPI(EGL_OPENGL_ES_API) != EGL_TRUE) {
        return makeError(ErrorCode::Unsupported, "background compile: EGL cannot bind OpenGL ES (" +
                                                         eglErrorString() + ")");
    }
    const EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 1, EGL_NONE};
    EGLContext context = eglCreateContext(display, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attribs);
    if (context == EGL_NO_CONTEXT) {
        return makeError(ErrorCode::Unsupported,
                         "background compile: no GLES 3.1 context of its own (" + eglErrorString() +
                                 ")");
    }
    Expected<void> ok;
    if (eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context) != EGL_TRUE) {
        ok = makeError(ErrorCode::Unsupported,
                       "background compile: cannot make its context current (" + eglErrorString() +
                               ")");
    } else {
        ok = compileVariants(setup, variants, width, height, stop);
        eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    }
    eglDestroyContext(display, context);
    eglReleaseThread();
    if (!ok) {
        return tl::unexpected(ok.error());
    }
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count();
}

} // namespace

bool mesaShaderCacheDisabled()
{
    for (const char* name : {"MESA_SHADER_CACHE_DISABLE", "MESA_GLSL_CACHE_DISABLE"}) {
        if (const char* v = std::getenv(name); v != nullptr) {
            const std::string s(v);
            if (s == "true" || s == "1" || s == "yes" || s == "y") {
                return true;
            }
        }
    }
    return false;
}

Expected<std::unique_ptr<BackgroundPassCompile>>
BackgroundPassCompile::start(const pipeline::render::BoothScenePass& scene,
                             std::vector<std::size_t> variants,
                             int width,
                             int height)
{
    EGLDisplay display = eglGetCurrentDisplay();
    if (display == EGL_NO_DISPLAY) {
        return makeError(ErrorCode::Unsupported, "background compile: no current EGL display");
    }
    std::unique_ptr<BackgroundPassCompile> c(new BackgroundPassCompile());
    std::promise<Expected<double>> promise;
    c->result_ = promise.get_future();
    // The copy is the thread's alone from here.
    c->thread_ = std::thread([display, setup = scene.setup(), variants = std::move(variants), width,
                              height, stop = &c->stop_, promise = std::move(promise)]() mutable {
        promise.set_value(compileInContext(display, setup, variants, width, height, *stop));
    });
    return c;
}

BackgroundPassCompile::~BackgroundPassCompile()
{
    stop_.store(true);
    if (thread_.joinable()) {
        thread_.join();
    }
}

bool BackgroundPassCompile::done() const
{
    return result_.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
}

Expected<double> BackgroundPassCompile::result()
{
    if (thread_.joinable()) {
        thread_.join();
    }
    return result_.get();
}

PassWarmUp::PassWarmUp(std::shared_ptr<pipeline::render::BoothScenePass> scene,
                       int width,
                       int height)
    : scene_(std::move(scene)), width_(width), height_(height)
{}

void PassWarmUp::afterFrame(std::uint64_t frame)
{
    auto log = logger("render");
    if (scene_->firstUseDraws() > seen_) {
        seen_ = scene_->firstUseDraws();
        log->info("frame {} drew its shading pass for the first time: {:.0f} ms with the "
                  "compilation ({} such frame(s) so far)",
                  frame, scene_->lastFirstUseMs(), seen_);
    }
    if (started_ && !compile_ && !background_) {
        return; // nothing (more) compiled ahead
    }
    const auto pending = scene_->variantsNotDrawn();
    if (!started_) {
        started_ = true;
        if (pending.empty()) {
            return;
        }
        if (mesaShaderCacheDisabled()) {
            log->info("Mesa's shader cache is off: {} other shading pass(es) compile at their "
                      "first use",
                      pending.size());
            return;
        }
        auto c = BackgroundPassCompile::start(*scene_, pending, width_, height_);
        if (!c) {
            log->warn("{}; {} other shading pass(es) compile at their first use", c.error().message,
                      pending.size());
            return;
        }
        compile_ = std::move(*c);
        background_ = true;
        log->info("compiling {} other shading pass(es) in the background", pending.size());
        return;
    }
    if (compile_ && compile_->done()) {
        auto ms = compile_->result();
        compile_.reset();
        if (!ms) {
            log->warn("{}; the other shading passes compile at their first use",
                      ms.error().message);
            background_ = false;
        } else {
            backgroundMs_ = *ms;
            log->info("background compile of the other shading passes done in {:.0f} ms", *ms);
        }
        return;
    }
    if (compile_) {
        return;
    }
    if (pending.empty()) {
        background_ = false; // every pass drawn
        return;
    }
    // One pass per frame, from the shader cache the thread filled.
    auto ms = scene_->warmUpVariant(pending.front(), width_, height_);
    if (!ms) {
        log->warn("shading pass {}: {}; it compiles at its first use", pending.front(),
                  ms.error().message);
        background_ = false;
        return;
    }
    idleWarmUpMs_.push_back(*ms);
    log->info("shading pass {} compiled after frame {} in {:.0f} ms (from the shader cache)",
              pending.front(), frame, *ms);
}

void PassWarmUp::finish()
{
    if (compile_) {
        if (!compile_->done()) {
            logger("render")->info("waiting for the background compile to stop");
        }
        compile_.reset();
    }
    background_ = false; // nothing more compiled ahead
}

} // namespace replica::platform
