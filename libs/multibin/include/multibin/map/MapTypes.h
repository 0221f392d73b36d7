/* Part of the multibin elevation-mapping library. */
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

namespace mrpt::config {
class CConfigFileBase;
}

namespace multibin {

class StrictConfigSection;

/** Parameters of the per-point bin update (eqs 13-15). */
struct BinUpdateParams {
    double binHeight_m = 0.05;               //!< vertical bin size [m]
    float certaintyIncrement = 1.0f;         //!< `a` of eqs 13-14
    double maxElevationUncertainty_m = 0.1;  //!< Delta_max: a point counts if 3 sigma_z <= this [m]
    double varianceFloor_m2 = 0.002 * 0.002;  //!< reported variance never falls below this [m^2]

    /** Eq 13 gate: a height with this variance [m^2] counts only if its 99.7 % interval
     * (3 sigma) lies within Delta_max. */
    bool passesEq13(double variance_m2) const {
        return !(9.0 * variance_m2 > maxElevationUncertainty_m * maxElevationUncertainty_m);
    }
};

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

/** Parameters of the visibility constraint. */
struct VisibilityParams {
    bool enabled = true;
    /** A bin conflicts with a line of sight when it lies above it by more than this plus 3 sigma
     * of the bin [m]: cell-size relief and the ray's own uncertainty live in this margin. */
    double margin_m = 0.02;
    /** The fixed amount of certainty a conflicting bin loses for each new point it contradicts
     * (each point whose line of sight it blocks, or which lies below it in its own cell): with
     * the default equal to the certainty increment, a moved object is forgotten as fast as the
     * new surface is learnt. */
    float certaintyDecrement = 1.0f;
    /** What a bin above a line of sight (and as certain as the ray's target or more; a less
     * certain one goes at once) loses per ray after the decrement: this share [0, 1] of the
     * certainty left. 0 is the paper's fixed amount, 1 removes the bin. A vertical face collects
     * tens of points per cell and pass where ground collects a few, so with a fixed amount per
     * point the face outweighs every later ray through where it stood (doc/visibility.md). */
    float certaintyShare = 0.5f;

    /** The options protocol of every option struct of the library (map, fill, sensors,
     * visibility): read its keys from a strict ini section, write them, validate (throws
     * std::invalid_argument naming the key). Keys: visibility_constraint,
     * visibility_margin_m (alias visibility_margin), visibility_certainty_decrement,
     * visibility_certainty_share. */
    void read(StrictConfigSection& section);
    void write(mrpt::config::CConfigFileBase& target, const std::string& section) const;
    void validate() const;
};

/** What one application of the constraint did. */
struct VisibilityStats {
    size_t raysCast = 0;      //!< one per distinct updated cell
    size_t cellsVisited = 0;  //!< cells tested along the rays
    size_t binsRemoved = 0;   //!< stale bins removed
    size_t binsWeakened = 0;  //!< conflicting bins that lost certainty
};

/** Where a cell's height comes from: one enum for the map's queries, gap filling, rasters and
 * exports (the number is the value of the `source` raster layer). */
enum class HeightSource : std::uint8_t {
    Unknown = 0,        //!< never observed and not filled
    Measured = 1,       //!< observed: the cell's surface from its bins
    FilledMedian = 2,   //!< never observed; weighted median of the neighbours
    FilledSurface = 3,  //!< never observed; Gaussian surface (eq 16) / kriging of its support area
    /** never observed; eq 16 plus harmonic (or biharmonic) rim residuals: the rim check's choice
     * for a long shadow, or the surface path (its own sigma, doc/gap-filling.md) */
    FilledHarmonic = 4,
};

}  // namespace multibin
