/* Part of the multibin elevation-mapping library. */
#include "multibin/sensors/RayModel.h"

#include <mrpt/obs/CObservationPointCloud.h>

#include "RayPoint.h"
#include "multibin/sensors/SensorStats.h"

namespace multibin::sensors {

namespace {
// What each statistics struct counts for a cloud and for each of its points.
void countCloud(DepthStats&) {}
void countCloud(LidarStats& s) { s.scans++; }
void countCloud(StereoStats& s) { s.pairs++; }
void countPoint(DepthStats& s) { s.points++; }
void countPoint(LidarStats& s) { s.returns++; }
void countPoint(StereoStats& s) { s.pixels++; }
}  // namespace

template <class Model, class Stats>
void cloudToPoints(const mrpt::obs::CObservationPointCloud& cloud, const Model& model,
                   double minRange_m, double maxRange_m, PointsWithCov& out, Stats& stats) {
    out.clear();
    countCloud(stats);
    if (!cloud.pointcloud) return;
    const auto sigmas = model.raySigmas();
    forEachCloudPoint(*cloud.pointcloud, out, [&](const Eigen::Vector3f& p) {
        countPoint(stats);
        count(appendRayPoint(p, minRange_m, maxRange_m, sigmas, out), stats);
    });
}

template void cloudToPoints(const mrpt::obs::CObservationPointCloud&, const DepthModelOptions&,
                            double, double, PointsWithCov&, DepthStats&);
template void cloudToPoints(const mrpt::obs::CObservationPointCloud&, const LidarModelOptions&,
                            double, double, PointsWithCov&, LidarStats&);
template void cloudToPoints(const mrpt::obs::CObservationPointCloud&, const StereoModelOptions&,
                            double, double, PointsWithCov&, StereoStats&);

}  // namespace multibin::sensors
