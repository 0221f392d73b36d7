/* Part of the multibin elevation-mapping library: the Python module.
 * The one height query the module answers, in one place: height(), the benchmark and the C++
 * query-table helper all call it, so switching to another of the map's queries is one edit. */
#pragma once

#include <mrpt/maps/CMultiBinElevationMap.h>

#include <cstddef>
#include <cstdint>
#include <vector>

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

/** queryHeight over n points, bit for bit, as one batch (the map's heights(): one lock, the
 * work of a cell shared by the points near it): heights, sigmas [m] and sources (HeightSource as
 * a number). */
inline void queryHeights(const mrpt::maps::CMultiBinElevationMap& map, const double* x_m,
                         const double* y_m, size_t n, double* height_m, double* sigma_m,
                         uint8_t* source) {
    if (n == 1) {  // a scalar: as a loop of single queries calls it
        source[0] = static_cast<uint8_t>(queryHeight(map, x_m[0], y_m[0], height_m[0], sigma_m[0]));
        return;
    }
    std::vector<mrpt::maps::CMultiBinElevationMap::HeightAnswer> answers(n);
    map.heights(x_m, y_m, n, answers.data());
    for (size_t i = 0; i < n; i++) {
        height_m[i] = answers[i].height_m;
        sigma_m[i] = answers[i].sigma_m;
        source[i] = static_cast<uint8_t>(answers[i].source);
    }
}

/** queryHeight in a loop: what a C++ caller without the batch gets (benchmark reference). */
inline void queryHeightsOneByOne(const mrpt::maps::CMultiBinElevationMap& map, const double* x_m,
                                 const double* y_m, size_t n, double* height_m, double* sigma_m,
                                 uint8_t* source) {
    for (size_t i = 0; i < n; i++)
        source[i] = static_cast<uint8_t>(queryHeight(map, x_m[i], y_m[i], height_m[i], sigma_m[i]));
}

}  // namespace multibin::python
