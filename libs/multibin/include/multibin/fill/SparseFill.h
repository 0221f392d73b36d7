/* Part of the multibin elevation-mapping library. */
#pragma once

#include <limits>

#include "multibin/fill/FillOptions.h"
#include "multibin/fill/HeightRaster.h"
#include "multibin/fill/TiledCells.h"
#include "multibin/geometry/Lattice.h"

namespace multibin::fill {

/** A cell of the sparse input, as HeightRaster holds it: measured when certainty > 0 and height
 * and sigma are finite, sigma > 0. */
struct MeasuredCell {
    float height_m = std::numeric_limits<float>::quiet_NaN();  //!< [m]
    float sigma_m = std::numeric_limits<float>::quiet_NaN();   //!< 1-sigma [m]
    float certainty = 0;                                       //!< [-]; 0 = never observed
};

/** The input of gap filling over a window that may be huge and mostly empty (a long route's box):
 * the measured cells, tile by tile; a cell never set is a gap cell. Cells are absolute lattice
 * indices (lattice.window's, not raster columns); a cell outside the window is part of no gap. */
struct SparseHeights {
    Lattice lattice;  //!< the window and the cell size
    TiledCells<MeasuredCell> cells;

    /** Marks cell (ix, iy) (absolute, inside the window) measured (certainty 1 if c <= 0). */
    void setMeasured(int ix, int iy, float h_m, float sigma_m, float c = 1.0f);
    /** As HeightRaster::isMeasured; false outside the window. */
    bool isMeasured(int ix, int iy) const;
    /** The dense raster over window `w` (absolute cells, inside lattice.window): the whole-window
     * input of fillGaps(), or the raster around one gap. */
    HeightRaster toRaster(const CellWindow& w) const;
};

/** A filled cell of the sparse result. */
struct FilledCell {
    float height_m = std::numeric_limits<float>::quiet_NaN();  //!< [m]
    float sigma_m = std::numeric_limits<float>::quiet_NaN();   //!< 1-sigma [m]
    HeightSource source = HeightSource::Unknown;               //!< Filled*, or Unknown
};

/** The result of fillSparse(): the filled cells only, tile by tile (measured cells are the
 * input's, every other cell is Unknown), so its memory follows the filled cells. */
struct FilledCells {
    Lattice lattice;  //!< the input's
    TiledCells<FilledCell> cells;
    FillResult::Stats stats;  //!< as fillGaps() counts them (gapComponents: see fillSparse())

    /** The filled cell (ix, iy) (absolute), or nullptr if it is not filled. */
    const FilledCell* find(int ix, int iy) const {
        const FilledCell& c = cells.get(ix, iy);
        return c.source == HeightSource::Unknown ? nullptr : &c;
    }
    /** Calls f(ix, iy, const FilledCell&) for every filled cell, tile by tile. */
    template <typename F>
    void forEachFilled(F&& f) const {
        cells.forEachTile([&](int tx, int ty, const FilledCell* t) {
            for (size_t k = 0; k < TiledCells<FilledCell>::kTileCells; k++)
                if (t[k].source != HeightSource::Unknown)
                    f(tx * TiledCells<FilledCell>::kSide + int(k % TiledCells<FilledCell>::kSide),
                      ty * TiledCells<FilledCell>::kSide + int(k / TiledCells<FilledCell>::kSide),
                      t[k]);
        });
    }
    /** The dense result over the whole window with `in`'s measured cells, as fillGaps() returns
     * it (the same bits): for callers that index a raster. O(window). */
    FillResult toResult(const SparseHeights& in) const;
};

/** Gap filling whose cost follows the data, not the window: the same heights, sigmas and sources
 * as fillGaps(in.toRaster(window)) (and the same per-gap statistics, in the same order).
 *
 * The gaps are found by flood fill from the unmeasured cells next to measured ones; a flood stops
 * when it passes options.maxGapCells cells or reaches a cell of a region already found larger
 * (those cells are marked), so the search visits the cells within about sqrt(maxGapCells) of the
 * data. Each gap is then filled by the whole-window path's own per-gap code on a raster around it:
 * its bounding box widened by what that code reads (the support square wherever it slides, the
 * median window, the shadow test's reach), clipped to the window as the whole-window raster is.
 * stats.gapComponents counts the gaps of at most maxGapCells cells plus the larger regions as the
 * floods met them (one region reached by floods that never met counts more than once);
 * stats.cellsVisited the cells flooded plus those of the per-gap rasters. */
FilledCells fillSparse(const SparseHeights& in, const FillOptions& options);

}  // namespace multibin::fill
