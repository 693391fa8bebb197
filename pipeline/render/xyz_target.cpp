// The RGBA32F target the tests, the benchmark and 'replica render' draw the booth pass into.
#include <cmath>
#include <vector>

#include <pipeline/render/booth_shading_pass.h>
#include <pipeline/render/booth_upload.h>
#include <pipeline/render/xyz_target.h>
#include <pipeline/shading/wall_field.h>

namespace replica::pipeline::render {

using booth_upload::glCheck;

Expected<std::unique_ptr<XyzTarget>> XyzTarget::create(int width, int height)
{
    if (width <= 0 || height <= 0) {
        return makeError(ErrorCode::InvalidArgument, "render: empty XYZ target");
    }
    std::unique_ptr<XyzTarget> t(new XyzTarget());
    t->width_ = width;
    t->height_ = height;
    t->texture_ = texture2d(GL_RGBA32F, GL_RGBA, GL_FLOAT, width, height, nullptr);
    t->fbo_ = GlFramebuffer::make();
    glBindFramebuffer(GL_FRAMEBUFFER, t->fbo_.get());
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, t->texture_.get(),
                           0);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        return makeError(ErrorCode::Unsupported,
                         "render: an RGBA32F target is not renderable on this GL (float colour "
                         "buffers need GLES 3.2 or EXT_color_buffer_float)");
    }
    if (auto ok = glCheck("creating the XYZ target"); !ok) {
        return tl::unexpected(ok.error());
    }
    return t;
}

XyzTarget::~XyzTarget() = default;

void XyzTarget::bind() const
{
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_.get());
}

shading::XyzFrame XyzTarget::read(const shading::PreparedLight& light,
                                  const shading::View& view,
                                  double flareRho) const
{
    shading::XyzFrame f;
    f.width = width_;
    f.height = height_;
    std::vector<float> px(static_cast<std::size_t>(width_) * height_ * 4);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_.get());
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, width_, height_, GL_RGBA, GL_FLOAT, px.data());
    f.xyz.resize(static_cast<std::size_t>(width_) * height_);
    for (int y = 0; y < height_; ++y) {
        const std::size_t src = static_cast<std::size_t>(height_ - 1 - y) * width_; // GL rows up
        for (int x = 0; x < width_; ++x) {
            const float* p = &px[(src + x) * 4];
            colour::Xyz v(p[0], p[1], p[2]);
            const double flare = flareRho * static_cast<double>(p[3]) / std::numbers::pi;
            for (int c = 0; c < 3; ++c) {
                if (!std::isfinite(v[c])) {
                    ++f.nonFinite;
                    v[c] = 0.0;
                }
                if (flareRho > 0.0 && v[c] == 0.0 && light.white[c] * flare > 0.0) {
                    ++f.flareClamped;
                }
            }
            f.xyz[static_cast<std::size_t>(y) * width_ + x] = v;
        }
    }
    if (light.light != nullptr) {
        f.whiteY = shading::panelWhiteY(light, view.panel, false);
        f.whiteXyz = light.white * f.whiteY;
    }
    return f;
}

Expected<shading::XyzFrame> renderBoothFrame(BoothShadingPass& pass,
                                             const shading::PreparedLight& light,
                                             const shading::View& view)
{
    auto target = XyzTarget::create(view.pixelsX, view.pixelsY);
    if (!target) {
        return tl::unexpected(target.error());
    }
    (*target)->bind();
    if (auto ok = pass.draw(view, view.pixelsX, view.pixelsY); !ok) {
        return tl::unexpected(ok.error());
    }
    const shading::RenderSettings& s = pass.settings();
    shading::XyzFrame f =
            (*target)->read(light, view, s.subtractFlare ? shading::kScreenFlareRho : 0.0);
    if (light.light != nullptr) {
        f.whiteY = shading::panelWhiteY(light, view.panel, s.areaLights) +
                   shading::wallsWhiteY(light.walls, view.panel, s.walls);
        f.whiteXyz = light.white * f.whiteY;
    }
    // The eye's side of the surface, pixel by pixel as the CPU model tests it.
    const std::vector<shading::Vec3> flat;
    for (int py = 0; py < view.pixelsY; ++py) {
        for (int px = 0; px < view.pixelsX; ++px) {
            const shading::ShadingPoint sp =
                    shading::shadingPoint(view, *pass.scene().scene, flat, px, py);
            f.eyeBehindPixels += shading::eyeBehind(view, sp) ? 1 : 0;
        }
    }
    return f;
}

} // namespace replica::pipeline::render
