/* Part of the multibin elevation-mapping library. */
#pragma once

#include <vector>

#include "multibin/fill/HeightSource.h"
#include "multibin/geometry/Lattice.h"

namespace multibin::fill {

/** The input of gap filling: the surface of every cell of an elevation grid, as plain rows.
 *
 * The geometry is a multibin::Lattice: cell (ix, iy), column ix and row iy of the lattice, is
 * stored at lattice.index(ix, iy) = iy * nx + ix. A cell is *measured* when certainty > 0 and its
 * height and sigma are finite, sigma > 0; every other cell is a gap to be filled (the map's "never
 * observed": c = 0 in every bin). */
struct HeightRaster {
    Lattice lattice;               //!< cells covered and their size
    std::vector<float> height_m;   //!< winning-bin height [m]; NaN where unknown
    std::vector<float> sigma_m;    //!< 1-sigma of that height [m]; NaN where unknown
    std::vector<float> certainty;  //!< winning-bin certainty c [-]; 0 = never observed

    HeightRaster() = default;
    /** A raster over `lattice` with every cell unknown (NaN height and sigma, certainty 0). */
    explicit HeightRaster(const Lattice& lattice);
    /** An nx x ny raster anchored at cell (0, 0), every cell unknown. */
    HeightRaster(int nx, int ny, double cellSize_m);

    int nx() const { return lattice.nx(); }  //!< number of columns (x) [cells]
    int ny() const { return lattice.ny(); }  //!< number of rows (y) [cells]
    double cellSize_m() const { return lattice.cellSize_m; }
    size_t size() const { return lattice.cellCount(); }
    size_t index(int ix, int iy) const { return lattice.index(ix, iy); }
    bool inside(int ix, int iy) const { return lattice.inside(ix, iy); }
    /** True if the cell holds a usable measurement (see the class comment). */
    bool isMeasured(size_t k) const;
    /** Marks a cell measured with the given height and sigma [m] (certainty 1 if c <= 0). */
    void setMeasured(int ix, int iy, float h_m, float sigma_m, float c = 1.0f);
    /** Marks a cell never observed (NaN height and sigma, certainty 0). */
    void setUnknown(int ix, int iy);

    /** Throws std::invalid_argument naming the field if sizes or the cell size are inconsistent. */
    void validate() const;
};

/** The output of gap filling: one height, sigma and source per cell of the input raster, on the
 * input's lattice.
 *
 * Measured cells keep their height and sigma; filled cells get a height and a 1-sigma
 * uncertainty; Unknown cells stay NaN. A height is never set to zero for lack of data. The
 * input certainty is not part of the result: filled cells keep certainty 0 in the map, so
 * foothold selection can still avoid them. */
struct FillResult {
    Lattice lattice;                   //!< the input raster's lattice
    std::vector<float> height_m;       //!< [m], NaN for Unknown cells
    std::vector<float> sigma_m;        //!< 1-sigma [m], NaN for Unknown cells
    std::vector<HeightSource> source;  //!< where each height comes from

    /** Statistics of one run (for logs, tests and tuning). */
    struct Stats {
        /** Cell counts; `gaussian` counts every cell filled from a support area's eq 16 fit
         * (FilledSurface and FilledHarmonic), `harmonic` those of them FilledHarmonic. */
        int measured = 0, median = 0, gaussian = 0, harmonic = 0, unfilled = 0;
        int gapComponents = 0;         //!< connected gaps found (4-connected never-observed cells)
        int supportAreas = 0;          //!< gaps filled by a Gaussian surface
        std::vector<int> termsChosen;  //!< AIC-chosen number m of Gaussians, per support area
        int movingNeighbourhoods = 0;  //!< gaps kriged in moving neighbourhoods (tiles)
        int rimCheckHarmonic = 0;      //!< of those, gaps the rim check gave to the harmonic path
        /** m of the eq 16 surface whose heights those gaps took (AICc on independent residuals;
         * termsChosen keeps the kriging's m for them), one per rimCheckHarmonic gap */
        std::vector<int> rimCheckTerms;
        /** gaps filled as shadows behind a step, from their hidden side (ShadowOccluders.h), and
         * their cells (FilledHarmonic) */
        int shadowGaps = 0, shadowCells = 0;
        /** cells the run read or labelled: the whole raster for fillGaps(); for fillSparse()
         * the cells its gap search flooded plus the per-gap rasters (its cost follows the data) */
        size_t cellsVisited = 0;
    } stats;

    int nx() const { return lattice.nx(); }
    int ny() const { return lattice.ny(); }
    size_t index(int ix, int iy) const { return lattice.index(ix, iy); }
    bool isFilled(size_t k) const {
        return source[k] == HeightSource::FilledMedian ||
               source[k] == HeightSource::FilledSurface ||
               source[k] == HeightSource::FilledHarmonic;
    }
};

}  // namespace multibin::fill
