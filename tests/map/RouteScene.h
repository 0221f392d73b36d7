/* Part of the multibin elevation-mapping library's tests.
 * A route as long as one likes over rough ground, seen by a depth-camera-like sensor: the input of
 * the route-scale test and program (doc/route-scale.md). Not the library's own models: the ground
 * is a fixed sum of waves with uniform noise, the points a regular grid ahead of the robot. */
#pragma once

#include <mrpt/maps/CSimplePointsMap.h>
#include <mrpt/obs/CObservationPointCloud.h>
#include <mrpt/poses/CPose3D.h>

#include <cmath>
#include <cstdint>
#include <random>

namespace multibin::test {

/** A straight route along the diagonal (heading 45 deg) from the origin. */
struct RouteOptions {
    double length_m = 50;     //!< along the route
    double step_m = 0.2;      //!< between clouds
    double swath_m = 4.0;     //!< width of each cloud's footprint, across the route
    double nearest_m = 0.5;   //!< footprint from nearest_m ..
    double farthest_m = 2.5;  //!< .. to farthest_m ahead of the robot
    double spacing_m = 0.04;  //!< between the footprint's points
    double sensorHeight_m = 1.0;
    double noise_m = 0.005;  //!< half-width of the uniform height noise
    uint32_t seed = 1;
};

/** The rough ground [m]: waves of 0.5 .. 7 m, about 0.1 m high. */
inline double routeGround_m(double x_m, double y_m) {
    return 0.06 * std::sin(0.9 * x_m) * std::cos(0.7 * y_m) +
           0.03 * std::sin(3.1 * x_m + 1.7 * y_m) + 0.015 * std::cos(9.0 * x_m - 5.0 * y_m) +
           0.1 * std::sin(0.05 * (x_m + y_m));
}

/** Number of clouds along the route. */
inline size_t routeCloudCount(const RouteOptions& o) { return size_t(o.length_m / o.step_m) + 1; }

/** Calls f(const CObservationPointCloud&, const CPose3D& robotPose, size_t pointCount) for each
 * cloud along the route: the points in the sensor frame (sensorPose: sensorHeight_m above the
 * robot, looking ahead), the robot on the ground. */
template <typename F>
void forEachRouteCloud(const RouteOptions& o, F&& f) {
    std::mt19937 rng(o.seed);
    std::uniform_real_distribution<double> noise(-o.noise_m, o.noise_m);
    const double c = std::cos(M_PI / 4), s = std::sin(M_PI / 4);
    const mrpt::poses::CPose3D sensorOnRobot(0, 0, o.sensorHeight_m, 0, 0, 0);
    for (size_t k = 0; k < routeCloudCount(o); k++) {
        const double along = k * o.step_m, rx = c * along, ry = s * along;
        const mrpt::poses::CPose3D robot(rx, ry, routeGround_m(rx, ry), M_PI / 4, 0, 0);
        const mrpt::poses::CPose3D sensor = robot + sensorOnRobot;
        auto points = mrpt::maps::CSimplePointsMap::Create();
        for (double u = o.nearest_m; u <= o.farthest_m; u += o.spacing_m)
            for (double v = -0.5 * o.swath_m; v <= 0.5 * o.swath_m; v += o.spacing_m) {
                const double x = rx + c * u - s * v, y = ry + s * u + c * v;
                double lx, ly, lz;
                sensor.inverseComposePoint(x, y, routeGround_m(x, y) + noise(rng), lx, ly, lz);
                points->insertPoint(float(lx), float(ly), float(lz));
            }
        mrpt::obs::CObservationPointCloud cloud;
        cloud.sensorLabel = "DEPTH";
        cloud.sensorPose = sensorOnRobot;
        cloud.pointcloud = points;
        f(cloud, robot, points->size());
    }
}

}  // namespace multibin::test
