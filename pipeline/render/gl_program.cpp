// GLES program compilation with the info log in the error.
#include <array>

#include <fmt/format.h>

#include <pipeline/render/gl_program.h>

namespace replica::pipeline::render {
namespace {

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
                                     type == GL_VERTEX_SHADER ? "vertex" : "fragment", log.data()));
    }
    return shader;
}

} // namespace

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
    GLuint program = glCreateProgram();
    glAttachShader(program, *vs);
    glAttachShader(program, *fs);
    glLinkProgram(program);
    glDeleteShader(*vs);
    glDeleteShader(*fs);
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

} // namespace replica::pipeline::render
