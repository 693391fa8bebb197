// Small EGL helpers shared by the headless and the KMS outputs.
#pragma once

#include <string>

namespace replica::platform {

// Whether 'name' is a whole word of the space-separated extension list (nullptr: none).
bool hasExtension(const char* list, const char* name);

// The calling thread's last EGL error as "EGL error 0x3003", for messages.
std::string eglErrorString();

} // namespace replica::platform
