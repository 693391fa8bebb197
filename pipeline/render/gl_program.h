// Compiling and linking a GLES program with errors that carry the driver's log.
#pragma once

#include <GLES3/gl31.h>

#include <pipeline/base/expected.h>

namespace replica::pipeline::render {

// Needs a current GLES 3.1 context. 'what' names the program in error messages.
Expected<GLuint>
linkProgram(const char* vertexSource, const char* fragmentSource, const char* what);

} // namespace replica::pipeline::render
