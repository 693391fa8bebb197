// One small dense linear solver for the fits (tone curves, the display's crosstalk term, the HDR
// camera response): none needs more than Gaussian elimination, and three copies had grown.
#pragma once

#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

namespace replica::pipeline {

// Solves the n x n system a x = b (a row-major) by Gaussian elimination with partial pivoting;
// b becomes x and a is overwritten. False, with a and b left part-way, when a pivot's magnitude
// is not above minPivot (singular, or near it by the caller's measure of scale).
inline bool
solveLinear(std::vector<double>& a, std::vector<double>& b, std::size_t n, double minPivot = 1e-300)
{
    for (std::size_t c = 0; c < n; ++c) {
        std::size_t piv = c;
        for (std::size_t r = c + 1; r < n; ++r) {
            if (std::abs(a[r * n + c]) > std::abs(a[piv * n + c])) {
                piv = r;
            }
        }
        if (!(std::abs(a[piv * n + c]) > minPivot)) {
            return false;
        }
        if (piv != c) {
            for (std::size_t k = 0; k < n; ++k) {
                std::swap(a[c * n + k], a[piv * n + k]);
            }
            std::swap(b[c], b[piv]);
        }
        const double d = a[c * n + c];
        for (std::size_t r = c + 1; r < n; ++r) {
            const double f = a[r * n + c] / d;
            if (f == 0.0) {
                continue; // the HDR response's system is mostly zeros below the diagonal
            }
            for (std::size_t k = c; k < n; ++k) {
                a[r * n + k] -= f * a[c * n + k];
            }
            b[r] -= f * b[c];
        }
    }
    for (std::size_t i = n; i-- > 0;) {
        double s = b[i];
        for (std::size_t k = i + 1; k < n; ++k) {
            s -= a[i * n + k] * b[k];
        }
        b[i] = s / a[i * n + i];
    }
    return true;
}

} // namespace replica::pipeline
