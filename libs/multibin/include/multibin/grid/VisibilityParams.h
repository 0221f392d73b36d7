/* Part of the multibin elevation-mapping library. */
#pragma once

#include <cstddef>
#include <string>

#include "multibin/io/OptionsFwd.h"

namespace multibin {

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
    VisibilityStats& operator+=(const VisibilityStats& o);  //!< saturating, as InsertStats
};

}  // namespace multibin
