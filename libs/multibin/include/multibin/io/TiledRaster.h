/* Part of the multibin elevation-mapping library. */
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "multibin/geometry/Lattice.h"
#include "multibin/io/EsriAsciiGrid.h"

namespace multibin {

/** A raster layer read tile by tile, so its outputs cost what the data covers, not its bounding
 * box: a long diagonal route's window is mostly empty.
 *
 * Cells are those of a map lattice: cell (ix, iy) is centred at
 * (originX_m + (ix + 0.5) cellSize_m, originY_m + (iy + 0.5) cellSize_m) in the output frame.
 * Tiles are tileCells x tileCells cells aligned on multiples of tileCells (tile (tx, ty) holds
 * cells tx tileCells .. (tx + 1) tileCells - 1 in x, the same in y); `tiles` lists those that may
 * hold a known sample, every other sample is unknown. */
struct TiledRaster {
    double cellSize_m = 1;
    double originX_m = 0, originY_m = 0;  //!< the frame position of cell (0, 0)'s corner [m]
    int tileCells = 256;
    std::vector<CellWindow> tiles;  //!< aligned, tileCells x tileCells each, no duplicates
    /** The samples over a window of cells (any window), NaN where unknown. */
    std::function<EsriAsciiGrid(const CellWindow&)> samples;
    /** A visitor of a sample: cell (ix, iy), its value. */
    using SampleVisit = std::function<void(int ix, int iy, float value)>;
    /** Optional (rasters kept sparse, knownLayers() in MapLayerFiles.h): visits the known samples
     * of tile `tile` (one of `tiles`) inside `window`, row by row from the south, west to east
     * (the order of samples()); knownCells() and blockReduced() then cost the known samples, not
     * the tiles' cells. */
    std::function<void(const CellWindow& tile, const CellWindow& window, const SampleVisit&)>
        knownSamples;

    /** The smallest window holding every tile (empty without tiles). */
    CellWindow tileBounds() const;
    /** The bounding box of the known samples, read tile by tile (one tile in memory; from
     * each side inwards, so mostly the tiles at the extremes); empty (nx = ny = 0) when no
     * sample is known. */
    CellWindow knownCells() const;
    /** Centre of cell (ix, iy) [m, output frame]. */
    double cellCenterX_m(int ix) const { return originX_m + (ix + 0.5) * cellSize_m; }
    double cellCenterY_m(int iy) const { return originY_m + (iy + 0.5) * cellSize_m; }
};

/** What the calling thread's raster reads cost (CMultiBinElevationMap::toRasters() and the
 * outputs built on it): the cells they visited, counted from the thread's start or the last
 * reset, so a test checks that an output's work follows the tiles holding data, not the window.
 */
struct RasterReadCounters {
    size_t cellsVisited = 0;  //!< cells of tiles holding data inside the windows read
};
/** This thread's counters (thread_local). */
RasterReadCounters& rasterReadCounters();

/** The aligned tile holding cell (ix, iy). */
CellWindow tileOfCell(int ix, int iy, int tileCells);

/** How blockReduced() merges a block's known samples into one. */
enum class BlockReduce {
    Mean,  //!< continuous layers: the mean of the known samples
    Max    //!< the largest (sigma: the worst; source: filled when any cell is)
};

/** The raster over `window` with one sample per `factor` x `factor` block of cells (blocks
 * aligned on the window's lower-left corner), unknown where the block holds no known sample;
 * built tile by tile (one tile and the result in memory). factor 1 is the raster itself. */
EsriAsciiGrid blockReduced(const TiledRaster& raster, const CellWindow& window, int factor,
                           BlockReduce how);
/** The same for several rasters over the same tiles, in one loop over the tiles (each tile read
 * from every raster in turn). */
std::vector<EsriAsciiGrid> blockReduced(const std::vector<TiledRaster>& rasters,
                                        const CellWindow& window, int factor,
                                        const std::vector<BlockReduce>& how);

/** The smallest block side (>= 1) that brings `window` within maxSide_px on its long side. */
int blockFactorFor(const CellWindow& window, int maxSide_px);

/** The most cells the dense outputs (ESRI ASCII, PLY, super-sampled rasters) take: 4096 x 4096
 * (64 MB a float layer, about 150 MB of ESRI ASCII text). */
constexpr uint64_t kMaxDenseOutputCells = uint64_t(4096) * 4096;

/** Throws std::invalid_argument when `cells` exceeds kMaxDenseOutputCells: "OUTPUT: the map's
 * known area spans NX x NY cells (...), more than ...; ALTERNATIVE". */
void checkDenseOutputFits(const CellWindow& cells, double cellSize_m, const std::string& output,
                          const std::string& alternative);

}  // namespace multibin
