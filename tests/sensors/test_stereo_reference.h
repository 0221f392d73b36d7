/* The stereo sensor model as it was before its optimisation (commit 12fed76): per-pixel Eigen
 * products, an interleaved covariance table, a flood fill over every valid pixel for the
 * near-cluster filter. Kept only as the straightforward reference that the optimised library
 * path is compared with (test_stereo_aloe's equivalence tests) and timed against in the same run
 * (tests/bench/bench_stereo.cpp). Not part of the library. */
#pragma once

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "multibin/geometry/PointsWithCovariance.h"
#include "multibin/sensors/StereoDisparity.h"
#include "multibin/sensors/StereoModel.h"

namespace stereo_reference {

using multibin::PointsWithCov;
using multibin::SymmetricCov3;
using multibin::sensors::CalibrationVector;
using multibin::sensors::DisparityImage;
using multibin::sensors::StereoGeometry;
using multibin::sensors::StereoModelOptions;

inline Eigen::Matrix<double, 2, 9> intrinsicsJacobian(double x, double y, double fx, double fy) {
    const double r2 = x * x + y * y;
    Eigen::Matrix<double, 2, 9> J;
    J << x, 0, 1, 0, fx * x * r2, fx * x * r2 * r2, fx * 2 * x * y, fx * (r2 + 2 * x * x),
        fx * x * r2 * r2 * r2,  //
        0, y, 0, 1, fy * y * r2, fy * y * r2 * r2, fy * (r2 + 2 * y * y), fy * 2 * x * y,
        fy * y * r2 * r2 * r2;
    return J;
}

inline Eigen::RowVector3d rightRotationJacobian(double xr, double y, double fx) {
    Eigen::Matrix3d S;
    S << 0, -1, y, 1, 0, -xr, -y, xr, 0;
    return fx * Eigen::RowVector3d(1, 0, -xr) * S;
}

/** The covariance table and per-point covariance as they were (eqs 6-10). */
class Table {
public:
    Table(const StereoGeometry& g, const StereoModelOptions& opts)
        : m_g(g),
          m_var(multibin::sensors::calibrationVariances(opts)),
          m_matchingVar_px2(opts.matchingSigma_px * opts.matchingSigma_px) {
        const size_t n = size_t(g.width) * size_t(g.height);
        m_left.resize(3 * n);
        m_right.resize(4 * n);
        const Eigen::Matrix<double, 9, 1> vl = m_var.segment<9>(0), vr = m_var.segment<9>(9);
        for (int v = 0; v < g.height; v++)
            for (int u = 0; u < g.width; u++) {
                const size_t i = size_t(v) * size_t(g.width) + size_t(u);
                const double y = (v - g.cy) / g.fy;
                const Eigen::Matrix<double, 2, 9> Jl =
                    intrinsicsJacobian((u - g.cx) / g.fx, y, g.fx, g.fy);
                const Eigen::Matrix2d Cl = Jl * vl.asDiagonal() * Jl.transpose();
                m_left[3 * i] = float(Cl(0, 0));
                m_left[3 * i + 1] = float(Cl(0, 1));
                m_left[3 * i + 2] = float(Cl(1, 1));
                const double xr = (u - g.cxRight) / g.fx;
                const Eigen::Matrix<double, 1, 9> Jr = intrinsicsJacobian(xr, y, g.fx, g.fy).row(0);
                m_right[4 * i] = float((Jr * vr.asDiagonal() * Jr.transpose())(0, 0));
                const Eigen::RowVector3d Jrot = rightRotationJacobian(xr, y, g.fx);
                for (int k = 0; k < 3; k++) m_right[4 * i + 1 + size_t(k)] = float(Jrot[k]);
            }
    }

    Eigen::Matrix3d pixelCovariance(int u, int v, double d) const {
        const StereoGeometry& g = m_g;
        const size_t i = size_t(v) * size_t(g.width) + size_t(u);
        const int ur = std::min(g.width - 1, std::max(0, int(std::lround(u - d))));
        const size_t j = size_t(v) * size_t(g.width) + size_t(ur);
        const double luu = m_left[3 * i], luv = m_left[3 * i + 1], lvv = m_left[3 * i + 2];
        const double z = g.baseline_m * g.fx / (d - (g.cx - g.cxRight));
        const double xr = (u - d - g.cxRight) / g.fx;
        double ext = 0;
        for (int k = 0; k < 3; k++)
            ext += m_var[18 + k] * double(m_right[4 * j + 1 + size_t(k)]) *
                   double(m_right[4 * j + 1 + size_t(k)]);
        const double jt[3] = {g.fx / z, 0, -g.fx * xr / z};
        for (int k = 0; k < 3; k++) ext += m_var[21 + k] * jt[k] * jt[k];
        const double vd = luu + double(m_right[4 * j]) + ext + 2 * m_matchingVar_px2;
        Eigen::Matrix3d C;
        C << luu, luv, luu, luv, lvv, luv, luu, luv, vd;
        return C;
    }

