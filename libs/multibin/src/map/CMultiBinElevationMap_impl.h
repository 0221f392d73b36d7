/* Part of the multibin elevation-mapping library.
 * CMultiBinElevationMap's state, kept out of the public header (which shows only the map, its
 * option structs and plain result types). Included by the map's own source files only. */
#pragma once

#include <mrpt/maps/CMultiBinElevationMap.h>

#include <array>
#include <cstdint>
#include <mutex>
#include <optional>

#include "MapLock.h"
#include "TraversabilityCache.h"
#include "multibin/fill/HeightRaster.h"
#include "multibin/fill/SparseFill.h"
#include "multibin/geometry/Lattice.h"
#include "multibin/grid/BinGrid.h"
#include "multibin/sensors/SensorDispatch.h"

namespace mrpt::maps {

struct CMultiBinElevationMap::Impl {
    multibin::BinGrid grid;   //!< the single grid, or the global grid of the dual grid
    multibin::BinGrid local;  //!< dual grid only: the precise local grid
    /** The map origin [m, pose frame]: cells and map-frame points are relative to it. Not yet
     * fixed when automatic and nothing was inserted. */
    Eigen::Vector2d origin_m{0, 0};
    bool originFixed = false;
    multibin::InsertStats stats;
    multibin::VisibilityStats visibilityStats;
    size_t poseFallbacks = 0;
    size_t skippedByLabel = 0;
    size_t nonFinitePoses = 0;  //!< observations refused for a NaN or infinite robot pose
    /** The latest CObservationRobotPose: its PDF and timestamp. */
    std::optional<mrpt::poses::CPose3DPDFGaussian> lastRobotPose;
    mrpt::Clock::time_point lastRobotPoseTime;
    /** Previous laser scans (eq 14), stereo covariance table, sensor statistics. */
    multibin::sensors::SensorModelState sensorState;
    /** The last gap filling's filled cells, over fillWindow of grid (absolute cell indices): what
     * the queries and rasters read. */
    multibin::fill::FilledCells filled;
    /** The same as one raster over fillWindow, for lastFill() only: built on its first call
     * (9 B per window cell, which the mapper and the queries never pay), under fillRasterMutex;
     * statistics only until then and beyond kMaxWholeWindowCells. */
    multibin::fill::FillResult fill;
    bool fillRasterBuilt = false;
    /** Readers share the map's lock: the first lastFill() builds `fill` under this one. */
    struct CopyableMutex {
        std::mutex m;
        CopyableMutex() = default;
        CopyableMutex(const CopyableMutex&) {}
        CopyableMutex& operator=(const CopyableMutex&) { return *this; }
    } fillRasterMutex;
    multibin::CellWindow fillWindow;
    bool fillStale = true;
    /** One writer or concurrent readers: every public entry point takes it (MapLock.h). */
    multibin::MapLock lock;
    /** The memory budget (CMultiBinElevationMap_budget.cpp): the scratch file of the tiles on
     * disk, created on the first tile written; the most the grid took; warned once. */
    std::shared_ptr<multibin::TileStoreFile> tileFile;
    size_t peakResidentBytes = 0;
    bool budgetWarned = false;
    /** One edge of the window in the pose frame [m]: 0 x min, 1 x max, 2 y min, 3 y max. The
     * caller holds `lock` (growth moves the window). */
    double windowEdge_m(int edge) const {
        return (edge < 2 ? origin_m.x() : origin_m.y()) + grid.lattice().area_m()[edge];
    }
    /** Whether cell (ix, iy) of `grid` holds a bin, or with the dual grid the local grid's cell at
     * its centre does: a cell without is unknown, skipped without a surface query. */
    bool holdsBins(int ix, int iy, bool dual) const {
        bool any = false;
        grid.forEachBin(ix, iy, [&](const multibin::Bin&) { any = true; });
        if (!any && dual)
            local.forEachBin(local.cellIndex(grid.cellCenter_m(ix)),
                             local.cellIndex(grid.cellCenter_m(iy)),
                             [&](const multibin::Bin&) { any = true; });
        return any;
    }
    /** holdsBins() over the cells of one 64 x 64 tile of `grid`'s store: the tile is found once
     * (a directory lookup), not per cell; with the dual grid, holdsBins() itself. */
    class TileBins {
    public:
        TileBins(const Impl& impl, int tx, int ty, bool dual)
            : m_impl(impl),
              m_dual(dual),
              m_tile(impl.grid.store().tileNumber(tx, ty)),
              m_base(multibin::BinStore::tileBase(m_tile)),
              m_inside(wholeInside(impl.grid.store().window(), tx, ty)) {}
        /** Whether the tile holds no bin (not allocated) and the dual grid is off. */
        bool empty() const { return !m_dual && m_tile == 0; }
        /** holdsBins(ix, iy, dual) for a cell of this tile: without the dual grid, a look at
         * the cell's slot (a tile inside the store's window needs no window test per cell). */
        bool holds(int ix, int iy) const {
            if (m_dual) return m_impl.holdsBins(ix, iy, true);
            const multibin::BinStore& s = m_impl.grid.store();
            return m_tile != 0 && (m_inside || s.window().contains(ix, iy)) &&
                   s.slotHoldsBins(m_base + multibin::BinStore::slotInTile(ix, iy));
        }
        /** Calls f(ix, iy), row by row, for the cells of [xa, xb) x [ya, yb) (within this tile)
         * that hold bins (holds()) or for which also(ix, iy) is true; also() is asked only if
         * `alsoAny` (it may hold somewhere in the tile). Without the dual grid the cells holding
         * bins come from the store's row bits (BinStore::rowHoldingBins()), a word per row, and
         * are picked before f is called: most cells of a sparse route's tiles are empty. */
        template <typename Also, typename F>
        void forEachHeld(int xa, int xb, int ya, int yb, bool alsoAny, Also&& also, F&& f) const {
            if (m_dual || !m_inside) {
                for (int iy = ya; iy < yb; iy++)
                    for (int ix = xa; ix < xb; ix++)
                        if (holds(ix, iy) || (alsoAny && also(ix, iy))) f(ix, iy);
                return;
            }
            if (m_tile == 0 && !alsoAny) return;
            constexpr int kSide = multibin::BinStore::kTileCells;
            std::array<uint16_t, multibin::BinStore::kTileSlots> picked;  // (iy, ix) in the tile
            size_t n = 0;
            const multibin::BinStore& s = m_impl.grid.store();
            const int x0 = xa & ~(kSide - 1), y0 = ya & ~(kSide - 1);  // the tile's first cell
            const int width = xb - xa;  // the columns [xa, xb) as bits
            const uint64_t columns = (width >= 64 ? ~uint64_t(0) : (uint64_t(1) << width) - 1)
                                     << (xa - x0);
            for (int iy = ya; iy < yb; iy++) {
                uint64_t held = m_tile != 0 ? s.rowHoldingBins(m_tile, iy - y0) & columns : 0;
                if (!alsoAny) {  // the row's cells holding bins, from its bits
                    for (; held != 0; held &= held - 1)
                        picked[n++] = uint16_t((iy - y0) * kSide + __builtin_ctzll(held));
                    continue;
                }
                for (int ix = xa; ix < xb; ix++) {
                    picked[n] = uint16_t((iy - y0) * kSide + (ix - x0));
                    n += ((held >> (ix - x0)) & 1) != 0 || also(ix, iy);
                }
            }
            for (size_t i = 0; i < n; i++) f(x0 + picked[i] % kSide, y0 + picked[i] / kSide);
        }
        /** Whether tile (tx, ty)'s cells all lie in window w. */
        static bool wholeInside(const multibin::CellWindow& w, int tx, int ty) {
            constexpr int k = multibin::BinStore::kTileCells;
            return w.contains(tx * k, ty * k) && w.contains(tx * k + k - 1, ty * k + k - 1);
        }

    private:
        const Impl& m_impl;
        bool m_dual;
        uint32_t m_tile;
        size_t m_base;
        bool m_inside;
    };
    /** The traversability layers (CMultiBinElevationMap_traversability.cpp). */
    multibin::TraversabilityCache traversability;
};

}  // namespace mrpt::maps
