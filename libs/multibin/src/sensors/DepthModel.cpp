/* Part of the multibin elevation-mapping library. */
#include "multibin/sensors/DepthModel.h"

#include <mrpt/maps/CPointsMap.h>
#include <mrpt/maps/CSimplePointsMap.h>

#include <cmath>
#include <stdexcept>
#include <string>

namespace multibin::sensors {

SymmetricCov3 depthPointCovariance(const Eigen::Vector3f& p_m, const DepthModelOptions& opts) {
    const double r = p_m.cast<double>().norm();
    const Eigen::Vector3d d = p_m.cast<double>() / r;
    const double sa = opts.axialSigma_m(r), sl = opts.lateralSigma_rad * r;
    const Eigen::Matrix3d C =
        sa * sa * d * d.transpose() + sl * sl * (Eigen::Matrix3d::Identity() - d * d.transpose());
    return SymmetricCov3::fromMatrix(C);
}

void appendDepthPoint(const Eigen::Vector3f& p_m, const DepthModelOptions& opts, double minRange_m,
                      double maxRange_m, PointsWithCov& out, DepthStats& stats) {
    stats.points++;
    if (!p_m.allFinite()) {
        stats.notFinite++;
        return;
    }
    const float r = p_m.norm();
    if (!(r > 0) || r < minRange_m || r > maxRange_m) {
        stats.outOfRange++;
        return;
    }
    out.push_back({p_m, depthPointCovariance(p_m, opts)});
    stats.kept++;
}

namespace {
void appendPointsMap(const mrpt::maps::CPointsMap& pts, const DepthModelOptions& opts,
                     double minRange_m, double maxRange_m, PointsWithCov& out, DepthStats& stats) {
    const auto& xs = pts.getPointsBufferRef_x();
    const auto& ys = pts.getPointsBufferRef_y();
    const auto& zs = pts.getPointsBufferRef_z();
    out.reserve(out.size() + xs.size());
    for (size_t i = 0; i < xs.size(); i++)
        appendDepthPoint(Eigen::Vector3f(xs[i], ys[i], zs[i]), opts, minRange_m, maxRange_m, out,
                         stats);
}
}  // namespace

void depthScanToPoints(const mrpt::obs::CObservation3DRangeScan& scan,
                       const DepthModelOptions& opts, double minRange_m, double maxRange_m,
                       PointsWithCov& out, DepthStats& stats) {
    out.clear();
    if (scan.hasPoints3D) {
        const size_t nx = scan.points3D_x.size(), ny = scan.points3D_y.size(),
                     nz = scan.points3D_z.size();
        if (nx != ny || nx != nz)
            throw std::invalid_argument(
                "CObservation3DRangeScan '" + scan.sensorLabel +
                "': points3D_x, points3D_y and points3D_z have different sizes (" +
                std::to_string(nx) + ", " + std::to_string(ny) + ", " + std::to_string(nz) + ")");
        out.reserve(nx);
        for (size_t i = 0; i < scan.points3D_x.size(); i++)
            appendDepthPoint(
                Eigen::Vector3f(scan.points3D_x[i], scan.points3D_y[i], scan.points3D_z[i]), opts,
                minRange_m, maxRange_m, out, stats);
    } else if (scan.hasRangeImage) {
        mrpt::maps::CSimplePointsMap local;
        mrpt::obs::T3DPointsProjectionParams pp;
        pp.takeIntoAccountSensorPoseOnRobot = false;  // sensor frame (+x forward)
        // unprojectInto() only fills caches of the observation; the data are not changed.
        const_cast<mrpt::obs::CObservation3DRangeScan&>(scan).unprojectInto(local, pp);
        appendPointsMap(local, opts, minRange_m, maxRange_m, out, stats);
    }
}

void pointCloudToPoints(const mrpt::obs::CObservationPointCloud& cloud,
                        const DepthModelOptions& opts, double minRange_m, double maxRange_m,
                        PointsWithCov& out, DepthStats& stats) {
    out.clear();
    if (cloud.pointcloud)
        appendPointsMap(*cloud.pointcloud, opts, minRange_m, maxRange_m, out, stats);
}

}  // namespace multibin::sensors
