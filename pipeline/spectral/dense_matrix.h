// A small dense row-major matrix of doubles with the few solvers the spectral fits need (no BLAS).
#pragma once

#include <cstddef>
#include <vector>

#include <pipeline/base/expected.h>

namespace replica::pipeline::spectral {

class DenseMatrix
{
public:
    DenseMatrix() = default;
    DenseMatrix(std::size_t rows, std::size_t cols) : rows_(rows), cols_(cols), v_(rows * cols, 0.0)
    {}
    static DenseMatrix identity(std::size_t n);

    std::size_t rows() const { return rows_; }
    std::size_t cols() const { return cols_; }
    double& operator()(std::size_t r, std::size_t c) { return v_[r * cols_ + c]; }
    double operator()(std::size_t r, std::size_t c) const { return v_[r * cols_ + c]; }

    DenseMatrix transposed() const;

private:
    std::size_t rows_ = 0;
    std::size_t cols_ = 0;
    std::vector<double> v_;
};

DenseMatrix operator*(const DenseMatrix& a, const DenseMatrix& b);
DenseMatrix operator+(const DenseMatrix& a, const DenseMatrix& b);

// Lower-triangular L with a = L L^T, for a symmetric positive-definite a; fails otherwise.
Expected<DenseMatrix> cholesky(const DenseMatrix& a);
// x with a x = b for square a (Gaussian elimination with partial pivoting); fails when a is
// singular to working precision.
Expected<DenseMatrix> solve(const DenseMatrix& a, const DenseMatrix& b);
// Inverse of a lower-triangular matrix with a non-zero diagonal.
DenseMatrix invertLowerTriangular(const DenseMatrix& l);

// Eigen-decomposition of a symmetric matrix by cyclic Jacobi rotations: values in descending order,
// vectors as the matching columns (orthonormal).
struct SymmetricEigen {
    std::vector<double> values;
    DenseMatrix vectors;
};
SymmetricEigen symmetricEigen(const DenseMatrix& a);

} // namespace replica::pipeline::spectral
