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

Expected<GlShader> compileShader(GLenum type, const char* source, const char* what)
{
    GlShader shader(glCreateShader(type));
    const char* const sources[] = {source};
    glShaderSource(shader.get(), 1, sources, nullptr);
    glCompileShader(shader.get());
    GLint ok = GL_FALSE;
    glGetShaderiv(shader.get(), GL_COMPILE_STATUS, &ok);
    if (ok != GL_TRUE) {
        std::array<char, 4096> log{};
        glGetShaderInfoLog(shader.get(), static_cast<GLsizei>(log.size()), nullptr, log.data());
        return makeError(ErrorCode::Unsupported,
                         fmt::format("render: {} {} shader does not compile: {}", what,
                                     stageName(type), log.data()));
    }
    return shader;
}

Expected<GlProgram> linkShaders(std::initializer_list<const GlShader*> shaders, const char* what)
{
    GlProgram program = GlProgram::make();
    for (const GlShader* s : shaders) {
        glAttachShader(program.get(), s->get());
    }
    glLinkProgram(program.get());
    GLint ok = GL_FALSE;
    glGetProgramiv(program.get(), GL_LINK_STATUS, &ok);
    if (ok != GL_TRUE) {
        std::array<char, 4096> log{};
        glGetProgramInfoLog(program.get(), static_cast<GLsizei>(log.size()), nullptr, log.data());
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

Expected<GlProgram>
linkProgram(const char* vertexSource, const char* fragmentSource, const char* what)
{
    auto vs = compileShader(GL_VERTEX_SHADER, vertexSource, what);
    if (!vs) {
        return tl::unexpected(vs.error());
    }
    auto fs = compileShader(GL_FRAGMENT_SHADER, fragmentSource, what);
    if (!fs) {
        return tl::unexpected(fs.error());
    }
    return linkShaders({&*vs, &*fs}, what);
}

void setUniform3(GLuint program, const char* name, const glm::dvec3& v)
{
    glUniform3f(glGetUniformLocation(program, name), static_cast<float>(v.x),
                static_cast<float>(v.y), static_cast<float>(v.z));
}

} // namespace replica::pipeline::render
