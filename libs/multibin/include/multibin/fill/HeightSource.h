/* Part of the multibin elevation-mapping library. */
#pragma once

#include <cstdint>

namespace multibin {

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
