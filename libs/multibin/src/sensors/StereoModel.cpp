/* Part of the multibin elevation-mapping library. */
#include "multibin/sensors/StereoModel.h"

#include <mrpt/obs/CObservationPointCloud.h>
#include <mrpt/poses/CPose3D.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <exception>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "../util/HelperThread.h"
#include "RayPoint.h"
#include "multibin/util/Counters.h"
#include "multibin/util/VectorClones.h"

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
    if (!(g.fx > 0 && g.fy > 0 && std::isfinite(g.fx) && std::isfinite(g.fy)))
        notRectified("leftCamera", "focal lengths must be positive and finite");
    // A principal point that is NaN or far off the image turns every pixel's ray to NaN or into
    // nonsense: within one image size of the image, or refused.
    auto nearImage = [](double c_px, int size_px) {
        return c_px >= -size_px && c_px <= 2 * size_px;
    };
    if (!nearImage(g.cx, g.width) || !nearImage(g.cy, g.height))
        notRectified("leftCamera",
                     "principal point (cx, cy) must be finite and within one image "
                     "size of the image");
    if (!nearImage(g.cxRight, g.width))
        notRectified("rightCamera",
                     "principal point cx must be finite and within one image size "
                     "of the image");
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
    m_luu.resize(n);
    m_luv.resize(n);
    m_lvv.resize(n);
    m_rightVar.resize(n);
    const Eigen::Matrix<double, 9, 1> vl = m_var.segment<9>(kLeft), vr = m_var.segment<9>(kRight);
    for (int v = 0; v < g.height; v++)
        for (int u = 0; u < g.width; u++) {
            const size_t i = size_t(v) * size_t(g.width) + size_t(u);
            const double y = (v - g.cy) / g.fy;
            // Left pixel (u, v): eq 6 with the left intrinsics.
            const Eigen::Matrix<double, 2, 9> Jl =
                intrinsicsJacobian((u - g.cx) / g.fx, y, g.fx, g.fy);
            const Eigen::Matrix2d Cl = Jl * vl.asDiagonal() * Jl.transpose();
            m_luu[i] = float(Cl(0, 0));
            m_luv[i] = float(Cl(0, 1));
            m_lvv[i] = float(Cl(1, 1));
            // Right pixel (u, v): u variance from the right intrinsics plus that from the
            // extrinsic rotation (both rounded as the table stored them when they were apart).
            const double xr = (u - g.cxRight) / g.fx;
            const Eigen::Matrix<double, 1, 9> Jr = intrinsicsJacobian(xr, y, g.fx, g.fy).row(0);
            const float intrinsic = float((Jr * vr.asDiagonal() * Jr.transpose())(0, 0));
            const Eigen::RowVector3d Jrot = rightRotationJacobian(xr, y, g.fx);
            double rot = 0;
            for (int k = 0; k < 3; k++)
                rot += m_var[kExt + k] * double(float(Jrot[k])) * double(float(Jrot[k]));
            m_rightVar[i] = double(intrinsic) + rot;
        }
}

bool StereoCovarianceTable::matches(const StereoGeometry& g, const StereoModelOptions& opts) const {
    return g == m_geometry && calibrationVariances(opts) == m_var &&
           opts.matchingSigma_px * opts.matchingSigma_px == m_matchingVar_px2;
}

namespace {
/** What eqs 8-10 need besides the pixel, its disparity and its table entries (per table). */
struct PointConstants {
    double offset_px;   //!< cx - cxRight: d - offset is the disparity of the triangulation
    double baselineFx;  //!< baseline [m] * fx [px]
    double cx, cy, cxRight, fx, fy;
    double invFx, invFy, invBaseline, invBaselineFx;
    double varTx, varTz;  //!< extrinsic translation variances [m^2] (ty does not move u_r)
    double matchingVar2;  //!< 2 sigma_m^2 [px^2]

