/* Part of the multibin elevation-mapping library. */
#include "multibin/sensors/StereoModel.h"

#include <mrpt/poses/CPose3D.h>

#include <Eigen/Geometry>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace multibin::sensors {

namespace {
constexpr int kLeft = 0, kRight = 9, kExt = 18;

[[noreturn]] void notRectified(const std::string& field, const std::string& what) {
    throw std::invalid_argument("CObservationStereoImages: " + field + ": " + what +
                                " (the stereo model needs a rectified pair)");
}

/** OpenCV's distortion of normalised coordinates (x, y) with k1 k2 p1 p2 k3 = k[0..4]. */
Eigen::Vector2d distort(double x, double y, const double* k) {
    const double r2 = x * x + y * y;
    const double radial = 1 + r2 * (k[0] + r2 * (k[1] + r2 * k[4]));
    return {x * radial + 2 * k[2] * x * y + k[3] * (r2 + 2 * x * x),
            y * radial + k[2] * (r2 + 2 * y * y) + 2 * k[3] * x * y};
}

/** d (u, v) / d (fx fy cx cy k1 k2 p1 p2 k3) at zero distortion, normalised coords (x, y). */
Eigen::Matrix<double, 2, 9> intrinsicsJacobian(double x, double y, double fx, double fy) {
    const double r2 = x * x + y * y;
    Eigen::Matrix<double, 2, 9> J;
    J << x, 0, 1, 0, fx * x * r2, fx * x * r2 * r2, fx * 2 * x * y, fx * (r2 + 2 * x * x),
        fx * x * r2 * r2 * r2,  //
        0, y, 0, 1, fy * y * r2, fy * y * r2 * r2, fy * (r2 + 2 * y * y), fy * 2 * x * y,
        fy * y * r2 * r2 * r2;
    return J;
}

Eigen::Matrix3d skew(const Eigen::Vector3d& a) {
    Eigen::Matrix3d S;
    S << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
    return S;
}

/** d u_right / d (rx, ry, rz) at unit depth: fx (1, 0, -x) [(x, y, 1)]x (depth-independent). */
Eigen::RowVector3d rightRotationJacobian(double xr, double y, double fx) {
    return fx * Eigen::RowVector3d(1, 0, -xr) * skew(Eigen::Vector3d(xr, y, 1));
}

bool close(double a, double b) { return std::abs(a - b) <= 1e-6 * std::max(1.0, std::abs(a)); }
}  // namespace

StereoGeometry StereoGeometry::fromObservation(const mrpt::obs::CObservationStereoImages& obs) {
    const auto& L = obs.leftCamera;
    const auto& R = obs.rightCamera;
    StereoGeometry g;
    g.width = int(L.ncols);
    g.height = int(L.nrows);
    g.fx = L.fx();
    g.fy = L.fy();
    g.cx = L.cx();
    g.cy = L.cy();
    g.cxRight = R.cx();
    if (!(g.width > 0 && g.height > 0)) notRectified("leftCamera", "image size is zero");
    if (R.ncols != L.ncols || R.nrows != L.nrows)
        notRectified("rightCamera", "image size differs from leftCamera");
    if (!(g.fx > 0 && g.fy > 0)) notRectified("leftCamera", "focal lengths must be positive");
    if (!close(R.fx(), g.fx) || !close(R.fy(), g.fy) || !close(R.cy(), g.cy))
        notRectified("rightCamera", "fx, fy and cy must equal leftCamera's");
    for (double k : L.dist)
        if (k != 0) notRectified("leftCamera.dist", "distortion must be zero");
    for (double k : R.dist)
        if (k != 0) notRectified("rightCamera.dist", "distortion must be zero");
    const mrpt::poses::CPose3D rp(obs.rightCameraPose);
    g.baseline_m = rp.x();
    if (!(g.baseline_m > 0))
        notRectified("rightCameraPose", "the right camera must be at +x (baseline > 0)");
    if (std::abs(rp.y()) > 1e-6 * g.baseline_m || std::abs(rp.z()) > 1e-6 * g.baseline_m)
        notRectified("rightCameraPose", "translation must be along +x only");
    if (std::abs(rp.yaw()) > 1e-6 || std::abs(rp.pitch()) > 1e-6 || std::abs(rp.roll()) > 1e-6)
        notRectified("rightCameraPose", "rotation must be identity");
    return g;
}

