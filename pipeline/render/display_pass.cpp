// The display pass on GLES 3.1.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>
#include <string>
#include <utility>

#include <fmt/format.h>

#include <pipeline/display/display_inverse.h>
#include <pipeline/display/display_pass_params.h>
#include <pipeline/render/display_pass.h>
#include <pipeline/render/display_shaders.h>
#include <pipeline/render/gl_program.h>

namespace replica::pipeline::render {
namespace {

// Pixels a gamut-count invocation reads along a row (glsl/gamut_count.glsl).
constexpr int kCountRun = 16;

void setInt(GLuint program, const char* name, int v)
{
    glUniform1i(glGetUniformLocation(program, name), v);
}

} // namespace

DisplayPass::~DisplayPass() = default;

Expected<void> DisplayPass::init(const DisplayPassSetup& setup, int width, int height)
{
    setup_ = setup;
    width_ = width;
    height_ = height;
    if (setup.model.bitDepth != 8) {
        return makeError(ErrorCode::Unsupported,
                         fmt::format("display profile '{}' is {}-bit; this build drives 8-bit "
                                     "panels only (an RGBA8 output)",
                                     setup.model.name, setup.model.bitDepth));
    }
    auto inverse = display::DisplayInverse::build(setup.model);
    if (!inverse) {
        return tl::unexpected(inverse.error());
    }
    const display::DisplayPassParams params = display::makeDisplayPassParams(*inverse);
    white_ = setup.model.whiteXyz();
    flarePerLux_ = setup.flareSubtraction ? params.flarePerLux : 0.0f;
    // The viewing gain filtered by the sampler where the GL filters float textures.
    const bool filtered = setup.viewingCompensation && !params.viewingGrid.empty() &&
                          hasExtension("GL_OES_texture_float_linear");
    if (auto ok = compilePrograms(params, filtered); !ok) {
        return ok;
    }
    rgbaTarget_ = texture2d(GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE, width, height, nullptr);
    classTarget_ = texture2d(GL_R8, GL_RED, GL_UNSIGNED_BYTE, width, height, nullptr);
    toneLut_ = texture2d(GL_RG32F, GL_RG, GL_FLOAT, params.lutSize - 1, 3, params.lut.data());
    if (filtered) {
        viewingGrid_ = texture2d(GL_RGBA32F, GL_RGBA, GL_FLOAT, display::kViewingGridNodes, 1,
                                 params.viewingGrid.data());
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    }
    glm::dvec3 latticeScale(0.0);
    const std::vector<float> lattice = uploadLut3d(*inverse, latticeScale);
    findSurround(params, lattice);
    if (auto ok = makeTargets(); !ok) {
        return ok;
    }
    setConstantUniforms(params, latticeScale);
    if (GLenum err = glGetError(); err != GL_NO_ERROR) {
        return makeError(ErrorCode::Unsupported,
                         fmt::format("display pass: GL error 0x{:04x} while setting up", err));
    }
    return {};
}

Expected<void> DisplayPass::compilePrograms(const display::DisplayPassParams& params, bool filtered)
{
    const std::string fragment =
            fmt::format("#version 310 es\n#define DISP_METHOD {}\n#define DISP_GAMUT_MODE {}\n"
                        "#define DISP_VIEWING {}\n#define DISP_FALSE_COLOUR {}\n"
                        "#define DISP_VIEWING_ROWS {}\n#define DISP_VIEWING_FILTERED {}\n"
                        "#define DISP_VIEWING_GRID_PER_DEG {:.17g}\n"
                        "#define DISP_VIEWING_GRID_NODES {}\n",
                        setup_.method == InverseMethod::Lut3d ? 1 : 0,
                        setup_.gamut == display::GamutMode::Clip ? 1 : 0,
                        setup_.viewingCompensation ? 1 : 0, setup_.falseColour ? 1 : 0,
                        params.viewingRows, filtered ? 1 : 0, 1.0 / display::kViewingGridStepDeg,
                        display::kViewingGridNodes) +
            kDisplayFragmentShader;
    auto program = linkProgram(kFullscreenVertexShader, fragment.c_str(), "display");
    if (!program) {
        return tl::unexpected(program.error());
    }
    program_ = std::move(*program);
    const std::string countSource =
            fmt::format("#version 310 es\n#define COUNT_RUN {}\n", kCountRun) + kGamutCountShader;
    auto cs = compileShader(GL_COMPUTE_SHADER, countSource.c_str(), "gamut count");
    if (!cs) {
        return tl::unexpected(cs.error());
    }
    auto count = linkShaders({&*cs}, "gamut count");
    if (!count) {
        return tl::unexpected(count.error());
    }
    countProgram_ = std::move(*count);
    return {};
}

std::vector<float> DisplayPass::uploadLut3d(const display::DisplayInverse& inverse,
                                            glm::dvec3& latticeScale)
{
    // A 3-D texture always exists (a 2^3 dummy on the analytic path) so that the sampler is valid.
    const int n = lut3dSize();
    std::vector<float> lattice(static_cast<std::size_t>(n * n * n) * 4, 0.0f);
    latticeScale = glm::dvec3(0.0);
    if (setup_.method == InverseMethod::Lut3d) {
        const auto lut = display::DisplayLut3d::build(inverse, n);
        for (std::size_t i = 0; i < lut.nodes().size(); ++i) {
            for (int c = 0; c < 3; ++c) {
                lattice[i * 4 + static_cast<std::size_t>(c)] =
                        static_cast<float>(lut.nodes()[i][c]);
            }
        }
        latticeScale = lut.scale();
    }
    lut3d_ = GlTexture::make();
    glBindTexture(GL_TEXTURE_3D, lut3d_.get());
    glTexStorage3D(GL_TEXTURE_3D, 1, GL_RGBA32F, n, n, n);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexSubImage3D(GL_TEXTURE_3D, 0, 0, 0, 0, n, n, n, GL_RGBA, GL_FLOAT, lattice.data());
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    return lattice;
}

int DisplayPass::lut3dSize() const
{
    return setup_.method == InverseMethod::Lut3d ? std::max(setup_.lut3dSize, 2) : 2;
}

void DisplayPass::findSurround(const display::DisplayPassParams& params,
                               const std::vector<float>& lattice)
{
    // The black surround's output, in float as the shader forms it: a pixel below black gets the
    // counts at r = 0 (the tone LUT's first entry; on the 3-D LUT path the lattice's first node),
    // then floor(counts + dither). Constant only if no dither entry moves it.
    surroundConstant_ = params.blackY > 0.0f && !setup_.falseColour &&
                        (setup_.method == InverseMethod::Lut3d ||
                         setup_.gamut == display::GamutMode::HueKeeping) &&
                        params.lutSize >= 2;
    for (int c = 0; c < 3 && surroundConstant_; ++c) {
        const float counts =
                setup_.method == InverseMethod::Lut3d
                        ? lattice[static_cast<std::size_t>(c)]
                        : params.lut[static_cast<std::size_t>(c * 2 * (params.lutSize - 1))] *
                                  params.maxCount;
        const auto quantise = [&](float t) {
            return std::clamp(std::floor(counts + t), 0.0f, params.maxCount);
        };
        const float q = quantise(params.dither[0]);
        for (const float t : params.dither) {
            surroundConstant_ = surroundConstant_ && quantise(t) == q;
        }
        surroundRgba_[static_cast<std::size_t>(c)] = q / params.maxCount;
    }
    surroundRgba_[3] = 1.0f;
}

Expected<void> DisplayPass::makeTargets()
{
    counts_ = GlBuffer::make();
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, counts_.get());
    glBufferData(GL_SHADER_STORAGE_BUFFER, 4 * sizeof(GLuint), nullptr, GL_DYNAMIC_READ);

