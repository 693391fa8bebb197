// 3x3 row-major matrices acting on XYZ-like triples (CAT02, RGB primaries).
#pragma once

#include <array>

#include <pipeline/colour/xyz.h>

namespace replica::pipeline::colour {

using Matrix3 = std::array<std::array<double, 3>, 3>; // out[i] = sum_j m[i][j] in[j]

Xyz applyMatrix(const Matrix3& m, const Xyz& v);
Matrix3 multiply(const Matrix3& a, const Matrix3& b);
// Inverse by the adjugate; the caller guarantees a non-singular matrix (a fixed colour matrix).
Matrix3 inverse(const Matrix3& m);

} // namespace replica::pipeline::colour
