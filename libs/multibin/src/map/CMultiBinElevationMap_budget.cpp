/* Part of the multibin elevation-mapping library.
 * CMultiBinElevationMap: the memory budget (TCreationOptions::memory_budget_mb). After an
 * insertion, tiles far from the sensor go to a scratch file (BinStore::spillTile); an insertion
 * brings back those within its reach first, and a read brings back all of them, so every
 * operation sees the same bins as without a budget. */
#include "CMultiBinElevationMap_impl.h"

#include <algorithm>
#include <iostream>

using namespace mrpt::maps;

namespace {
/** What an insertion from a sensor may read or write: max_range_m, plus a tile for the cells
 * that the points' cells and the rays' cells overlap. */
double insertionReach_m(double maxRange_m, double cellSize_m) {
    return maxRange_m + multibin::BinStore::kTileCells * cellSize_m;
}
}  // namespace

void CMultiBinElevationMap::prepareForReading() const {
    // Inside another entry point the lock is held: the outermost one has prepared.
    if (m_impl->lock.heldByThisThread()) return;
    bool spilled;
    {
        const multibin::MapLock::Shared lock(m_impl->lock);
        spilled = m_impl->grid.hasSpilledTiles();
    }
    if (spilled) {
        const multibin::MapLock::Exclusive lock(m_impl->lock);
        m_impl->grid.reloadAllTiles();
    }
    fillIfLoaded();
}

void CMultiBinElevationMap::reloadTilesInReach(multibin::BinGrid& grid,
                                               const Eigen::Vector3d& sensor_m) {
    if (&grid != &m_impl->grid || !grid.hasSpilledTiles()) return;
    grid.reloadTilesNear(sensor_m.x(), sensor_m.y(),
                         insertionReach_m(insertionOptions.max_range_m, grid.cellSize_m()));
}

void CMultiBinElevationMap::keepWithinMemoryBudget(const Eigen::Vector3d& sensor_m) {
    const double budget_mb = creationOptions.memory_budget_mb;
    if (!(budget_mb > 0)) return;
    multibin::BinGrid& grid = m_impl->grid;
    const size_t budgetBytes = size_t(budget_mb * 1e6);
    m_impl->peakResidentBytes = std::max(m_impl->peakResidentBytes, grid.residentBytes());
    if (grid.residentBytes() <= budgetBytes) return;
    if (!m_impl->tileFile)
        m_impl->tileFile =
            std::make_shared<multibin::TileStoreFile>(creationOptions.tile_store_dir);
    // Down to 3/4 of the budget, so that the next insertions do not each write a tile.
    grid.spillFarTiles(sensor_m.x(), sensor_m.y(),
                       insertionReach_m(insertionOptions.max_range_m, grid.cellSize_m()),
                       budgetBytes / 4 * 3, m_impl->tileFile);
    if (grid.residentBytes() > budgetBytes && !m_impl->budgetWarned) {
        m_impl->budgetWarned = true;
        std::cerr << "CMultiBinElevationMap: memory_budget_mb = " << budget_mb
                  << " is below what the ground within max_range_m ("
                  << insertionOptions.max_range_m << " m) of the sensor takes ("
                  << grid.residentBytes() / 1e6
                  << " MB): that ground stays in memory; raise memory_budget_mb\n";
    }
}

CMultiBinElevationMap::TileStoreStats CMultiBinElevationMap::tileStoreStats() const {
    const multibin::MapLock::Shared lock(m_impl->lock);
    TileStoreStats s;
    s.tilesWritten = m_impl->grid.store().tilesSpilled();
    s.tilesRead = m_impl->grid.store().tilesReloaded();
    s.tilesOnDisk = m_impl->grid.spilledTileCount();
    s.peakResidentBytes = std::max(m_impl->peakResidentBytes, m_impl->grid.residentBytes());
    return s;
}
