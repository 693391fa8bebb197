// Normal and horizon maps from a height field.
#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/gtc/packing.hpp>

#include <pipeline/base/bilinear.h>
#include <pipeline/base/parallel_for.h>
#include <pipeline/surface/relief.h>

namespace replica::pipeline::surface {

double HeightField::at(int x, int y) const
{
    x = std::clamp(x, 0, width - 1);
    y = std::clamp(y, 0, height - 1);
    return m[static_cast<std::size_t>(y) * width + x];
}

double HeightField::sample(double x, double y) const
{
    return bilinearAtTexel(x, y, [this](int ix, int iy) { return at(ix, iy); });
}

bool HeightField::flat() const
{
    for (double v : m) {
        if (v != m.front()) {
            return false;
        }
    }
    return true;
}

std::vector<Vec3> normalMap(const HeightField& h)
{
    std::vector<Vec3> n(static_cast<std::size_t>(h.width) * static_cast<std::size_t>(h.height));
    for (int y = 0; y < h.height; ++y) {
        for (int x = 0; x < h.width; ++x) {
            const int xl = std::max(x - 1, 0);
            const int xr = std::min(x + 1, h.width - 1);
            const int yu = std::max(y - 1, 0);
            const int yd = std::min(y + 1, h.height - 1);
            const double dx = xr > xl ? (h.at(xr, y) - h.at(xl, y)) / ((xr - xl) * h.pitchM) : 0.0;
            // Image rows run down, tangent +y runs up.
            const double dy = yd > yu ? -(h.at(x, yd) - h.at(x, yu)) / ((yd - yu) * h.pitchM) : 0.0;
            const Vec3 v(-dx, -dy, 1.0); // length >= 1: never zero
            n[static_cast<std::size_t>(y) * h.width + x] =
                    v / std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
        }
    }
    return n;
}

double largestNormalTurn(const HeightField& h)
{
    const std::vector<Vec3> n = normalMap(h);
    const auto at = [&](int x, int y) {
        return n[static_cast<std::size_t>(y) * static_cast<std::size_t>(h.width) +
                 static_cast<std::size_t>(x)];
    };
    // atan2(|a x b|, a.b), not acos(a.b): exact for the small angles a smooth surface turns by,
    // where acos loses half its digits.
    const auto angle = [](const Vec3& a, const Vec3& b) {
        const Vec3 c(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
        return std::atan2(std::sqrt(c.x * c.x + c.y * c.y + c.z * c.z),
                          a.x * b.x + a.y * b.y + a.z * b.z);
    };
    double largest = 0.0;
    for (int y = 0; y < h.height; ++y) {
        for (int x = 0; x < h.width; ++x) {
            if (x + 1 < h.width) {
                largest = std::max(largest, angle(at(x, y), at(x + 1, y)));
            }
            if (y + 1 < h.height) {
                largest = std::max(largest, angle(at(x, y), at(x, y + 1)));
            }
        }
    }
    return largest;
}

double exactSinHorizon(const HeightField& h, double x, double y, double phi, double maxDistanceM)
{
    const double h0 = h.sample(x, y);
    const double cx = std::cos(phi);
    const double cy = std::sin(phi);
    double best = 0.0; // tan of the elevation, floored at the macro plane
    const double step = 0.5;
    const int steps = static_cast<int>(std::ceil(maxDistanceM / (step * h.pitchM)));
    for (int s = 1; s <= steps; ++s) {
        const double t = s * step;
        const double px = x + cx * t;
        const double py = y - cy * t; // +y in tangent space is up the image
        if (px < 0.0 || py < 0.0 || px > h.width || py > h.height) {
            break;
        }
        best = std::max(best, (h.sample(px, py) - h0) / (t * h.pitchM));
    }
    return best / std::sqrt(1.0 + best * best); // sin(atan(best)), finite for cliffs
}

HorizonMap horizonMap(const HeightField& h, int directions, double maxDistanceM)
{
    HorizonMap map;
    map.width = h.width;
    map.height = h.height;
    map.directions = std::max(directions, 1);
    map.sinBeta.assign(static_cast<std::size_t>(h.width) * static_cast<std::size_t>(h.height) *
                               static_cast<std::size_t>(map.directions),
                       0.0f);
    if (h.flat()) {
        return map; // every horizon is the macro plane: identical result, no marching
    }
    // Rows on every core: each texel's march reads only the height field and writes only its own
    // slots, so the map is the same, bit for bit, on any number of threads. It is on the way to
    // the first frame (the painting's 384 x 288 x 8 marches: about 0.7 s on one core here).
    parallelFor(static_cast<std::size_t>(h.height), [&](std::size_t row) {
        const int y = static_cast<int>(row);
        for (int x = 0; x < h.width; ++x) {
            for (int k = 0; k < map.directions; ++k) {
                const double phi = 2.0 * std::numbers::pi * k / map.directions;
                map.sinBeta[(static_cast<std::size_t>(y) * h.width + x) * map.directions + k] =
                        static_cast<float>(exactSinHorizon(h, x + 0.5, y + 0.5, phi, maxDistanceM));
            }
        }
    });
    return map;
}

HorizonMap halfPrecision(const HorizonMap& map)
{
    HorizonMap half = map;
    for (float& s : half.sinBeta) {
        s = glm::unpackHalf1x16(glm::packHalf1x16(s));
    }
    return half;
}

double HorizonMap::sinHorizon(int x, int y, const Vec3& l) const
{
    if (directions <= 0 || width <= 0) {
        return 0.0;
    }
    x = std::clamp(x, 0, width - 1);
    y = std::clamp(y, 0, height - 1);
    return atAzimuth(&sinBeta[(static_cast<std::size_t>(y) * width + x) * directions], directions,
                     l.x, l.y);
}

double HorizonMap::sinHorizonBilinear(double x, double y, const Vec3& l) const
{
    // sinHorizon clamps each texel to the map.
    return bilinearAtTexel(x, y, [&](int ix, int iy) { return sinHorizon(ix, iy, l); });
}

} // namespace replica::pipeline::surface
