// Debevec & Malik response recovery and merge; four-point homography; ceiling resampling.
#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include <pipeline/base/linear_solve.h>
#include <pipeline/offline/booth/hdr_capture.h>

namespace replica::pipeline::booth {
namespace {

double hatWeight(int z)
{
    return z <= 127 ? static_cast<double>(z) : static_cast<double>(255 - z);
}

Expected<void> checkSeries(const std::vector<Exposure>& series)
{
    if (series.size() < 2) {
        return makeError(ErrorCode::InvalidArgument, "an HDR merge needs at least 2 exposures");
    }
    for (std::size_t j = 0; j < series.size(); ++j) {
        const Exposure& e = series[j];
        if (e.width != series[0].width || e.height != series[0].height || e.width <= 0 ||
            e.height <= 0 ||
            e.z.size() != static_cast<std::size_t>(e.width) * static_cast<std::size_t>(e.height)) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("exposure {} has a different size from exposure 0", j));
        }
        if (!(e.seconds > 0.0) || !std::isfinite(e.seconds)) {
            return makeError(ErrorCode::InvalidArgument,
                             fmt::format("exposure {}: time must be > 0 seconds", j));
        }
    }
    return {};
}

} // namespace

Expected<ResponseCurve>
recoverResponse(const std::vector<Exposure>& series, int samplePixels, double lambda)
{
    if (auto ok = checkSeries(series); !ok) {
        return tl::unexpected(ok.error());
    }
    const int w = series[0].width;
    const int h = series[0].height;
    // Sample pixels on a grid, keeping those whose values span the range (not all clipped).
    std::vector<std::size_t> picks;
    const int side =
            std::max(1, static_cast<int>(std::ceil(std::sqrt(static_cast<double>(samplePixels)))));
    for (int gy = 0; gy < side; ++gy) {
        for (int gx = 0; gx < side; ++gx) {
            const int x = (2 * gx + 1) * w / (2 * side);
            const int y = (2 * gy + 1) * h / (2 * side);
            picks.push_back(static_cast<std::size_t>(y) * w + x);
        }
    }
    const int n = 256 + static_cast<int>(picks.size());
    std::vector<double> ata(static_cast<std::size_t>(n) * n, 0.0);
    std::vector<double> atb(static_cast<std::size_t>(n), 0.0);
    // Accumulate one equation sum_k c_k x_k = rhs into the normal equations.
    const auto addRow = [&](const std::vector<std::pair<int, double>>& row, double rhs) {
        for (const auto& [i, ci] : row) {
            for (const auto& [k, ck] : row) {
                ata[static_cast<std::size_t>(i) * n + k] += ci * ck;
            }
            atb[static_cast<std::size_t>(i)] += ci * rhs;
        }
    };
    for (std::size_t i = 0; i < picks.size(); ++i) {
        for (const Exposure& e : series) {
            const int z = e.z[picks[i]];
            const double wz =
                    hatWeight(z) + 1e-3; // a tiny floor keeps clipped samples from being unknowns
            addRow({{z, wz}, {256 + static_cast<int>(i), -wz}}, wz * std::log(e.seconds));
        }
    }
    addRow({{128, 1.0}}, 0.0);
    for (int z = 1; z < 255; ++z) {
        const double s = lambda * hatWeight(z);
        addRow({{z - 1, s}, {z, -2.0 * s}, {z + 1, s}}, 0.0);
    }
    if (!solveLinear(ata, atb, static_cast<std::size_t>(n))) {
        return makeError(ErrorCode::InvalidArgument,
                         "camera response: the exposure series does not determine it "
                         "(use exposures that overlap in range)");
    }
    ResponseCurve c;
    for (int z = 0; z < 256; ++z) {
        c.g[static_cast<std::size_t>(z)] = atb[static_cast<std::size_t>(z)];
    }
    return c;
}

Expected<LuminanceImage> mergeHdr(const std::vector<Exposure>& series, const ResponseCurve& curve)
{
    if (auto ok = checkSeries(series); !ok) {
        return tl::unexpected(ok.error());
    }
    LuminanceImage out = LuminanceImage::filled(series[0].width, series[0].height, 0.0);
    for (std::size_t p = 0; p < out.cdM2.size(); ++p) {
        double num = 0.0, den = 0.0;
        bool saturated = true;
        for (const Exposure& e : series) {
            const int z = e.z[p];
            saturated = saturated && z == 255;
            const double wz = hatWeight(z);
            num += wz * (curve.g[static_cast<std::size_t>(z)] - std::log(e.seconds));
            den += wz;
        }
        if (saturated) {
            return makeError(
                    ErrorCode::Corrupt,
                    fmt::format(
                            "pixel ({}, {}) is saturated in every exposure; add a shorter exposure",
                            p % static_cast<std::size_t>(out.width),
                            p / static_cast<std::size_t>(out.width)));
        }
        out.cdM2[p] = den > 0.0 ? std::exp(num / den) : 0.0; // black in every exposure: no light
    }
    return out;
}

