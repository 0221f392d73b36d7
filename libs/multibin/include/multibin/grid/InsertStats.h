/* Part of the multibin elevation-mapping library. */
#pragma once

#include <cmath>
#include <cstddef>

namespace multibin {

/** What happened to the points of one insertion. */
struct InsertStats {
    size_t accepted = 0;       //!< fused into a bin
    size_t outOfRange = 0;     //!< sensor reading invalid or outside the accepted range
    size_t notFinite = 0;      //!< NaN/inf coordinates or covariance
    size_t badCovariance = 0;  //!< covariance indefinite (zero and singular ones are exact)
    /** (x, y) outside the grid window (after any growth: grow and the extent keys, the dual
     * grid's sizes, and max_range_m, how far from its sensor a point grows the map, govern it),
     * the point passing eq 13 */
    size_t outsideMap = 0;
    size_t outsideBinRange = 0;  //!< height beyond the representable bin indices
    /** eq 13 gate: 3 sigma_z > Delta_max (max_elevation_uncertainty_m or the sensor model's
     * *_max_elevation_uncertainty_m), wherever the point lies: such a point does not grow the
     * map either */
    size_t tooUncertain = 0;
    size_t continuityRejected = 0;  //!< eq 14 gate: |h_m - h| > Delta_zmax on a certain bin
    /** Not a rejection: of the points an observation handed to the grid, those whose ray from
     * the sensor points more than kBelowHorizon_rad below the horizontal (a sensor that sees
     * the ground below it; a horizontal laser's are all level with it). */
    size_t seenBelow = 0;
    static constexpr double kBelowHorizon_rad = 5.0 * M_PI / 180.0;
    size_t rejected() const {
        return outOfRange + notFinite + badCovariance + outsideMap + outsideBinRange +
               tooUncertain + continuityRejected;
    }
    InsertStats& operator+=(const InsertStats& o);
};

}  // namespace multibin
