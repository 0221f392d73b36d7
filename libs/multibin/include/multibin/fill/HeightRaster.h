/* Part of the multibin elevation-mapping library. */
#pragma once

#include <cstdint>
#include <vector>

namespace multibin::fill {

/** Where the height of a cell of a FillResult comes from. */
enum class FillSource : std::uint8_t {
    Measured = 0,  //!< observed (certainty > 0): copied unchanged
    Median = 1,    //!< never observed, filled by the weighted median of its neighbours
    Gaussian = 2,  //!< never observed, filled by the Gaussian surface of its support area (eq 16)
    Unfilled = 3   //!< never observed and left unknown (NaN): gap too large or no data near it
};

/** The input of gap filling: the winning bin of every cell of an elevation grid, as plain rows.
 *
 * Cell (ix, iy) is stored at index iy * nx + ix; ix grows with x (columns), iy with y (rows).
 * A cell is *measured* when certainty > 0 and its height and sigma are finite, sigma > 0; every
 * other cell is a gap to be filled (the map's "never observed": c = 0 in every bin). */
struct HeightRaster {
    int nx = 0;                    //!< number of columns (x) [cells]
    int ny = 0;                    //!< number of rows (y) [cells]
    double cellSize_m = 0.015;     //!< cell side [m]
    std::vector<float> height_m;   //!< winning-bin height [m]; NaN where unknown
    std::vector<float> sigma_m;    //!< 1-sigma of that height [m]; NaN where unknown
    std::vector<float> certainty;  //!< winning-bin certainty c [-]; 0 = never observed

    HeightRaster() = default;
    /** An nx x ny raster with every cell unknown (NaN height and sigma, certainty 0). */
    HeightRaster(int nx, int ny, double cellSize_m);

    size_t size() const { return size_t(nx) * size_t(ny); }
    size_t index(int ix, int iy) const { return size_t(iy) * size_t(nx) + size_t(ix); }
    bool inside(int ix, int iy) const { return ix >= 0 && iy >= 0 && ix < nx && iy < ny; }
    /** True if the cell holds a usable measurement (see the class comment). */
    bool isMeasured(size_t k) const;
    /** Marks a cell measured with the given height and sigma [m] (certainty 1 if c <= 0). */
    void setMeasured(int ix, int iy, float h_m, float sigma_m, float c = 1.0f);
    /** Marks a cell never observed (NaN height and sigma, certainty 0). */
    void setUnknown(int ix, int iy);

    /** Throws std::invalid_argument naming the field if sizes or the cell size are inconsistent. */
    void validate() const;
};

/** The output of gap filling: one height, sigma and source per cell of the input raster.
 *
 * Measured cells keep their height and sigma; filled cells get a height and a 1-sigma
 * uncertainty; Unfilled cells stay NaN. A height is never set to zero for lack of data. The
 * input certainty is not part of the result: filled cells keep certainty 0 in the map, so
 * foothold selection can still avoid them. */
struct FillResult {
    int nx = 0, ny = 0;
    std::vector<float> height_m;     //!< [m], NaN for Unfilled cells
    std::vector<float> sigma_m;      //!< 1-sigma [m], NaN for Unfilled cells
    std::vector<FillSource> source;  //!< where each height comes from

    /** Statistics of one run (for logs, tests and tuning). */
    struct Stats {
        int measured = 0, median = 0, gaussian = 0, unfilled = 0;  //!< cell counts
        int gapComponents = 0;         //!< connected gaps found (4-connected never-observed cells)
        int supportAreas = 0;          //!< gaps filled by a Gaussian surface
        std::vector<int> termsChosen;  //!< AIC-chosen number m of Gaussians, per support area
        int movingNeighbourhoods = 0;  //!< gaps kriged in moving neighbourhoods (tiles)
        int rimCheckHarmonic = 0;      //!< of those, gaps the rim check gave to the harmonic path
    } stats;

    size_t index(int ix, int iy) const { return size_t(iy) * size_t(nx) + size_t(ix); }
    bool isFilled(size_t k) const {
        return source[k] == FillSource::Median || source[k] == FillSource::Gaussian;
    }
};

}  // namespace multibin::fill