bool StereoGeometry::operator==(const StereoGeometry& o) const {
    return width == o.width && height == o.height && fx == o.fx && fy == o.fy && cx == o.cx &&
           cy == o.cy && cxRight == o.cxRight && baseline_m == o.baseline_m;
}

Eigen::Vector3d StereoGeometry::triangulate(double u, double v, double d) const {
    const double z = baseline_m * fx / (d - (cx - cxRight));
    return {(u - cx) * z / fx, (v - cy) * z / fy, z};
}

Eigen::Matrix3d StereoGeometry::triangulationJacobian(double u, double v, double d) const {
    const Eigen::Vector3d p = triangulate(u, v, d);
    const double dd = d - (cx - cxRight);
    Eigen::Matrix3d J;
    J << p.z() / fx, 0, -p.x() / dd,  //
        0, p.z() / fy, -p.y() / dd,   //
        0, 0, -p.z() / dd;
    return J;
}

Eigen::Vector3d StereoGeometry::observe(const Eigen::Vector3d& P,
                                        const CalibrationVector& delta) const {
    auto project = [&](const Eigen::Vector3d& p, int base, double cxNominal) {
        const double* q = delta.data() + base;
        const double k[5] = {q[4], q[5], q[6], q[7], q[8]};
        const Eigen::Vector2d xd = distort(p.x() / p.z(), p.y() / p.z(), k);
        return Eigen::Vector2d((fx + q[0]) * xd.x() + cxNominal + q[2],
                               (fy + q[1]) * xd.y() + cy + q[3]);
    };
    const Eigen::Vector2d left = project(P, kLeft, cx);
    // True right camera pose in the left frame: rotation vector r, translation (b,0,0) + dt.
    const Eigen::Vector3d r = delta.segment<3>(kExt);
    const Eigen::Matrix3d Rot = r.norm() > 0
                                    ? Eigen::AngleAxisd(r.norm(), r / r.norm()).toRotationMatrix()
                                    : Eigen::Matrix3d::Identity();
    const Eigen::Vector3d t = Eigen::Vector3d(baseline_m, 0, 0) + delta.segment<3>(kExt + 3);
    const Eigen::Vector2d right = project(Rot.transpose() * (P - t), kRight, cxRight);
    return {left.x(), left.y(), left.x() - right.x()};
}

Eigen::Matrix<double, 3, kCalibrationParams> StereoGeometry::calibrationJacobian(double u, double v,
                                                                                 double d) const {
    const Eigen::Vector3d P = triangulate(u, v, d);
    const double x = (u - cx) / fx, y = (v - cy) / fy;
    const Eigen::Vector3d pr = P - Eigen::Vector3d(baseline_m, 0, 0);
    const double xr = pr.x() / pr.z();
    Eigen::Matrix<double, 3, kCalibrationParams> J;
    J.setZero();
    const Eigen::Matrix<double, 2, 9> Jl = intrinsicsJacobian(x, y, fx, fy);
    const Eigen::Matrix<double, 1, 9> Jr = intrinsicsJacobian(xr, y, fx, fy).row(0);
    J.block<2, 9>(0, kLeft) = Jl;
    J.block<1, 9>(2, kLeft) = Jl.row(0);
    J.block<1, 9>(2, kRight) = -Jr;
    // u_r = fx X_r / Z_r + c, p_r = R^T (P - t): d p_r / d r = [p_r]x, d p_r / d t = -I.
    const Eigen::RowVector3d duDp = fx * Eigen::RowVector3d(1 / pr.z(), 0, -xr / pr.z());
    J.block<1, 3>(2, kExt) = -duDp * skew(pr);
    J.block<1, 3>(2, kExt + 3) = duDp;
    return J;
}

CalibrationVector calibrationVariances(const StereoModelOptions& opts) {
    CalibrationVector v;
    for (int i = 0; i < 9; i++) {
        v[kLeft + i] = opts.leftIntrinsicsSigma[size_t(i)] * opts.leftIntrinsicsSigma[size_t(i)];
        v[kRight + i] = opts.rightIntrinsicsSigma[size_t(i)] * opts.rightIntrinsicsSigma[size_t(i)];
    }
    for (int i = 0; i < 6; i++)
        v[kExt + i] = opts.extrinsicsSigma[size_t(i)] * opts.extrinsicsSigma[size_t(i)];
    return v;
}

