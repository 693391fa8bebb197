// Dense matrix arithmetic, Cholesky, LU solve and Jacobi eigen-decomposition.
#include <algorithm>
#include <cmath>
#include <numeric>

#include <fmt/format.h>

#include <pipeline/base/assert.h>
#include <pipeline/spectral/dense_matrix.h>

namespace replica::pipeline::spectral {

DenseMatrix DenseMatrix::identity(std::size_t n)
{
    DenseMatrix m(n, n);
    for (std::size_t i = 0; i < n; ++i) {
        m(i, i) = 1.0;
    }
    return m;
}

DenseMatrix DenseMatrix::transposed() const
{
    DenseMatrix t(cols_, rows_);
    for (std::size_t r = 0; r < rows_; ++r) {
        for (std::size_t c = 0; c < cols_; ++c) {
            t(c, r) = (*this)(r, c);
        }
    }
    return t;
}

DenseMatrix operator*(const DenseMatrix& a, const DenseMatrix& b)
{
    REPLICA_ASSERT(a.cols() == b.rows(), "matrix product needs matching inner dimensions");
    DenseMatrix r(a.rows(), b.cols());
    for (std::size_t i = 0; i < a.rows(); ++i) {
        for (std::size_t k = 0; k < a.cols(); ++k) {
            const double aik = a(i, k);
            if (aik == 0.0) {
                continue;
            }
            for (std::size_t j = 0; j < b.cols(); ++j) {
                r(i, j) += aik * b(k, j);
            }
        }
    }
    return r;
}

DenseMatrix operator+(const DenseMatrix& a, const DenseMatrix& b)
{
    REPLICA_ASSERT(a.rows() == b.rows() && a.cols() == b.cols(), "matrix sum needs equal shapes");
    DenseMatrix r(a.rows(), a.cols());
    for (std::size_t i = 0; i < a.rows(); ++i) {
        for (std::size_t j = 0; j < a.cols(); ++j) {
            r(i, j) = a(i, j) + b(i, j);
        }
    }
    return r;
}

Expected<DenseMatrix> cholesky(const DenseMatrix& a)
{
    const std::size_t n = a.rows();
    DenseMatrix l(n, n);
    for (std::size_t j = 0; j < n; ++j) {
        double d = a(j, j);
        for (std::size_t k = 0; k < j; ++k) {
            d -= l(j, k) * l(j, k);
        }
        if (!(d > 0.0)) {
            return makeError(
                    ErrorCode::InvalidArgument,
                    fmt::format("cholesky: matrix is not positive definite (pivot {} is {})", j,
                                d));
        }
        l(j, j) = std::sqrt(d);
        for (std::size_t i = j + 1; i < n; ++i) {
            double s = a(i, j);
            for (std::size_t k = 0; k < j; ++k) {
                s -= l(i, k) * l(j, k);
            }
            l(i, j) = s / l(j, j);
        }
    }
    return l;
}

Expected<DenseMatrix> solve(const DenseMatrix& a, const DenseMatrix& b)
{
    REPLICA_ASSERT(a.rows() == a.cols() && a.rows() == b.rows(),
                   "solve needs square a and matching b");
    const std::size_t n = a.rows();
    DenseMatrix m = a;
    DenseMatrix x = b;
    double scale = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t j = 0; j < n; ++j) {
            scale = std::max(scale, std::abs(a(i, j)));
        }
    }
    for (std::size_t col = 0; col < n; ++col) {
        std::size_t pivot = col;
        for (std::size_t r = col + 1; r < n; ++r) {
            if (std::abs(m(r, col)) > std::abs(m(pivot, col))) {
                pivot = r;
            }
        }
        if (!(std::abs(m(pivot, col)) > 1e-13 * scale)) {
            return makeError(
                    ErrorCode::InvalidArgument,
                    fmt::format("solve: matrix is singular to working precision at column {}",
                                col));
        }
        if (pivot != col) {
            for (std::size_t j = 0; j < n; ++j) {
                std::swap(m(col, j), m(pivot, j));
            }
            for (std::size_t j = 0; j < x.cols(); ++j) {
                std::swap(x(col, j), x(pivot, j));
            }
        }
        for (std::size_t r = col + 1; r < n; ++r) {
            const double f = m(r, col) / m(col, col);
            if (f == 0.0) {
                continue;
            }
            for (std::size_t j = col; j < n; ++j) {
                m(r, j) -= f * m(col, j);
            }
            for (std::size_t j = 0; j < x.cols(); ++j) {
                x(r, j) -= f * x(col, j);
            }
        }
    }
    for (std::size_t i = n; i-- > 0;) {
        for (std::size_t j = 0; j < x.cols(); ++j) {
            double s = x(i, j);
            for (std::size_t k = i + 1; k < n; ++k) {
                s -= m(i, k) * x(k, j);
            }
            x(i, j) = s / m(i, i);
        }
    }
    return x;
}

