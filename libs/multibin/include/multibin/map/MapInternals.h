/* Part of the multibin elevation-mapping library. */
#pragma once

#include <mrpt/maps/CMultiBinElevationMap.h>

#include "multibin/fill/HeightRaster.h"
#include "multibin/grid/BinGrid.h"

namespace multibin {

/** The map's parts, for tests and tools that check the map against them (the bins of its
 * grids, the last gap filling as one raster). Applications read the map through its queries,
 * statistics() and rasters. The references are not guarded by the map's lock: use them from
 * the writer thread or while no one writes. */
struct MapInternals {
    using Map = mrpt::maps::CMultiBinElevationMap;
    /** The grid (the global one with the dual grid). */
    static const BinGrid& grid(const Map& map) { return map.grid(); }
    /** The precise local grid (empty unless dual grid). */
    static const BinGrid& localGrid(const Map& map) { return map.localGrid(); }
    /** The last gap filling's result over the window it ran on, as one raster (stats only
     * beyond Map::kMaxWholeWindowCells). */
    static const fill::FillResult& lastFill(const Map& map) { return map.lastFill(); }
    /** True when observations arrived after the last gap filling. */
    static bool fillIsStale(const Map& map) { return map.fillIsStale(); }
};

}  // namespace multibin