glm::dvec2 Homography::apply(double u, double v) const
{
    const double x = h[0] * u + h[1] * v + h[2];
    const double y = h[3] * u + h[4] * v + h[5];
    const double w = h[6] * u + h[7] * v + h[8];
    if (!(std::abs(w) > 1e-15)) {
        return {std::nan(""), std::nan("")};
    }
    return {x / w, y / w};
}

Expected<Homography> homographyFromCorners(const std::array<glm::dvec2, 4>& corners)
{
    const double uv[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    std::vector<double> a(64, 0.0), b(8, 0.0);
    for (int k = 0; k < 4; ++k) {
        const double u = uv[k][0], v = uv[k][1];
        const double x = corners[static_cast<std::size_t>(k)].x,
                     y = corners[static_cast<std::size_t>(k)].y;
        const double r1[8] = {u, v, 1, 0, 0, 0, -u * x, -v * x};
        const double r2[8] = {0, 0, 0, u, v, 1, -u * y, -v * y};
        for (int c = 0; c < 8; ++c) {
            a[static_cast<std::size_t>(2 * k) * 8 + c] = r1[c];
            a[static_cast<std::size_t>(2 * k + 1) * 8 + c] = r2[c];
        }
        b[static_cast<std::size_t>(2 * k)] = x;
        b[static_cast<std::size_t>(2 * k + 1)] = y;
    }
    if (!solveLinear(a, b, 8)) {
        return makeError(ErrorCode::InvalidArgument,
                         "the four ceiling corners are degenerate (three on a line?)");
    }
    Homography hm;
    for (int k = 0; k < 8; ++k) {
        hm.h[static_cast<std::size_t>(k)] = b[static_cast<std::size_t>(k)];
    }
    hm.h[8] = 1.0;
    return hm;
}

Expected<LuminanceImage>
warpToCeiling(const LuminanceImage& hdr, const Homography& hm, int texelsX, int texelsY)
{
    for (const auto& c : {hm.apply(0, 0), hm.apply(1, 0), hm.apply(1, 1), hm.apply(0, 1)}) {
        if (!(c.x >= 0.0 && c.y >= 0.0 && c.x <= hdr.width && c.y <= hdr.height)) {
            return makeError(
                    ErrorCode::InvalidArgument,
                    fmt::format(
                            "ceiling corner maps to ({:.1f}, {:.1f}), outside the {}x{} capture",
                            c.x, c.y, hdr.width, hdr.height));
        }
    }
    const auto bilinear = [&](double x, double y) {
        const double fx = std::clamp(x - 0.5, 0.0, hdr.width - 1.0);
        const double fy = std::clamp(y - 0.5, 0.0, hdr.height - 1.0);
        const int x0 = std::min(static_cast<int>(fx), hdr.width - 1),
                  y0 = std::min(static_cast<int>(fy), hdr.height - 1);
        const int x1 = std::min(x0 + 1, hdr.width - 1), y1 = std::min(y0 + 1, hdr.height - 1);
        const double ax = fx - x0, ay = fy - y0;
        return (1 - ay) * ((1 - ax) * hdr.at(x0, y0) + ax * hdr.at(x1, y0)) +
               ay * ((1 - ax) * hdr.at(x0, y1) + ax * hdr.at(x1, y1));
    };
    LuminanceImage out = LuminanceImage::filled(texelsX, texelsY, 0.0);
    for (int ty = 0; ty < texelsY; ++ty) {
        for (int tx = 0; tx < texelsX; ++tx) {
            double s = 0.0;
            for (int j = 0; j < 2; ++j) {
                for (int i = 0; i < 2; ++i) {
                    const auto p = hm.apply((tx + 0.25 + 0.5 * i) / texelsX,
                                            (ty + 0.25 + 0.5 * j) / texelsY);
                    s += bilinear(p.x, p.y);
                }
            }
            out.at(tx, ty) = 0.25 * s;
        }
    }
    return out;
}

} // namespace replica::pipeline::booth