    PointConstants(const StereoGeometry& g, const CalibrationVector& var, double matchingVar)
        : offset_px(g.cx - g.cxRight),
          baselineFx(g.baseline_m * g.fx),
          cx(g.cx),
          cy(g.cy),
          cxRight(g.cxRight),
          fx(g.fx),
          fy(g.fy),
          invFx(1 / g.fx),
          invFy(1 / g.fy),
          invBaseline(1 / g.baseline_m),
          invBaselineFx(1 / (g.baseline_m * g.fx)),
          varTx(var[kExt + 3]),
          varTz(var[kExt + 5]),
          matchingVar2(2 * matchingVar) {}

    /** Column of the right pixel of the match, nearest to u - d, clamped to the image (equal to
     * clamp(lround(u - d)): u - d + 0.5 is exact wherever u - d is near a half); 0 for a NaN d. */
    static int rightColumn(double u, double d, int width) {
        return int(std::min(std::max(0.0, u - d), double(width - 1)) + 0.5);
    }

    /** Variance of the disparity [px^2] at left column u with disparity d: the left u
     * variance, the right pixel's u variance from its intrinsics and the extrinsic rotation
     * (table entry `rightVar`), from the extrinsic translation (d u_r / d t = fx / z (1, 0, -x_r),
     * fx / z = (d - offset) / baseline), and the matching noise of both images. */
    double disparityVariance(double u, double d, double luu, double rightVar) const {
        const double xr = (u - d - cxRight) * invFx;
        const double jtx = (d - offset_px) * invBaseline, jtz = -xr * jtx;
        return luu + rightVar + varTx * jtx * jtx + varTz * jtz * jtz + matchingVar2;
    }