    fbo_ = GlFramebuffer::make();
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_.get());
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, rgbaTarget_.get(),
                           0);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D, classTarget_.get(),
                           0);
    const std::array<GLenum, 2> buffers{GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    glDrawBuffers(2, buffers.data());
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        return makeError(ErrorCode::Unsupported,
                         "display pass: the RGBA8 + R8 display target is not renderable");
    }
    // The read buffer stays attachment 0: what glReadPixels on this framebuffer returns.
    glReadBuffer(GL_COLOR_ATTACHMENT0);

    return {};
}

void DisplayPass::setConstantUniforms(const display::DisplayPassParams& params,
                                      const glm::dvec3& latticeScale)
{
    glUseProgram(program_.get());
    glUniformMatrix3fv(glGetUniformLocation(program_.get(), "uDispXyzToLinear"), 1, GL_FALSE,
                       params.xyzToLinear.data());
    glUniform3fv(glGetUniformLocation(program_.get(), "uDispBlackXyz"), 1, params.blackXyz.data());
    glUniform1f(glGetUniformLocation(program_.get(), "uDispBlackY"), params.blackY);
    glUniform1f(glGetUniformLocation(program_.get(), "uDispWhiteY"), params.whiteY);
    glUniform1f(glGetUniformLocation(program_.get(), "uDispGamutEdgeTolerance"),
                params.gamutEdgeTolerance);
    glUniform1f(glGetUniformLocation(program_.get(), "uDispGamutEdgeFloor"), params.gamutEdgeFloor);
    glUniformMatrix3fv(glGetUniformLocation(program_.get(), "uDispCrosstalk"), 1, GL_FALSE,
                       params.crosstalk.data());
    glUniform1i(glGetUniformLocation(program_.get(), "uDispCrosstalkSteps"), params.crosstalkSteps);
    glUniform1f(glGetUniformLocation(program_.get(), "uDispMaxCount"), params.maxCount);
    setInt(program_.get(), "uDispLutSize", params.lutSize);
    if (params.viewingRows > 0) {
        glUniform4fv(glGetUniformLocation(program_.get(), "uDispViewing"), params.viewingRows,
                     params.viewing.data());
    }
    setInt(program_.get(), "uDispLut3dSize", lut3dSize());
    setUniform3(program_.get(), "uDispLut3dScale", latticeScale);
    setInt(program_.get(), "uXyz", 0);
    setInt(program_.get(), "uDispToneLut", 1);
    setInt(program_.get(), "uDispLut3d", 2);
    setInt(program_.get(), "uDispViewingGrid", 3);
    glUseProgram(countProgram_.get());
    setInt(countProgram_.get(), "uClass", 0);
    glUseProgram(0);
}

