/* Part of the multibin elevation-mapping library: the Python module.
 * The one height query the module answers, in one place: height(), the benchmark and the C++
 * query-table helper all call it, so switching to another of the map's queries is one edit. */
#pragma once

#include <mrpt/maps/CMultiBinElevationMap.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

namespace multibin::python {

/** Height [m], sigma [m] and source at (x, y) [m, pose frame]: the map's recommended query,
 * height(): the sub-cell surface where measured, else the gap filling's value (option
 * dem_return_filled); NaN and Unknown where the map knows nothing. */
inline HeightSource queryHeight(const mrpt::maps::CMultiBinElevationMap& map, double x_m,
                                double y_m, double& height_m, double& sigma_m) {
    const auto answer = map.height(x_m, y_m);  // NaN where unknown
    height_m = answer.height_m;
    sigma_m = answer.sigma_m;
    return answer.source;
}

/** queryHeight over n points: heights, sigmas [m] and sources (HeightSource as a number). */
inline void queryHeights(const mrpt::maps::CMultiBinElevationMap& map, const double* x_m,
                         const double* y_m, size_t n, double* height_m, double* sigma_m,
                         uint8_t* source) {
    for (size_t i = 0; i < n; i++)
        source[i] = static_cast<uint8_t>(queryHeight(map, x_m[i], y_m[i], height_m[i], sigma_m[i]));
}

}  // namespace multibin::python
