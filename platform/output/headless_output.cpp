// Headless output: a surfaceless EGL display and a GLES 3 context with no window.
#include <cstring>

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GLES3/gl3.h>
#include <fmt/format.h>

#include <platform/output/egl_util.h>
#include <platform/output/output.h>

namespace replica::platform {
namespace {

class HeadlessOutput final : public Output
{
public:
    HeadlessOutput(EGLDisplay display, EGLContext context) : display_(display), context_(context) {}
    ~HeadlessOutput() override
    {
        eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(display_, context_);
        eglTerminate(display_);
    }
    HeadlessOutput(const HeadlessOutput&) = delete;
    HeadlessOutput& operator=(const HeadlessOutput&) = delete;

    std::string name() const override { return "headless"; }
    std::string glRenderer() const override
    {
        const auto* r = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
        return r != nullptr ? r : "unknown";
    }
    Expected<void> present(const DisplayFrame& /*frame*/) override { return {}; }

private:
    EGLDisplay display_;
    EGLContext context_;
};

// Tries the surfaceless platform (Mesa: llvmpipe or a GPU's render node), then EGL devices
// (NVIDIA).
EGLDisplay openDisplay(std::string& tried)
{
    const char* clientExts = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    auto getPlatformDisplay = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
            eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (getPlatformDisplay == nullptr) {
        tried = "eglGetPlatformDisplayEXT is missing";
        return EGL_NO_DISPLAY;
    }
    if (hasExtension(clientExts, "EGL_MESA_platform_surfaceless")) {
        EGLDisplay d =
                getPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
        EGLint major = 0;
        EGLint minor = 0;
        if (d != EGL_NO_DISPLAY && eglInitialize(d, &major, &minor) == EGL_TRUE) {
            return d;
        }
        tried += "surfaceless platform failed (" + eglErrorString() + "); ";
    }
    if (hasExtension(clientExts, "EGL_EXT_platform_device")) {
        auto queryDevices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(
                eglGetProcAddress("eglQueryDevicesEXT"));
        EGLDeviceEXT devices[8];
        EGLint count = 0;
        if (queryDevices != nullptr && queryDevices(8, devices, &count) == EGL_TRUE) {
            for (EGLint i = 0; i < count; ++i) {
                EGLDisplay d = getPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
                if (d != EGL_NO_DISPLAY && eglInitialize(d, nullptr, nullptr) == EGL_TRUE) {
                    return d;
                }
            }
        }
        tried += "no EGL device initialised; ";
    }
    return EGL_NO_DISPLAY;
}

} // namespace

Expected<std::unique_ptr<Output>> createHeadlessOutput()
{
    std::string tried;
    EGLDisplay display = openDisplay(tried);
    if (display == EGL_NO_DISPLAY) {
        return makeError(
                ErrorCode::Unsupported,
                fmt::format("headless output: no EGL display could be opened ({}); install Mesa's "
                            "libegl-mesa0 and libgl1-mesa-dri (deploy/install-deps)",
                            tried));
    }
    if (eglBindAPI(EGL_OPENGL_ES_API) != EGL_TRUE) {
        eglTerminate(display);
        return makeError(ErrorCode::Unsupported,
                         "headless output: EGL cannot bind OpenGL ES (" + eglErrorString() + ")");
    }
    const EGLint contextAttribs[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 1,
                                     EGL_NONE};
    EGLContext context =
            eglCreateContext(display, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, contextAttribs);
    if (context == EGL_NO_CONTEXT) {
        const std::string err = eglErrorString();
        eglTerminate(display);
        return makeError(
                ErrorCode::Unsupported,
                "headless output: cannot create an OpenGL ES 3.1 context with no config (" + err +
                        "); the EGL driver needs EGL_KHR_no_config_context");
    }
    if (eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context) != EGL_TRUE) {
        const std::string err = eglErrorString();
        eglDestroyContext(display, context);
        eglTerminate(display);
        return makeError(ErrorCode::Unsupported,
                         "headless output: cannot make a surfaceless context current (" + err +
                                 ")");
    }
    return std::make_unique<HeadlessOutput>(display, context);
}

} // namespace replica::platform
