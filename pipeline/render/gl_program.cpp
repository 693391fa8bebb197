// GLES program compilation with the info log in the error.
#include <array>
#include <cstring>

#include <fmt/format.h>

#include <pipeline/render/gl_program.h>

namespace replica::pipeline::render {
namespace {

const char* stageName(GLenum type)
{
    switch (type) {
    case GL_VERTEX_SHADER:
        return "vertex";
    case GL_FRAGMENT_SHADER:
        return "fragment";
    case GL_COMPUTE_SHADER:
        return "compute";
    default:
        return "unknown";
    }
}

} // namespace

const char* const kFullscreenVertexShader = R"(#version 310 es
out vec2 vUv;
void main() {
    vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
    vUv = p;
    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
)";

Expected<GLuint> compileShader(GLenum type, const char* source, const char* what)
{
    GLuint shader = glCreateShader(type);
    glShaderSource(shader, 1, &source, nullptr);
    glCompileShader(shader);
    GLint ok = GL_FALSE;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (ok != GL_TRUE) {
        std::array<char, 4096> log{};
        glGetShaderInfoLog(shader, static_cast<GLsizei>(log.size()), nullptr, log.data());
        glDeleteShader(shader);
        return makeError(ErrorCode::Unsupported,
                         fmt::format("render: {} {} shader does not compile: {}", what,
                                     stageName(type), log.data()));
    }
    return shader;
}

Expected<GLuint> linkShaders(std::initializer_list<GLuint> shaders, const char* what)
{
    GLuint program = glCreateProgram();
    for (const GLuint s : shaders) {
        glAttachShader(program, s);
    }
    glLinkProgram(program);
    for (const GLuint s : shaders) {
        glDeleteShader(s);
    }
    GLint ok = GL_FALSE;
    glGetProgramiv(program, GL_LINK_STATUS, &ok);
    if (ok != GL_TRUE) {
        std::array<char, 4096> log{};
        glGetProgramInfoLog(program, static_cast<GLsizei>(log.size()), nullptr, log.data());
        glDeleteProgram(program);
        return makeError(ErrorCode::Unsupported,
                         fmt::format("render: {} program does not link: {}", what, log.data()));
    }
    return program;
}

bool hasExtension(const char* name)
{
    GLint n = 0;
    glGetIntegerv(GL_NUM_EXTENSIONS, &n);
    for (GLint i = 0; i < n; ++i) {
        const auto* e =
                reinterpret_cast<const char*>(glGetStringi(GL_EXTENSIONS, static_cast<GLuint>(i)));
        if (e != nullptr && std::strcmp(e, name) == 0) {
            return true;
        }
    }
    return false;
}

Expected<GLuint> linkProgram(const char* vertexSource, const char* fragmentSource, const char* what)
{
    auto vs = compileShader(GL_VERTEX_SHADER, vertexSource, what);
    if (!vs) {
        return tl::unexpected(vs.error());
    }
    auto fs = compileShader(GL_FRAGMENT_SHADER, fragmentSource, what);
    if (!fs) {
        glDeleteShader(*vs);
        return tl::unexpected(fs.error());
    }
    return linkShaders({*vs, *fs}, what);
}

} // namespace replica::pipeline::render