StereoCovarianceTable::StereoCovarianceTable(const StereoGeometry& g,
                                             const StereoModelOptions& opts)
    : m_geometry(g),
      m_var(calibrationVariances(opts)),
      m_matchingVar_px2(opts.matchingSigma_px * opts.matchingSigma_px) {
    const size_t n = size_t(g.width) * size_t(g.height);
    m_left.resize(3 * n);
    m_right.resize(4 * n);
    const Eigen::Matrix<double, 9, 1> vl = m_var.segment<9>(kLeft), vr = m_var.segment<9>(kRight);
    for (int v = 0; v < g.height; v++)
        for (int u = 0; u < g.width; u++) {
            const size_t i = size_t(v) * size_t(g.width) + size_t(u);
            const double y = (v - g.cy) / g.fy;
            // Left pixel (u, v): eq 6 with the left intrinsics.
            const Eigen::Matrix<double, 2, 9> Jl =
                intrinsicsJacobian((u - g.cx) / g.fx, y, g.fx, g.fy);
            const Eigen::Matrix2d Cl = Jl * vl.asDiagonal() * Jl.transpose();
            m_left[3 * i] = float(Cl(0, 0));
            m_left[3 * i + 1] = float(Cl(0, 1));
            m_left[3 * i + 2] = float(Cl(1, 1));
            // Right pixel (u, v): u variance from the right intrinsics, rotation Jacobian.
            const double xr = (u - g.cxRight) / g.fx;
            const Eigen::Matrix<double, 1, 9> Jr = intrinsicsJacobian(xr, y, g.fx, g.fy).row(0);
            m_right[4 * i] = float((Jr * vr.asDiagonal() * Jr.transpose())(0, 0));
            const Eigen::RowVector3d Jrot = rightRotationJacobian(xr, y, g.fx);
            for (int k = 0; k < 3; k++) m_right[4 * i + 1 + size_t(k)] = float(Jrot[k]);
        }
}

bool StereoCovarianceTable::matches(const StereoGeometry& g, const StereoModelOptions& opts) const {
    return g == m_geometry && calibrationVariances(opts) == m_var &&
           opts.matchingSigma_px * opts.matchingSigma_px == m_matchingVar_px2;
}

Eigen::Matrix3d StereoCovarianceTable::pixelCovariance(int u, int v, double d) const {
    const StereoGeometry& g = m_geometry;
    if (u < 0 || v < 0 || u >= g.width || v >= g.height)
        throw std::out_of_range("StereoCovarianceTable: pixel outside the image");
    const size_t i = size_t(v) * size_t(g.width) + size_t(u);
    // The right pixel of the match, to the nearest column (the table varies slowly).
    const int ur = std::min(g.width - 1, std::max(0, int(std::lround(u - d))));
    const size_t j = size_t(v) * size_t(g.width) + size_t(ur);
    const double luu = m_left[3 * i], luv = m_left[3 * i + 1], lvv = m_left[3 * i + 2];
    // Extrinsics: rotation row from the table, translation row d u_r / d t = fx/Z (1, 0, -x_r).
    const double z = g.baseline_m * g.fx / (d - (g.cx - g.cxRight));
    const double xr = (u - d - g.cxRight) / g.fx;
    double ext = 0;
    for (int k = 0; k < 3; k++)
        ext += m_var[kExt + k] * double(m_right[4 * j + 1 + size_t(k)]) *
               double(m_right[4 * j + 1 + size_t(k)]);
    const double jt[3] = {g.fx / z, 0, -g.fx * xr / z};
    for (int k = 0; k < 3; k++) ext += m_var[kExt + 3 + k] * jt[k] * jt[k];
    const double vd = luu + double(m_right[4 * j]) + ext + 2 * m_matchingVar_px2;
    Eigen::Matrix3d C;
    C << luu, luv, luu, luv, lvv, luv, luu, luv, vd;
    return C;
}

Eigen::Matrix3d StereoCovarianceTable::pointCovariance(int u, int v, double d) const {
    const Eigen::Matrix3d Jp = m_geometry.triangulationJacobian(u, v, d);
    return Jp * pixelCovariance(u, v, d) * Jp.transpose();
}

}  // namespace multibin::sensors
