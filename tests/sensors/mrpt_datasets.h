/* MRPT's own recorded datasets (Debian package mrpt-common, MRPT_DATASETS_DIR): reading them in
 * the tests. */
#pragma once

#include <gtest/gtest.h>
#include <mrpt/maps/CPointsMap.h>
#include <mrpt/obs/CObservation.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CRawlog.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose3DPDFGaussian.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>
#include <string>
#include <vector>

namespace multibin::test {

/** The observations of a rawlog of MRPT's datasets folder (fails the test if it is missing: the
 * set-up installs mrpt-common). */
inline std::vector<mrpt::obs::CObservation::Ptr> datasetObservations(const std::string& name) {
    mrpt::obs::CRawlog rawlog;
    const std::string path = std::string(MRPT_DATASETS_DIR) + "/" + name;
    EXPECT_TRUE(rawlog.loadFromRawLogFile(path)) << path << " (Debian package mrpt-common)";
    std::vector<mrpt::obs::CObservation::Ptr> out;
    for (size_t i = 0; i < rawlog.size(); i++) {
        if (rawlog.getType(i) == mrpt::obs::CRawlog::etObservation)
            out.push_back(rawlog.getAsObservation(i));
        else if (rawlog.getType(i) == mrpt::obs::CRawlog::etSensoryFrame)
            for (const auto& o : *rawlog.getAsObservations(i)) out.push_back(o);
    }
    for (auto& o : out) o->load();
    return out;
}

/** A nearly exact robot pose at the origin (1 mm, 1 mrad). */
inline mrpt::poses::CPose3DPDFGaussian originPose() {
    mrpt::poses::CPose3DPDFGaussian pdf;
    for (int i = 0; i < 6; i++) pdf.cov(i, i) = 1e-6;
    return pdf;
}

/** The points of an MRPT point map. */
inline std::vector<Eigen::Vector3d> pointsOf(const mrpt::maps::CPointsMap& map) {
    std::vector<Eigen::Vector3d> P;
    for (size_t i = 0; i < map.size(); i++) {
        float x, y, z;
        map.getPoint(i, x, y, z);
        P.emplace_back(x, y, z);
    }
    return P;
}

/** A depth frame's point in the map frame, with its pixel. */
struct FramePoint {
    Eigen::Vector3d p_m;
    int row, col;
};

/** The valid points (x > 0 in the camera frame) of a depth frame seen from the robot pose
 * `robot`, in the map frame. */
inline std::vector<FramePoint> depthFramePoints(const mrpt::obs::CObservation3DRangeScan& frame,
                                                const mrpt::poses::CPose3D& robot) {
    const mrpt::poses::CPose3D camera = robot + frame.sensorPose;
    std::vector<FramePoint> out;
    for (size_t i = 0; i < frame.points3D_x.size(); i++) {
        if (!(frame.points3D_x[i] > 0)) continue;
        double x, y, z;
        camera.composePoint(frame.points3D_x[i], frame.points3D_y[i], frame.points3D_z[i], x, y, z);
        out.push_back({{x, y, z}, frame.points3D_idxs_y[i], frame.points3D_idxs_x[i]});
    }
    return out;
}

/** A near-horizontal plane n.p = d (n_z > 0). */
struct FloorPlane {
    Eigen::Vector3d normal{0, 0, 1};
    double d_m = 0;
    size_t inliers = 0;
    double z(double x_m, double y_m) const {
        return (d_m - normal.x() * x_m - normal.y() * y_m) / normal.z();
    }
};

/** The floor of a scan: the near-horizontal plane (|n_z| > 0.8) with the most points within 5 cm
 * (RANSAC, 3000 draws, fixed seed). */
inline FloorPlane fitFloorPlane(const std::vector<Eigen::Vector3d>& P) {
    std::mt19937 rng(1);
    std::uniform_int_distribution<size_t> pick(0, P.size() - 1);
    FloorPlane best;
    for (int it = 0; it < 3000; it++) {
        const Eigen::Vector3d a = P[pick(rng)], b = P[pick(rng)], c = P[pick(rng)];
        Eigen::Vector3d m = (b - a).cross(c - a);
        if (m.norm() < 1e-9) continue;
        m = m.normalized() * (m.z() < 0 ? -1.0 : 1.0);
        if (m.z() < 0.8) continue;
        size_t inliers = 0;
        for (const auto& p : P) inliers += std::abs(m.dot(p) - m.dot(a)) < 0.05;
        if (inliers > best.inliers) best = {m, m.dot(a), inliers};
    }
    return best;
}

}  // namespace multibin::test