    /** Eqs 8-10 for left pixel column u, row offset dv = v - cy [px], disparity d [px] and the
     * table entries of the pixel (luu, luv, lvv) and of its right pixel (rightVar): the point
     * [m] (x, y, z) and the upper triangle of its covariance [m^2] in SymmetricCov3's order. The
     * point is computed exactly as StereoGeometry::triangulate(); the covariance is
     * J_p C_uvd J_p^T written out with the zeros of J_p and C_uvd's repeated entries left out and
     * the divisions by d and fx replaced by products (a few 1e-16 relative from the plain
     * matrix product: tested to round to the same floats in practically every entry). */
    void point(double u, double dv, double d, double luu, double luv, double lvv, double rightVar,
               double* p, double* c) const {
        const double dd = d - offset_px;
        const double z = baselineFx / dd;
        const double x = (u - cx) * z / fx, y = dv * z / fy;
        p[0] = x;
        p[1] = y;
        p[2] = z;
        const double vd = disparityVariance(u, d, luu, rightVar);
        const double invDd = z * invBaselineFx;  // 1 / dd
        // Triangulation Jacobian [[a 0 b] [0 cc e] [0 0 f]] (eq 10's J_p).
        const double a = z * invFx, b = -x * invDd, cc = z * invFy, e = -y * invDd, f = -z * invDd;
        // T = J_p C_uvd (the entries needed), then J_p^T's columns.
        const double t00 = a * luu + b * luu, t01 = a * luv + b * luv, t02 = a * luu + b * vd;
        const double t11 = cc * lvv + e * luv, t12 = cc * luv + e * vd, t22 = f * vd;
        c[0] = t00 * a + t02 * b;
        c[1] = t01 * cc + t02 * e;
        c[2] = t02 * f;
        c[3] = t11 * cc + t12 * e;
        c[4] = t12 * f;
        c[5] = t22 * f;
    }
};

/** What became of a pixel: kept, or which test skipped it (in the order of the tests). */
enum PixelStatus : int32_t { kKept = 0, kNoDisparity = 1, kTooNear = 2, kOutOfRange = 3 };

/** Per-frame inputs of rowPoints() besides the row. */
struct RowInputs {
    int width, step;
    double minDepth_m, minRange2_m2, maxRange2_m2;  //!< range limits as squares (see below)
};

/** Results for the pixels of one image row (structure of arrays), allocated once per frame. */
struct RowBuffers {
    std::vector<float> p[3];      //!< points [m]
    std::vector<float> c[6];      //!< covariances [m^2], SymmetricCov3's order
    std::vector<int32_t> status;  //!< PixelStatus (int: vectorises with the doubles)
    explicit RowBuffers(size_t n) : status(n) {
        for (auto& a : p) a.resize(n);
        for (auto& a : c) a.resize(n);
    }
};

/** Points, covariances and status of the n pixels u = 0, step, 2 step... of one row: straight-
 * line code over arrays, which the compiler vectorises (4 doubles a step with AVX2; the right
 * pixel's table entries are gathered). `drow` and the table pointers point at the row. */
MULTIBIN_VECTOR_CLONES
void rowPoints(const PointConstants& constants, const RowInputs& in, double dv, size_t n,
               const float* __restrict drow, const float* __restrict luu,
               const float* __restrict luv, const float* __restrict lvv,
               const double* __restrict rightVar, RowBuffers& b) {
    const PointConstants k = constants;  // local copies: no aliasing with the outputs
    const RowInputs r = in;
    float* __restrict px = b.p[0].data();
    float* __restrict py = b.p[1].data();
    float* __restrict pz = b.p[2].data();
    float* __restrict c0 = b.c[0].data();
    float* __restrict c1 = b.c[1].data();
    float* __restrict c2 = b.c[2].data();
    float* __restrict c3 = b.c[3].data();
    float* __restrict c4 = b.c[4].data();
    float* __restrict c5 = b.c[5].data();
    int32_t* __restrict status = b.status.data();
#pragma GCC ivdep  // the arrays are distinct (GCC ignores restrict on local pointers)
    for (size_t i = 0; i < n; i++) {
        const int u = int(i) * r.step;  // int: converts to double in vector registers
        const double d = drow[u];
        const bool usable = d - k.offset_px > 0;  // false for NaN
        const int ur = PointConstants::rightColumn(double(u), d, r.width);
        double p[3], c[6];
        k.point(double(u), dv, d, luu[u], luv[u], lvv[u], rightVar[ur], p, c);
        // As Eigen's squaredNorm(): (x^2 + y^2) + z^2.
        const double range2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
        const bool inRange = !(range2 < r.minRange2_m2) & !(range2 > r.maxRange2_m2);
        // Branch-free (so the loop vectorises): the first failing test, in the order of the
        // tests (disparity, depth, range).
        const int tooNear = p[2] < r.minDepth_m;
        // Mutually exclusive 0/1 flags, combined with bit operations only.
        const int ok = usable, near = ok & tooNear, out = ok & (tooNear ^ 1) & int(!inRange);
        status[i] = (ok ^ 1) * kNoDisparity | near * kTooNear | out * kOutOfRange;
        px[i] = float(p[0]);
        py[i] = float(p[1]);
        pz[i] = float(p[2]);
        c0[i] = float(c[0]);
        c1[i] = float(c[1]);
        c2[i] = float(c[2]);
        c3[i] = float(c[3]);
        c4[i] = float(c[4]);
        c5[i] = float(c[5]);
    }
}

/** Appends the kept pixels of a row to `out` (written in place) and counts the skipped ones. */
void packRow(size_t n, RowBuffers& b, PointsWithCov& out, StereoPixelCounts& counts) {
    const float *px = b.p[0].data(), *py = b.p[1].data(), *pz = b.p[2].data();
    const float *c0 = b.c[0].data(), *c1 = b.c[1].data(), *c2 = b.c[2].data(), *c3 = b.c[3].data(),
                *c4 = b.c[4].data(), *c5 = b.c[5].data();
    const int32_t* status = b.status.data();
    // Zero-filled first (a plain memory fill): the packing then writes to lines already in the
    // cache, which measured faster than packing into a row buffer and copying it out.
    const size_t base = out.size();
    out.resize(base + n);
    PointWithCov* kept = out.data() + base;
    size_t m = 0, byStatus[4] = {0, 0, 0, 0};
    for (size_t i = 0; i < n; i++) {
        byStatus[status[i]]++;
        if (status[i] != kKept) continue;
        PointWithCov& q = kept[m++];
        q.point_m = Eigen::Vector3f(px[i], py[i], pz[i]);
        q.cov_m2 = {c0[i], c1[i], c2[i], c3[i], c4[i], c5[i]};
    }
    out.resize(base + m);
    counts.pixels += n;
    counts.kept += m;
    counts.noDisparity += byStatus[kNoDisparity];
    counts.tooNear += byStatus[kTooNear];
    counts.outOfRange += byStatus[kOutOfRange];
}

/** The smallest s >= 0 with sqrt(s) >= r_m: sqrt(s) < r_m exactly when s < this (sqrt is
 * correctly rounded, hence monotonic), so ranges are tested without a square root per point. */
double smallestSquareReaching(double r_m) {
    if (!(r_m > 0)) return -std::numeric_limits<double>::infinity();
    const double inf = std::numeric_limits<double>::infinity();
    double s = r_m * r_m;
    while (std::sqrt(s) < r_m) s = std::nextafter(s, inf);
    while (s > 0 && std::sqrt(std::nextafter(s, 0.0)) >= r_m) s = std::nextafter(s, 0.0);
    return s;
}

/** The largest s with sqrt(s) <= r_m: sqrt(s) > r_m exactly when s > this. */
double largestSquareWithin(double r_m) {
    const double inf = std::numeric_limits<double>::infinity();
    if (!(r_m >= 0)) return r_m < 0 ? -inf : inf;  // negative: every range exceeds it; NaN: none
    double s = r_m * r_m;
    while (s > 0 && std::sqrt(s) > r_m) s = std::nextafter(s, 0.0);
    while (s < inf && std::sqrt(std::nextafter(s, inf)) <= r_m) s = std::nextafter(s, inf);
    return s;
}

/** Table indices of the left pixel (u, v) and of its match at disparity d in the right image;
 * throws if (u, v) lies outside the image. */
std::pair<size_t, size_t> pixelPairIndices(const StereoGeometry& g, const PointConstants& k, int u,
                                           int v, double d) {
    if (u < 0 || v < 0 || u >= g.width || v >= g.height)
        throw std::out_of_range("StereoCovarianceTable: pixel outside the image");
    const size_t row = size_t(v) * size_t(g.width);
    return {row + size_t(u), row + size_t(k.rightColumn(u, d, g.width))};
}
}  // namespace

