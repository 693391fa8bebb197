// RAII handles for GL objects, and the one helper that makes a 2-D texture. Every GL object the
// renderer makes is held by one of these: deleted once, when its owner goes (with the owner's
// context current, as every pass's life already requires), moved and never copied.
#pragma once

#include <utility>

#include <GLES3/gl31.h>

namespace replica::pipeline::render {

// Owns one GL name of the kind Traits deletes; 0 is "none" (deleting 0 is never called).
template <typename Traits>
class GlHandle
{
public:
    GlHandle() = default;
    explicit GlHandle(GLuint name) : name_(name) {}
    ~GlHandle() { reset(); }
    GlHandle(const GlHandle&) = delete;
    GlHandle& operator=(const GlHandle&) = delete;
    GlHandle(GlHandle&& other) noexcept : name_(std::exchange(other.name_, 0u)) {}
    GlHandle& operator=(GlHandle&& other) noexcept
    {
        if (this != &other) {
            reset(std::exchange(other.name_, 0u));
        }
        return *this;
    }

    // A fresh name from glGen* (glCreate* for programs and shaders).
    static GlHandle make() { return GlHandle(Traits::make()); }

    GLuint get() const { return name_; }
    explicit operator bool() const { return name_ != 0; }
    // Deletes what it holds and takes 'name' instead.
    void reset(GLuint name = 0)
    {
        if (name_ != 0) {
            Traits::destroy(name_);
        }
        name_ = name;
    }
    // Gives up the name without deleting it.
    GLuint release() { return std::exchange(name_, 0u); }

private:
    GLuint name_ = 0;
};

struct GlTextureTraits {
    static GLuint make()
    {
        GLuint n = 0;
        glGenTextures(1, &n);
        return n;
    }
    static void destroy(GLuint n) { glDeleteTextures(1, &n); }
};
struct GlBufferTraits {
    static GLuint make()
    {
        GLuint n = 0;
        glGenBuffers(1, &n);
        return n;
    }
    static void destroy(GLuint n) { glDeleteBuffers(1, &n); }
};
struct GlFramebufferTraits {
    static GLuint make()
    {
        GLuint n = 0;
        glGenFramebuffers(1, &n);
        return n;
    }
    static void destroy(GLuint n) { glDeleteFramebuffers(1, &n); }
};
struct GlVertexArrayTraits {
    static GLuint make()
    {
        GLuint n = 0;
        glGenVertexArrays(1, &n);
        return n;
    }
    static void destroy(GLuint n) { glDeleteVertexArrays(1, &n); }
};
struct GlProgramTraits {
    static GLuint make() { return glCreateProgram(); }
    static void destroy(GLuint n) { glDeleteProgram(n); }
};

using GlTexture = GlHandle<GlTextureTraits>;
using GlBuffer = GlHandle<GlBufferTraits>;
using GlFramebuffer = GlHandle<GlFramebufferTraits>;
using GlVertexArray = GlHandle<GlVertexArrayTraits>;
using GlProgram = GlHandle<GlProgramTraits>;

// A shader object; glCreateShader needs its type, so it has no make().
struct GlShaderTraits {
    static void destroy(GLuint n) { glDeleteShader(n); }
};
using GlShader = GlHandle<GlShaderTraits>;

// A 2-D texture of w x h texels with one level of 'internalFormat', filled from 'data' (rows of
// 'format'/'type', byte-aligned) unless null, sampled nearest and clamped to the edge: exact texel
// values, no dependence on float-filtering extensions. Leaves it bound to GL_TEXTURE_2D on the
// active unit.
GlTexture
texture2d(GLenum internalFormat, GLenum format, GLenum type, int w, int h, const void* data);

} // namespace replica::pipeline::render