DenseMatrix invertLowerTriangular(const DenseMatrix& l)
{
    const std::size_t n = l.rows();
    DenseMatrix inv(n, n);
    for (std::size_t j = 0; j < n; ++j) {
        inv(j, j) = 1.0 / l(j, j);
        for (std::size_t i = j + 1; i < n; ++i) {
            double s = 0.0;
            for (std::size_t k = j; k < i; ++k) {
                s -= l(i, k) * inv(k, j);
            }
            inv(i, j) = s / l(i, i);
        }
    }
    return inv;
}

SymmetricEigen symmetricEigen(const DenseMatrix& input)
{
    const std::size_t n = input.rows();
    DenseMatrix a = input;
    DenseMatrix v = DenseMatrix::identity(n);
    for (int sweep = 0; sweep < 100; ++sweep) {
        double off = 0.0;
        double diag = 0.0;
        for (std::size_t i = 0; i < n; ++i) {
            diag += a(i, i) * a(i, i);
            for (std::size_t j = i + 1; j < n; ++j) {
                off += a(i, j) * a(i, j);
            }
        }
        if (!(off > 1e-30 * diag)) {
            break;
        }
        for (std::size_t p = 0; p < n; ++p) {
            for (std::size_t q = p + 1; q < n; ++q) {
                const double apq = a(p, q);
                if (apq == 0.0) {
                    continue;
                }
                // Rotation angle that zeroes a(p, q) (Golub & Van Loan, algorithm 8.4.1).
                const double tau = (a(q, q) - a(p, p)) / (2.0 * apq);
                const double t =
                        (tau >= 0.0 ? 1.0 : -1.0) / (std::abs(tau) + std::sqrt(1.0 + tau * tau));
                const double c = 1.0 / std::sqrt(1.0 + t * t);
                const double s = t * c;
                for (std::size_t k = 0; k < n; ++k) {
                    const double akp = a(k, p);
                    const double akq = a(k, q);
                    a(k, p) = c * akp - s * akq;
                    a(k, q) = s * akp + c * akq;
                }
                for (std::size_t k = 0; k < n; ++k) {
                    const double apk = a(p, k);
                    const double aqk = a(q, k);
                    a(p, k) = c * apk - s * aqk;
                    a(q, k) = s * apk + c * aqk;
                }
                for (std::size_t k = 0; k < n; ++k) {
                    const double vkp = v(k, p);
                    const double vkq = v(k, q);
                    v(k, p) = c * vkp - s * vkq;
                    v(k, q) = s * vkp + c * vkq;
                }
            }
        }
    }
    std::vector<std::size_t> order(n);
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(),
              [&a](std::size_t i, std::size_t j) { return a(i, i) > a(j, j); });
    SymmetricEigen out;
    out.vectors = DenseMatrix(n, n);
    for (std::size_t c = 0; c < n; ++c) {
        out.values.push_back(a(order[c], order[c]));
        for (std::size_t r = 0; r < n; ++r) {
            out.vectors(r, c) = v(r, order[c]);
        }
    }
    return out;
}

} // namespace replica::pipeline::spectral