Expected<std::array<GLuint, 4>> DisplayPass::countClasses(const PixelRect& rect) const
{
    // Count the classes on the GPU: 16 bytes come back instead of the class image.
    const std::array<GLuint, 4> zero{};
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, counts_.get());
    glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, sizeof(zero), zero.data());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, counts_.get());
    glUseProgram(countProgram_.get());
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, classTarget_.get());
    glUniform2i(glGetUniformLocation(countProgram_.get(), "uOrigin"), rect.x, rect.y);
    glUniform2i(glGetUniformLocation(countProgram_.get(), "uEnd"), rect.x + rect.width,
                rect.y + rect.height);
    if (rect.width > 0 && rect.height > 0) {
        const int runs = (rect.width + kCountRun - 1) / kCountRun;
        const int rowPairs = (rect.height + 1) / 2;
        glDispatchCompute(static_cast<GLuint>((runs + 7) / 8),
                          static_cast<GLuint>((rowPairs + 7) / 8), 1);
    }
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    const void* mapped =
            glMapBufferRange(GL_SHADER_STORAGE_BUFFER, 0, sizeof(zero), GL_MAP_READ_BIT);
    if (mapped == nullptr) {
        return makeError(ErrorCode::DeviceFailure, "display pass: cannot read the gamut counts");
    }
    std::array<GLuint, 4> c{};
    std::memcpy(c.data(), mapped, sizeof(c));
    glUnmapBuffer(GL_SHADER_STORAGE_BUFFER);
    return c;
}