Eigen::Matrix3d StereoCovarianceTable::pixelCovariance(int u, int v, double d) const {
    const StereoGeometry& g = m_geometry;
    const PointConstants k(g, m_var, m_matchingVar_px2);
    const auto [i, j] = pixelPairIndices(g, k, u, v, d);
    const double luu = m_luu[i], luv = m_luv[i], lvv = m_lvv[i];
    const double vd = k.disparityVariance(u, d, luu, m_rightVar[j]);
    Eigen::Matrix3d C;
    C << luu, luv, luu, luv, lvv, luv, luu, luv, vd;
    return C;
}

Eigen::Matrix3d StereoCovarianceTable::pointCovariance(int u, int v, double d) const {
    const StereoGeometry& g = m_geometry;
    const PointConstants k(g, m_var, m_matchingVar_px2);
    const auto [i, j] = pixelPairIndices(g, k, u, v, d);
    double p[3], c[6];
    k.point(u, v - g.cy, d, m_luu[i], m_luv[i], m_lvv[i], m_rightVar[j], p, c);
    Eigen::Matrix3d C;
    C << c[0], c[1], c[2], c[1], c[3], c[4], c[2], c[4], c[5];
    return C;
}

StereoPixelCounts& StereoPixelCounts::operator+=(const StereoPixelCounts& o) {
    return util::addMembers(*this, o, &StereoPixelCounts::pixels, &StereoPixelCounts::noDisparity,
                            &StereoPixelCounts::tooNear, &StereoPixelCounts::outOfRange,
                            &StereoPixelCounts::kept);
}

