/* Part of the multibin elevation-mapping library. */
#pragma once

#include <vector>

#include "multibin/fill/FillOptions.h"
#include "multibin/fill/GaussianSurface.h"
#include "multibin/fill/HeightRaster.h"

namespace multibin::fill {

/** A measured cell of a support area as training point of eq 16, with its distance to the gap
 * (8-neighbour steps; 1 for a cell touching the gap) [cells]. */
struct TrainingPoint {
    SurfaceSample s;
    int gapDist = 0;
};

/** The square support area around one gap (DESIGN.md "Gap filling"): the gap's bounding square
 * plus supportMargin_cells on each side, slid inside the raster. Sample coordinates (i, j) are
 * support-area cells: raster column sx + i, row sy + j. */
struct SupportArea {
    std::vector<int> cells;     //!< the gap's cells (raster indices)
    int x0 = 0, x1 = 0;         //!< the gap's columns [raster cells]
    int y0 = 0, y1 = 0;         //!< the gap's rows [raster cells]
    int side = 0;               //!< side of the square [cells]
    int sx = 0, sy = 0;         //!< its first column and row [raster cells]
    int ex = 0, ey = 0;         //!< one past its last column and row, clipped to the raster
    double gapI = 0, gapJ = 0;  //!< centre of the gap's bounding box [support-area cells]
    /** The training points: the measured cells of the area, at most maxTrainingPoints of them,
     * nearest the gap first (see keepNearestToGap). */
    std::vector<TrainingPoint> training;
    std::vector<SurfaceSample> samples;    //!< the training points' samples
    std::vector<SurfaceSample> all;        //!< every measured cell of the area
    std::vector<SurfaceSample> rim;        //!< of those, the ones within 2 cells of the gap
    std::vector<SurfaceSample> beyondRim;  //!< the others
    double heightLo_m = 0, heightHi_m = 0;  //!< range of the training heights [m]

    /** Column and row of gap cell `c` (an index into `cells`) [support-area cells]. */
    int i(size_t c) const;
    int j(size_t c) const;
    /** Raster index of support-area cell (i, j). */
    int rasterIndex(int i, int j) const { return (sy + j) * m_nx + (sx + i); }
    /** Filled heights are kept within the training heights' range widened by this [m]. */
    double slack_m(const FillOptions& o) const {
        return o.extrapolationMargin * (heightHi_m - heightLo_m);
    }

    /** The area around `cells` (one gap of `raster`). */
    SupportArea(const HeightRaster& raster, const FillOptions& options, std::vector<int> cells);

private:
    int m_nx = 0;
};

/** Cuts `points` to the `count` nearest the gap. Where the cut falls inside a ring (more points
 * at the cut-off distance than places left), the places go to points evenly spread by angle
 * about the gap's centre (ci, cj), so the kept points still surround the gap: the raster order
 * would keep one side of a long rim only. */
void keepNearestToGap(std::vector<TrainingPoint>& points, size_t count, double ci, double cj);

/** The `count` training points of `area` nearest its gap (keepNearestToGap), as samples. */
std::vector<SurfaceSample> nearestToGap(const SupportArea& area, size_t count);

/** Empirical semivariogram gamma(h) = 0.5 mean (z(x) - z(x + h))^2 [m^2] of the measured cells
 * inside the box x0 <= ix < x0 + w, y0 <= iy < y0 + h (clipped to the raster), for lags
 * h = 1 .. maxLag cells along rows and columns; gamma[0] = 0. A lag with no pair takes the
 * previous lag's value. */
std::vector<double> semivariogram(const HeightRaster& raster, int x0, int y0, int w, int h,
                                  int maxLag);

}  // namespace multibin::fill
