/* Part of the multibin elevation-mapping library's tests: a straight diagonal route over rough
 * ground, for the outputs' benchmark and figure (issue 35's route). */
#pragma once

#include <mrpt/maps/CMultiBinElevationMap.h>

#include <cmath>
#include <memory>

#include "multibin/geometry/PointsWithCovariance.h"

namespace route_map {

constexpr double kCell_m = 0.05, kSwath_m = 4.0, kStep_m = 0.2;

inline double ground_m(double x, double y) { return 0.1 * std::sin(0.7 * x) * std::cos(0.5 * y); }

/** One frame: the swath across the route at distance s along it, a point every half cell. */
inline multibin::PointsWithCov frameAt(double s) {
    multibin::PointsWithCov pts;
    const double ux = std::sqrt(0.5), uy = ux;  // along the route; across: (-uy, ux)
    for (double a = 0; a < kStep_m; a += 0.5 * kCell_m)
        for (double c = -0.5 * kSwath_m; c < 0.5 * kSwath_m; c += 0.5 * kCell_m) {
            const double x = (s + a) * ux - c * uy, y = (s + a) * uy + c * ux;
            multibin::PointWithCov p;
            p.point_m = Eigen::Vector3f(float(x), float(y), float(ground_m(x, y)));
            p.cov_m2 = {1e-6f, 0, 0, 1e-6f, 0, 1e-4f};
            pts.push_back(p);
        }
    return pts;
}

/** The route's map: a 4 m wide swath of 5 cm cells seen every 0.2 m along the diagonal, four
 * points a cell per frame (a point every half cell), inserted through growToCoverPoints +
 * insertPoints. */
inline std::unique_ptr<mrpt::maps::CMultiBinElevationMap> routeMap(double length_m,
                                                                   size_t* points = nullptr) {
    auto map = std::make_unique<mrpt::maps::CMultiBinElevationMap>();
    map->creationOptions.resolution_m = kCell_m;
    map->setCreationOptions(map->creationOptions);
    size_t n = 0;
    for (double s = 0; s < length_m; s += kStep_m) {
        const multibin::PointsWithCov pts = frameAt(s);
        const Eigen::Vector3d sensor(s * std::sqrt(0.5), s * std::sqrt(0.5), 1.0);
        map->growToCoverPoints(pts, sensor);
        map->insertPoints(pts);
        n += pts.size();
    }
    if (points) *points = n;
    return map;
}

}  // namespace route_map