StereoPixelCounts StereoCovarianceTable::appendPoints(const DisparityImage& disp, int step,
                                                      double minDepth_m, double minRange_m,
                                                      double maxRange_m, PointsWithCov& out,
                                                      int threads) const {
    const StereoGeometry& g = m_geometry;
    if (disp.width != g.width || disp.height != g.height)
        throw std::invalid_argument(
            "StereoCovarianceTable::appendPoints: disparity image size differs from the "
            "table's");
    if (step < 1)
        throw std::invalid_argument("StereoCovarianceTable::appendPoints: step_px must be >= 1");
    const PointConstants k(g, m_var, m_matchingVar_px2);
    const size_t perRow = size_t((g.width + step - 1) / step);
    const RowInputs in{g.width, step, minDepth_m, smallestSquareReaching(minRange_m),
                       largestSquareWithin(maxRange_m)};
    // Rows [v0, v1) (sampled every step) appended to `to`, counted in `c`.
    auto rows = [&](int v0, int v1, PointsWithCov& to, StereoPixelCounts& c) {
        RowBuffers b(perRow);
        for (int v = v0; v < v1; v += step) {
            const size_t row = size_t(v) * size_t(g.width);
            rowPoints(k, in, v - g.cy, perRow, disp.disparity_px.data() + row, m_luu.data() + row,
                      m_luv.data() + row, m_lvv.data() + row, m_rightVar.data() + row, b);
            packRow(perRow, b, to, c);
        }
    };
    const int sampledRows = (g.height + step - 1) / step;
    StereoPixelCounts counts;
    out.reserve(out.size() + perRow * size_t(sampledRows));
    // With a second core the helper thread does the lower half of the rows into its own array,
    // appended after the upper half: the same points in the same order. Worth it from about 64
    // rows (a frame's rows take milliseconds; waking the helper tens of microseconds).
    const int split = step * (sampledRows / 2);
    PointsWithCov lower;
    StereoPixelCounts lowerCounts;
    std::exception_ptr lowerError;
    HelperThread& helper = HelperThread::shared();
    const bool twoCores = threads >= 2 && sampledRows >= 64 && helper.tryStart([&] {
        try {
            lower.reserve(perRow * size_t(sampledRows - split / step));
            rows(split, g.height, lower, lowerCounts);
        } catch (...) {
            lowerError = std::current_exception();
        }
    });
    if (!twoCores) {
        rows(0, g.height, out, counts);
        return counts;
    }
    try {
        rows(0, split, out, counts);
    } catch (...) {
        helper.wait();
        throw;
    }
    helper.wait();
    if (lowerError) std::rethrow_exception(lowerError);
    out.insert(out.end(), lower.begin(), lower.end());
    return counts += lowerCounts;
}

void stereoToPoints(const mrpt::obs::CObservationStereoImages& obs, const StereoModelOptions& opts,
                    double minRange_m, double maxRange_m,
                    std::shared_ptr<const StereoCovarianceTable>& table, PointsWithCov& out,
                    StereoStats& stats, int threads) {
    StereoGeometry g;
    try {
        g = StereoGeometry::fromObservation(obs);
    } catch (const std::invalid_argument&) {
        stats.badCalibration++;
        throw;
    }
    DisparityImage disp;
    if (obs.hasImageDisparity) {
        disp = decodeDisparityImage(obs.imageDisparity);
    } else {
        if (!obs.hasImageRight)
            throw std::invalid_argument(
                "CObservationStereoImages '" + obs.sensorLabel +
                "': neither a disparity image nor a right image (hasImageRight = false)");
        disp = computeDisparitySGBM(obs.imageLeft, obs.imageRight, opts);
        stats.textureless += removeTextureless(disp, obs.imageLeft, opts);
    }
    if (disp.width != g.width || disp.height != g.height)
        throw std::invalid_argument("CObservationStereoImages '" + obs.sensorLabel +
                                    "': image size differs from leftCamera's ncols x nrows");
    if (opts.halo.enabled) stats.halo += removeHalos(disp, opts);
    if (opts.nearCluster.enabled) stats.nearCluster += removeNearClusters(disp, opts);

    if (!table || !table->matches(g, opts)) {
        table = std::make_shared<const StereoCovarianceTable>(g, opts);
        stats.tableBuilds++;
    }
    stats.pairs++;
    out.clear();
    const StereoPixelCounts c = table->appendPoints(disp, opts.subsample, opts.minDepth_m,
                                                    minRange_m, maxRange_m, out, threads);
    stats.pixels += c.pixels;
    stats.noDisparity += c.noDisparity;
    stats.tooNear += c.tooNear;
    stats.outOfRange += c.outOfRange;
    stats.kept += c.kept;
}

}  // namespace multibin::sensors
