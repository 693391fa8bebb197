// Luminance image checks and the zero-padded, area-averaged mip chain.
#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include <pipeline/base/bilinear.h>
#include <pipeline/booth/luminance_image.h>

namespace replica::pipeline::booth {

LuminanceImage LuminanceImage::filled(int w, int h, double value)
{
    LuminanceImage img;
    img.width = w;
    img.height = h;
    img.cdM2.assign(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), value);
    return img;
}

double LuminanceImage::sum() const
{
    double s = 0.0;
    for (double v : cdM2) {
        s += v;
    }
    return s;
}

double LuminanceImage::max() const
{
    double m = 0.0;
    for (double v : cdM2) {
        m = std::max(m, v);
    }
    return m;
}

Expected<void> checkLuminance(const LuminanceImage& img, const std::string& what)
{
    if (img.width <= 0 || img.height <= 0 ||
        img.cdM2.size() !=
                static_cast<std::size_t>(img.width) * static_cast<std::size_t>(img.height)) {
        return makeError(ErrorCode::InvalidArgument,
                         fmt::format("{}: luminance image has no texels or a wrong size", what));
    }
    for (std::size_t k = 0; k < img.cdM2.size(); ++k) {
        const double v = img.cdM2[k];
        if (!std::isfinite(v) || v < 0.0) {
            return makeError(ErrorCode::Corrupt,
                             fmt::format("{}: texel ({}, {}) has luminance {} cd/m^2; it must be "
                                         "finite and >= 0 "
                                         "(re-merge the capture without saturated frames)",
                                         what, k % static_cast<std::size_t>(img.width),
                                         k / static_cast<std::size_t>(img.width), v));
        }
        if (v > kMaxLuminanceCdM2) {
            // A float's 3e38 passed, and the auto dimmer then drew the lamp black (gain 4e-36).
            return makeError(ErrorCode::Corrupt,
                             fmt::format("{}: texel ({}, {}) has luminance {:g} cd/m^2, brighter "
                                         "than the sun's disc ({:g}); is the map in cd/m^2 (not "
                                         "raw counts or another unit)?",
                                         what, k % static_cast<std::size_t>(img.width),
                                         k / static_cast<std::size_t>(img.width), v,
                                         kMaxLuminanceCdM2));
        }
    }
    return {};
}

namespace {

int nextPow2(int v)
{
    int p = 1;
    while (p < v) {
        p *= 2;
    }
    return p;
}

double bilinear(const LuminanceImage& img, double u, double v)
{
    // Texel centres at (x + 0.5) / w; outside the texture the border value 0 is used.
    return bilinearAtTexel(u * img.width, v * img.height, [&](int x, int y) {
        if (x < 0 || y < 0 || x >= img.width || y >= img.height) {
            return 0.0;
        }
        return img.at(x, y);
    });
}

} // namespace

MipChain buildMipChain(const LuminanceImage& img)
{
    MipChain chain;
    const int pw = nextPow2(std::max(img.width, 1));
    const int ph = nextPow2(std::max(img.height, 1));
    chain.usedU = static_cast<double>(img.width) / pw;
    chain.usedV = static_cast<double>(img.height) / ph;
    LuminanceImage base = LuminanceImage::filled(pw, ph, 0.0);
    for (int y = 0; y < img.height; ++y) {
        for (int x = 0; x < img.width; ++x) {
            base.at(x, y) = img.at(x, y);
        }
    }
    chain.levels.push_back(std::move(base));
    while (chain.levels.back().width > 1 || chain.levels.back().height > 1) {
        const LuminanceImage& f = chain.levels.back();
        const int w = std::max(f.width / 2, 1);
        const int h = std::max(f.height / 2, 1);
        LuminanceImage c = LuminanceImage::filled(w, h, 0.0);
        const int sx = f.width / w; // 1 or 2
        const int sy = f.height / h;
        for (int y = 0; y < h; ++y) {
            for (int x = 0; x < w; ++x) {
                double s = 0.0;
                for (int j = 0; j < sy; ++j) {
                    for (int i = 0; i < sx; ++i) {
                        s += f.at(x * sx + i, y * sy + j);
                    }
                }
                c.at(x, y) = s / (sx * sy);
            }
        }
        chain.levels.push_back(std::move(c));
    }
    return chain;
}

double MipChain::sample(double u, double v, double level) const
{
    if (!(u >= 0.0 && u <= 1.0 && v >= 0.0 && v <= 1.0)) {
        return 0.0; // ray misses the emitter (also catches NaN)
    }
    const double tu = u * usedU;
    const double tv = v * usedV;
    const double l =
            std::clamp(std::isfinite(level) ? level : 0.0, 0.0, static_cast<double>(maxLevel()));
    const int l0 = static_cast<int>(std::floor(l));
    const int l1 = std::min(l0 + 1, maxLevel());
    const double t = l - l0;
    const double a = bilinear(levels[static_cast<std::size_t>(l0)], tu, tv);
    if (t <= 0.0 || l1 == l0) {
        return a;
    }
    return (1.0 - t) * a + t * bilinear(levels[static_cast<std::size_t>(l1)], tu, tv);
}

double MipChain::sampleNearestLevel(double u, double v, double level) const
{
    if (!(u >= 0.0 && u <= 1.0 && v >= 0.0 && v <= 1.0)) {
        return 0.0;
    }
    const double l =
            std::clamp(std::isfinite(level) ? level : 0.0, 0.0, static_cast<double>(maxLevel()));
    const int d = l <= 0.5 ? 0 : std::min(static_cast<int>(std::ceil(l + 0.5)) - 1, maxLevel());
    return bilinear(levels[static_cast<std::size_t>(d)], u * usedU, v * usedV);
}

} // namespace replica::pipeline::booth
