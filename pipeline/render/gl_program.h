// Compiling and linking GLES programs with errors that carry the driver's log, and the one
// full-screen vertex shader every pass draws with.
#pragma once

#include <initializer_list>

#include <GLES3/gl31.h>
#include <glm/vec3.hpp>

#include <pipeline/base/expected.h>
#include <pipeline/render/gl_handles.h>

namespace replica::pipeline::render {

// A triangle covering the viewport (drawn with glDrawArrays(GL_TRIANGLES, 0, 3)); vUv runs 0..1.
extern const char* const kFullscreenVertexShader;

// Needs a current GLES 3.1 context. 'what' names the program in error messages.
Expected<GlShader> compileShader(GLenum type, const char* source, const char* what);

// Links the compiled shaders into a program (the shaders stay their owners' to delete; a linked
// program keeps what it needs of them).
Expected<GlProgram> linkShaders(std::initializer_list<const GlShader*> shaders, const char* what);

// Vertex + fragment from source.
Expected<GlProgram>
linkProgram(const char* vertexSource, const char* fragmentSource, const char* what);

// Sets vec3 uniform 'name' of the current program 'program' to 'v' rounded to float.
void setUniform3(GLuint program, const char* name, const glm::dvec3& v);

// Whether the current context lists the extension (e.g. "GL_OES_texture_float_linear").
bool hasExtension(const char* name);

} // namespace replica::pipeline::render
