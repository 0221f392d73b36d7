/* Part of the multibin elevation-mapping library. */
#pragma once

#include <memory>

#include "multibin/grid/BinGrid.h"
#include "multibin/grid/BinUpdate.h"

namespace multibin {

/** The surface estimate of one cell: what "the cell's height" means for every layer and every
 * query of the map (height, sigma, certainty; getHeight, dem_get_z, getElevation, rasters).
 *
 * The cell's winning bin (most certain, then least variance), fused (eq 15, information form)
 * with the neighbouring bins (index +-1, +-2, ... while contiguous) whose heights agree with it
 * within 3 sigma: a surface whose height lies near a bin boundary spreads its points over two
 * bins, each of which then holds a truncated, biased share; they are one hypothesis, not two.
 * Bins that disagree stay alternative hypotheses. */
struct CellSurface {
    double height_m = 0;
    double variance_m2 = 0;         //!< with the floor, and the relief if asked for [m^2]
    double certainty = 0;           //!< the certainty of the bins merged into the surface
    int firstBin = 0, lastBin = 0;  //!< the bin indices merged into the surface
    /** The pose's part of the height variance, which the surface's points share (the least
     * over its bins, Bin.h; for heightAt plus the slope's share of the horizontal part) [m^2].
     * Eq 15 fuses points as independent, so variance_m2 holds it divided among the points; a
     * pose error common to a frame (and, drifting, to the frames after it) does not average
     * away, so the variance a query reports adds it back once (reportedVariance_m2; one point
     * counts it twice: on the safe side). The fusion of bins and grids, and the gap filling,
     * weigh by variance_m2 alone (the pose error moves neighbours together), so heights are
     * what they were without it. */
    double poseVariance_m2 = 0;

    double reportedVariance_m2() const { return variance_m2 + poseVariance_m2; }
};

/** The surface of cell (ix, iy) of `grid`; false if it holds no certain bin (or lies outside
 * the window). */
bool cellSurface(const BinGrid& grid, int ix, int iy, const BinUpdateParams& params,
                 CellSurface& out);
/** The same for the cell containing (x_m, y_m). */
inline bool cellSurface(const BinGrid& grid, double x_m, double y_m, const BinUpdateParams& params,
                        CellSurface& out) {
    return cellSurface(grid, grid.cellIndex(x_m), grid.cellIndex(y_m), params, out);
}

/** Adds the relief of the cell to its variance [m^2]: the map gives one height per cell, the
 * points sample parts of it, and over a cell of side s on a slope g the heights spread with
 * variance (g s)^2 / 12 (uniform over the cell), g from the neighbours' surfaces; and the spread
 * of the cell's certain bins outside the surface (a step inside the cell). */
void addReliefVariance(const BinGrid& grid, double x_m, double y_m, const BinUpdateParams& params,
                       CellSurface& cell);

/** The map's surface at (x_m, y_m): the surface of `grid`'s cell, with its relief variance if
 * `reliefSigma`; with a dual grid (`local` not null) combined with the local grid's: agreeing
 * estimates fused by inverse variance (their data are disjoint), else the more certain one.
 * False if neither grid has a surface there. */
bool surfaceAt(const BinGrid& grid, const BinGrid* local, double x_m, double y_m,
               const BinUpdateParams& params, bool reliefSigma, CellSurface& out);

/** The sub-cell surface at (x_m, y_m): the plane of the cell's surface evaluated at the query
 * point, h + g . (q - m), with h the surface's height (eq 15) at its points' weighted centroid m
 * and g the weighted least-squares gradient of the points of the cell and of those neighbouring
 * cells (8-neighbourhood) whose surfaces agree with the cell's plane within 3 sigma both ways
 * (never across a step the bins show). The variance is var(h) + (q - m)^T C_g (q - m), C_g the
 * gradient's covariance scaled by the plane fit's residual chi^2 per degree of freedom (at least
 * 1): it grows towards the cell's edges and where the slope is uncertain; with `reliefSigma` the
 * spread of the cell's other certain bins (a step inside the cell) is added as in
 * addReliefVariance. A cell whose points give no plane (fewer than 4, or collinear) and no agreeing
 * neighbour falls back to a gradient 0 +- kUnknownSlope. The answer blends this plane with the
 * planes of the other three cells whose centres surround the point, each evaluated there, with
 * bilinear weights, a neighbour's only where it agrees with the cell's within 3 sigma (so the
 * surface is continuous across cell edges on one surface and never blends across a step); the
 * variance is the blend's weighted mean. With a dual grid, combined as surfaceAt does. The pose
 * part the points share is apart, in poseVariance_m2 (with |g|^2 times the horizontal part):
 * reportedVariance_m2() is what a query reports. False if neither grid has a surface there. */
bool heightAt(const BinGrid& grid, const BinGrid* local, double x_m, double y_m,
              const BinUpdateParams& params, bool reliefSigma, CellSurface& out);

/** heightAt over many points: the work of a cell (its surfaces, each surface's plane from its
 * neighbours) done once for the queries that read it, while the grids do not change (the
 * caller holds the map's lock). Answers bit for bit as heightAt. A grid's cells are kept in 4
 * rows of slots as wide as the queries' x span (at most the window's width and 4096 cells):
 * queries in the order of their cells (rows, then columns) compute each cell about once; any
 * order is correct. */
class HeightAtCache {
public:
    /** For queries on `grid` and, with a dual grid, `local` (null otherwise), spanning
     * `xSpan_m` in x. */
    HeightAtCache(const BinGrid& grid, const BinGrid* local, const BinUpdateParams& params,
                  double xSpan_m);
    ~HeightAtCache();
    HeightAtCache(const HeightAtCache&) = delete;
    HeightAtCache& operator=(const HeightAtCache&) = delete;

    /** heightAt(grid, local, x_m, y_m, params, reliefSigma, out). */
    bool heightAt(double x_m, double y_m, bool reliefSigma, CellSurface& out);

private:
    struct Impl;
    std::unique_ptr<Impl> m_impl;
};

/** The slope sigma assumed where no points give one [-]: 45 degrees. */
constexpr double kUnknownSlope = 1.0;

}  // namespace multibin
