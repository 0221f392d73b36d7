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
void countPoints(DepthStats& s, size_t n) { s.points += n; }
void countPoints(LidarStats& s, size_t n) { s.returns += n; }
void countPoints(StereoStats& s, size_t n) { s.pixels += n; }
}  // namespace

template <class Model, class Stats>
void cloudToPoints(const mrpt::obs::CObservationPointCloud& cloud, const Model& model,
                   double minRange_m, double maxRange_m, PointsWithCov& out, Stats& stats) {
    out.clear();
    countCloud(stats);
    if (!cloud.pointcloud) return;
    countPoints(stats, cloud.pointcloud->size());
    count(appendCloudPoints(*cloud.pointcloud, minRange_m, maxRange_m, model.raySigmas(), out),
          stats);
}

template void cloudToPoints(const mrpt::obs::CObservationPointCloud&, const DepthModelOptions&,
                            double, double, PointsWithCov&, DepthStats&);
template void cloudToPoints(const mrpt::obs::CObservationPointCloud&, const LidarModelOptions&,
                            double, double, PointsWithCov&, LidarStats&);
template void cloudToPoints(const mrpt::obs::CObservationPointCloud&, const StereoModelOptions&,
                            double, double, PointsWithCov&, StereoStats&);

}  // namespace multibin::sensors
