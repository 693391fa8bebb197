#include <pipeline/render/gl_handles.h>

namespace replica::pipeline::render {

GlTexture
texture2d(GLenum internalFormat, GLenum format, GLenum type, int w, int h, const void* data)
{
    GlTexture tex = GlTexture::make();
    glBindTexture(GL_TEXTURE_2D, tex.get());
    glTexStorage2D(GL_TEXTURE_2D, 1, internalFormat, w, h);
    if (data != nullptr) {
        glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
        glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, w, h, format, type, data);
    }
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    return tex;
}

} // namespace replica::pipeline::render
