// The fixed ordered-dither pattern used when quantising real-valued counts: deterministic (the same
// frame quantises to the same counts on every run, which replay needs) and with no low-frequency
// structure, so an 8-bit gradient shows no bands.
#pragma once

#include <array>

namespace replica::pipeline::display {

constexpr int kDitherSize = 16;

// The threshold at pixel (x, y) (any integers; the pattern repeats every kDitherSize): (Bayer
// index + 0.5) / 256 of a 16x16 Bayer matrix, its index by bit interleaving of x ^ y and y.
float ditherThreshold(int x, int y);

// Thresholds in (0, 1): ditherThreshold over one period, row-major.
const std::array<float, kDitherSize * kDitherSize>& ditherPattern();

// floor(counts + ditherThreshold(x, y)) clamped to [0, maxCount]. Non-finite counts give 0.
int quantiseCount(double counts, int x, int y, double maxCount);

} // namespace replica::pipeline::display
