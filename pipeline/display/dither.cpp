// Ordered dither.
#include <algorithm>
#include <cmath>

#include <pipeline/display/dither.h>

namespace replica::pipeline::display {

const std::array<float, kDitherSize * kDitherSize>& ditherPattern()
{
    static const std::array<float, kDitherSize* kDitherSize> pattern = [] {
        std::array<float, kDitherSize * kDitherSize> p{};
        for (int y = 0; y < kDitherSize; ++y) {
            for (int x = 0; x < kDitherSize; ++x) {
                // Bayer index by bit interleaving of x ^ y and y (4 levels of the recursion).
                int v = 0;
                const int xy = x ^ y;
                for (int bit = 0; bit < 4;
                     ++bit) { // low bits of x, y pick the high bits of the index
                    v = (v << 2) | (((xy >> bit) & 1) << 1) | ((y >> bit) & 1);
                }
                p[static_cast<std::size_t>(y * kDitherSize + x)] =
                        (static_cast<float>(v) + 0.5f) / 256.0f;
            }
        }
        return p;
    }();
    return pattern;
}

int quantiseCount(double counts, int x, int y, double maxCount)
{
    if (!std::isfinite(counts)) {
        return 0;
    }
    const auto& p = ditherPattern();
    const int ix = ((x % kDitherSize) + kDitherSize) % kDitherSize;
    const int iy = ((y % kDitherSize) + kDitherSize) % kDitherSize;
    const double t = static_cast<double>(p[static_cast<std::size_t>(iy * kDitherSize + ix)]);
    return static_cast<int>(std::clamp(std::floor(counts + t), 0.0, maxCount));
}

} // namespace replica::pipeline::display
