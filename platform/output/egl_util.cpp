// Small EGL helpers shared by the headless and the KMS outputs.
#include <cstring>

#include <EGL/egl.h>
#include <fmt/format.h>

#include <platform/output/egl_util.h>

namespace replica::platform {

bool hasExtension(const char* list, const char* name)
{
    if (list == nullptr) {
        return false;
    }
    // A bare strstr would take "EGL_KHR_surfaceless" for "EGL_KHR_surfaceless_context"'s prefix.
    const std::size_t n = std::strlen(name);
    for (const char* p = list; (p = std::strstr(p, name)) != nullptr; p += n) {
        if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) {
            return true;
        }
    }
    return false;
}

std::string eglErrorString()
{
    return fmt::format("EGL error 0x{:04x}", eglGetError());
}

} // namespace replica::platform
