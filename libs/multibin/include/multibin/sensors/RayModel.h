/* Part of the multibin elevation-mapping library. */
#pragma once

#include <Eigen/Core>

#include "multibin/geometry/PointsWithCovariance.h"
#include "multibin/sensors/SensorModelOptions.h"

namespace mrpt::obs {
class CObservationPointCloud;  // in mrpt::maps, not in obs_frwds.h
}

namespace multibin::sensors {

/** Covariance [m^2] of a point measured along the unit ray (dx, dy, dz) from the sensor origin:
 * axial_m^2 d d^T + lateral_m^2 (I - d d^T). */
inline SymmetricCov3 rayCovarianceAlong(double dx, double dy, double dz, double axial_m,
                                        double lateral_m) {
    // = (axial^2 - lateral^2) d d^T + lateral^2 I: six entries, no 3x3 temporaries.
    const double l2 = lateral_m * lateral_m, k = axial_m * axial_m - l2;
    return {float(k * dx * dx + l2), float(k * dx * dy), float(k * dx * dz),
            float(k * dy * dy + l2), float(k * dy * dz), float(k * dz * dz + l2)};
}

/** The same for a point `p_m` on the ray: d = p / |p|. */
inline SymmetricCov3 rayCovariance(const Eigen::Vector3f& p_m, double axial_m, double lateral_m) {
    const Eigen::Vector3d d = p_m.cast<double>() / p_m.cast<double>().norm();
    return rayCovarianceAlong(d.x(), d.y(), d.z(), axial_m, lateral_m);
}

/** Sensor-frame covariance [m^2] of a point at `p_m` (sensor origin at 0) under a ray model: a
 * DepthModelOptions, LidarModelOptions or StereoModelOptions (a stereo cloud's point), whose
 * raySigmas() give the sigmas along and across the ray as functions of its range. */
template <class Model>
SymmetricCov3 rayPointCovariance(const Eigen::Vector3f& p_m, const Model& model) {
    const RaySigmas s = model.raySigmas()(p_m.cast<double>().norm());
    return rayCovariance(p_m, s.axial_m, s.lateral_m);
}

/** Points of a point cloud observation in its sensor frame, each with its covariance under
 * `model`, or counted in `stats` as not finite or out of [minRange_m, maxRange_m] (a point at the
 * origin is a missing return). Model and statistics: DepthModelOptions with DepthStats (counted in
 * points), LidarModelOptions with LidarStats (scans, returns), StereoModelOptions with StereoStats
 * (pairs, pixels). */
template <class Model, class Stats>
void cloudToPoints(const mrpt::obs::CObservationPointCloud& cloud, const Model& model,
                   double minRange_m, double maxRange_m, PointsWithCov& out, Stats& stats);

}  // namespace multibin::sensors