Expected<display::GamutCounters> DisplayPass::draw(GLuint xyzTexture, const DisplayPassFrame& frame)
{
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_.get());
    glViewport(0, 0, width_, height_);
    glUseProgram(program_.get());
    setUniform3(program_.get(), "uDispEye", frame.eyeM);
    setUniform3(program_.get(), "uDispPanelOrigin", frame.pose.cornerM());
    setUniform3(program_.get(), "uDispPanelRight", frame.pose.rightEdgeM());
    setUniform3(program_.get(), "uDispPanelUp", frame.pose.upEdgeM());
    setUniform3(program_.get(), "uDispPanelNormal", frame.pose.normal);
    setUniform3(program_.get(), "uDispFlarePerLux",
                static_cast<double>(flarePerLux_) * frame.lightXyzUnitY);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, xyzTexture);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, toneLut_.get());
    glActiveTexture(GL_TEXTURE2);
    glBindTexture(GL_TEXTURE_3D, lut3d_.get());
    glActiveTexture(GL_TEXTURE3);
    glBindTexture(GL_TEXTURE_2D, viewingGrid_.get());
    PixelRect shade{0, 0, width_, height_};
    if (frame.blackOutside && surroundConstant_) {
        const PixelRect& inside = *frame.blackOutside;
        shade.x = std::clamp(inside.x, 0, width_);
        shade.y = std::clamp(inside.y, 0, height_);
        shade.width = std::clamp(inside.width, 0, width_ - shade.x);
        shade.height = std::clamp(inside.height, 0, height_ - shade.y);
        // The surround: its constant counts, gamut class 3 (below black).
        const std::array<float, 4> belowBlack{3.0f / 255.0f, 0.0f, 0.0f, 0.0f};
        glClearBufferfv(GL_COLOR, 0, surroundRgba_.data());
        glClearBufferfv(GL_COLOR, 1, belowBlack.data());
        glEnable(GL_SCISSOR_TEST);
        glScissor(shade.x, shade.y, shade.width, shade.height);
    }
    if (shade.width > 0 && shade.height > 0) {
        glDrawArrays(GL_TRIANGLES, 0, 3);
    }
    glDisable(GL_SCISSOR_TEST);

    auto c = countClasses(shade);
    if (!c) {
        return tl::unexpected(c.error());
    }
    display::GamutCounters counters;
    if (frame.blackOutside) {
        // The surface's own counts: the rectangle shaded above when the surround was cleared,
        // else counted again over the rectangle alone.
        const PixelRect& inside = *frame.blackOutside;
        PixelRect surface{std::clamp(inside.x, 0, width_), std::clamp(inside.y, 0, height_), 0, 0};
        surface.width = std::clamp(inside.width, 0, width_ - surface.x);
        surface.height = std::clamp(inside.height, 0, height_ - surface.y);
        auto s = surroundConstant_ ? c : countClasses(surface);
        if (!s) {
            return tl::unexpected(s.error());
        }
        counters.surfacePixels = static_cast<std::uint64_t>(surface.width) *
                                 static_cast<std::uint64_t>(surface.height);
        counters.surfaceChroma = (*s)[1];
        counters.surfaceOverPeak = (*s)[2];
        counters.surfaceBelowBlack = (*s)[3];
    }
    counters.pixels = static_cast<std::uint64_t>(width_) * static_cast<std::uint64_t>(height_);
    counters.chroma = (*c)[1];
    counters.overPeak = (*c)[2];
    // The cleared surround is below black, pixel for pixel.
    counters.belowBlack = (*c)[3] + (static_cast<std::uint64_t>(width_) * height_ -
                                     static_cast<std::uint64_t>(shade.width) * shade.height);
    glUseProgram(0);
    return counters;
}

} // namespace replica::pipeline::render
