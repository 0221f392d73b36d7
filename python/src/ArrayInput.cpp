/* Part of the multibin elevation-mapping library: the Python module. */
#include "ArrayInput.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace py = pybind11;

namespace multibin::python {

namespace {
std::string shapeText(const py::array& a) {
    std::string s = "(";
    for (py::ssize_t d = 0; d < a.ndim(); d++)
        s += (d ? ", " : "") + std::to_string(a.shape(d)) + (a.ndim() == 1 ? "," : "");
    return s + ")";
}

/** Throws unless `a` has `want` dimensions of the given sizes (-1: any). */
void requireShape(const py::array& a, std::initializer_list<py::ssize_t> want,
                  const std::string& where, const std::string& wantText) {
    bool ok = a.ndim() == py::ssize_t(want.size());
    py::ssize_t d = 0;
    for (py::ssize_t w : want) {
        ok = ok && (w < 0 || a.shape(d) == w);
        d++;
    }
    if (!ok)
        throw std::invalid_argument(where + " must have shape " + wantText + ", has shape " +
                                    shapeText(a));
}

/** Symmetric to rounding (a covariance written out by hand or by a float32 computation). */
bool nearlyEqual(double a, double b, double scale) {
    return std::abs(a - b) <= 1e-6 * scale + 1e-300;
}

/** Throws unless the n x n row-major matrix `m` is finite, symmetric and positive
 * semi-definite (eigenvalues >= -1e-9 of the largest, as rounding leaves an exact pose). */
template <int N>
Eigen::Matrix<double, N, N> checkedCovariance(const double* m, const std::string& what) {
    Eigen::Matrix<double, N, N> c;
    double scale = 0;
    for (int r = 0; r < N; r++)
        for (int k = 0; k < N; k++) {
            c(r, k) = m[r * N + k];
            if (!std::isfinite(c(r, k)))
                throw std::invalid_argument(what + " has a NaN or infinite entry at [" +
                                            std::to_string(r) + ", " + std::to_string(k) + "]");
            scale = std::max(scale, std::abs(c(r, k)));
        }
    for (int r = 0; r < N; r++)
        for (int k = r + 1; k < N; k++)
            if (!nearlyEqual(c(r, k), c(k, r), scale))
                throw std::invalid_argument(what + " is not symmetric ([" + std::to_string(r) +
                                            ", " + std::to_string(k) + "] != [" +
                                            std::to_string(k) + ", " + std::to_string(r) + "])");
    return c;
}
}  // namespace

py::array_t<double, py::array::c_style> realArray(const py::handle& obj, const std::string& where) {
    py::array a = py::array::ensure(obj);
    if (!a) throw py::type_error(where + " is not an array of numbers");
    const char kind = a.dtype().kind();
    if (kind != 'f' && kind != 'i' && kind != 'u')
        throw py::type_error(where + " has dtype " + std::string(py::str(a.dtype())) +
                             "; expected real numbers (float64, float32 or integers)");
    return py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
}

PointsWithCov pointsWithCovariance(const std::string& function, const py::handle& points,
                                   const py::handle& covariances, double offsetX_m,
                                   double offsetY_m) {
    const auto p = realArray(points, function + ": points");
    const auto c = realArray(covariances, function + ": covariances");
    requireShape(p, {-1, 3}, function + ": points", "(N, 3)");
    requireShape(c, {-1, 3, 3}, function + ": covariances", "(N, 3, 3)");
    if (c.shape(0) != p.shape(0))
        throw std::invalid_argument(function + ": covariances has " + std::to_string(c.shape(0)) +
                                    " matrices for " + std::to_string(p.shape(0)) + " points");
    const double* pd = p.data();
    const double* cd = c.data();
    PointsWithCov out(size_t(p.shape(0)));
    for (size_t i = 0; i < out.size(); i++) {
        const double* q = pd + 3 * i;
        if (!(std::isfinite(q[0]) && std::isfinite(q[1]) && std::isfinite(q[2])))
            throw std::invalid_argument(function + ": points[" + std::to_string(i) +
                                        "] has a NaN or infinite coordinate");
        const std::string what = function + ": covariances[" + std::to_string(i) + "]";
        const SymmetricCov3 cov = SymmetricCov3::fromMatrix(checkedCovariance<3>(cd + 9 * i, what));
        if (!isCovariance(cov))
            throw std::invalid_argument(what + " is not positive semi-definite");
        out[i].point_m =
            Eigen::Vector3f(float(q[0] - offsetX_m), float(q[1] - offsetY_m), float(q[2]));
        out[i].cov_m2 = cov;
    }
    return out;
}

mrpt::poses::CPose3D pose6(const std::string& where, const py::handle& pose) {
    const auto a = realArray(pose, where);
    requireShape(a, {6}, where, "(6,) (x, y, z [m], yaw, pitch, roll [rad])");
    const double* v = a.data();
    for (int i = 0; i < 6; i++)
        if (!std::isfinite(v[i]))
            throw std::invalid_argument(where + "[" + std::to_string(i) + "] is NaN or infinite");
    return mrpt::poses::CPose3D(v[0], v[1], v[2], v[3], v[4], v[5]);
}

mrpt::math::CMatrixDouble66 poseCovariance(const std::string& where, const py::handle& cov) {
    const auto a = realArray(cov, where);
    requireShape(a, {6, 6}, where, "(6, 6)");
    const Eigen::Matrix<double, 6, 6> c = checkedCovariance<6>(a.data(), where);
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(c);
    const double largest = std::max(0.0, eig.eigenvalues().maxCoeff());
    if (eig.eigenvalues().minCoeff() < -1e-9 * largest - 1e-300)
        throw std::invalid_argument(where + " is not positive semi-definite (eigenvalue " +
                                    std::to_string(eig.eigenvalues().minCoeff()) + ")");
    mrpt::math::CMatrixDouble66 out;
    for (int r = 0; r < 6; r++)
        for (int k = 0; k < 6; k++) out(r, k) = c(r, k);
    return out;
}

}  // namespace multibin::python