    Eigen::Matrix3d pointCovariance(int u, int v, double d) const {
        const Eigen::Matrix3d Jp = m_g.triangulationJacobian(u, v, d);
        return Jp * pixelCovariance(u, v, d) * Jp.transpose();
    }

private:
    StereoGeometry m_g;
    CalibrationVector m_var;
    double m_matchingVar_px2 = 0;
    std::vector<float> m_left, m_right;
};

inline size_t removeHalos(DisparityImage& d, const StereoModelOptions& o) {
    cv::Mat m(d.height, d.width, CV_32F);
    for (int v = 0; v < d.height; v++)
        for (int u = 0; u < d.width; u++) m.at<float>(v, u) = d.valid(u, v) ? d.at(u, v) : 1e9f;
    cv::Mat minWin;
    const int k = 2 * o.halo.radius_px + 1;
    cv::erode(m, minWin, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(k, k)));
    size_t removed = 0;
    for (int v = 0; v < d.height; v++)
        for (int u = 0; u < d.width; u++)
            if (d.valid(u, v) && d.at(u, v) - minWin.at<float>(v, u) > o.halo.jump_px) {
                d.at(u, v) = std::numeric_limits<float>::quiet_NaN();
                removed++;
            }
    return removed;
}

inline size_t removeNearClusters(DisparityImage& d, const StereoModelOptions& o) {
    const int W = d.width, H = d.height;
    std::vector<int32_t> label(size_t(W) * size_t(H), -1);
    std::vector<int> stack, members;
    std::vector<float> around;
    std::vector<int32_t> aroundSeen(label.size(), -1);
    size_t removed = 0;
    int32_t next = 0;
    const int du[4] = {1, -1, 0, 0}, dv[4] = {0, 0, 1, -1};
    for (int start = 0; start < W * H; start++) {
        if (label[size_t(start)] >= 0 || !std::isfinite(d.disparity_px[size_t(start)])) continue;
        const int32_t id = next++;
        stack.assign(1, start);
        members.clear();
        around.clear();
        label[size_t(start)] = id;
        double sum = 0;
        bool small = true;
        while (!stack.empty()) {
            const int p = stack.back();
            stack.pop_back();
            members.push_back(p);
            const float dp = d.disparity_px[size_t(p)];
            sum += dp;
            const int u = p % W, v = p / W;
            for (int k = 0; k < 4; k++) {
                const int uu = u + du[k], vv = v + dv[k];
                if (uu < 0 || vv < 0 || uu >= W || vv >= H) continue;
                const int q = vv * W + uu;
                const float dq = d.disparity_px[size_t(q)];
                if (!std::isfinite(dq)) continue;
                if (std::abs(dq - dp) <= o.nearCluster.step_px) {
                    if (label[size_t(q)] < 0) {
                        label[size_t(q)] = id;
                        stack.push_back(q);
                    }
                } else if (small && aroundSeen[size_t(q)] != id) {
                    aroundSeen[size_t(q)] = id;
                    around.push_back(dq);
                }
            }
            if (small && int(members.size()) >= o.nearCluster.maxArea_px) small = false;
        }
        if (!small) continue;
        bool remove = around.empty();
        if (!remove) {
            std::nth_element(around.begin(), around.begin() + long(around.size() / 2),
                             around.end());
            const double median = around[around.size() / 2];
            remove = sum / double(members.size()) > median + o.nearCluster.jump_px;
        }
        if (remove) {
            for (int p : members)
                d.disparity_px[size_t(p)] = std::numeric_limits<float>::quiet_NaN();
            removed += members.size();
        }
    }
    return removed;
}

/** What the reference frame path produced. */
struct Frame {
    DisparityImage filtered;  //!< the disparity after both filters
    PointsWithCov points;
    size_t halo = 0, nearCluster = 0, pixels = 0, noDisparity = 0, tooNear = 0, outOfRange = 0;
};

/** The old stereoToPoints from a decoded disparity image (filters, then every `subsample`-th
 * pixel through the table). */
inline Frame framePoints(const StereoGeometry& g, DisparityImage disp, const Table& table,
                         const StereoModelOptions& opts, double minRange_m, double maxRange_m) {
    Frame f;
    if (opts.halo.enabled) f.halo = stereo_reference::removeHalos(disp, opts);
    if (opts.nearCluster.enabled) f.nearCluster = stereo_reference::removeNearClusters(disp, opts);
    const int step = opts.subsample;
    f.points.reserve(size_t(g.width / step + 1) * size_t(g.height / step + 1));
    for (int v = 0; v < g.height; v += step)
        for (int u = 0; u < g.width; u += step) {
            f.pixels++;
            const float d = disp.at(u, v);
            if (!(d - (g.cx - g.cxRight) > 0)) {
                f.noDisparity++;
                continue;
            }
            const Eigen::Vector3d p = g.triangulate(u, v, d);
            if (p.z() < opts.minDepth_m) {
                f.tooNear++;
                continue;
            }
            const double r = p.norm();
            if (r < minRange_m || r > maxRange_m) {
                f.outOfRange++;
                continue;
            }
            f.points.push_back(
                {p.cast<float>(), SymmetricCov3::fromMatrix(table.pointCovariance(u, v, d))});
        }
    f.filtered = std::move(disp);
    return f;
}

}  // namespace stereo_reference
