// Ordered dither.
#include <algorithm>
#include <cmath>

#include <pipeline/display/dither.h>

namespace replica::pipeline::display {

float ditherThreshold(int x, int y)
{
    // Bayer index by bit interleaving of x ^ y and y (4 levels of the recursion): the low bits of
    // x, y pick the high bits of the index. '& 15' is the pixel modulo 16, negatives included.
    const int ym = y & (kDitherSize - 1);
    const int xy = (x & (kDitherSize - 1)) ^ ym;
    int v = 0;
    for (int bit = 0; bit < 4; ++bit) {
        v = (v << 2) | (((xy >> bit) & 1) << 1) | ((ym >> bit) & 1);
    }
    return (static_cast<float>(v) + 0.5f) / 256.0f;
}

const std::array<float, kDitherSize * kDitherSize>& ditherPattern()
{
    static const std::array<float, kDitherSize* kDitherSize> pattern = [] {
        std::array<float, kDitherSize * kDitherSize> p{};
        for (int y = 0; y < kDitherSize; ++y) {
            for (int x = 0; x < kDitherSize; ++x) {
                p[static_cast<std::size_t>(y * kDitherSize + x)] = ditherThreshold(x, y);
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
    const double t = static_cast<double>(ditherThreshold(x, y));
    return static_cast<int>(std::clamp(std::floor(counts + t), 0.0, maxCount));
}

} // namespace replica::pipeline::display
