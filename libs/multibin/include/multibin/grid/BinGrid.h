/* Part of the multibin elevation-mapping library. */
#pragma once

#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "multibin/geometry/Lattice.h"
#include "multibin/geometry/PointsWithCovariance.h"
#include "multibin/grid/Bin.h"
#include "multibin/grid/BinStore.h"
#include "multibin/grid/BinUpdate.h"
#include "multibin/grid/InsertStats.h"
#include "multibin/grid/VisibilityIndex.h"

namespace multibin {

class PosePropagator;
struct PoseVariances;

/** The 2.5D grid of multi-bin cells: the storage (a BinStore member: cells in tiles, bins, the
 * window), the update rule applied to points (the gates of eqs 13-14 from BinUpdate.h, each
 * bin's update through BinAccumulator.h) and the visibility index kept in step with both
 * (VisibilityIndex: update cycles, block height bounds), as OctoMap's OccupancyOcTreeBase adds its
 * update rule to the storage of OcTreeBaseImpl. The insertion on two cores runs through
 * src/grid/InsertionPipeline.h. Memory: 16 B per cell of an allocated tile (4 B store, 12 B index:
 * 64 KB per tile of 64 x 64 cells), 4 B per block of 256 cells and 64 B per bin (Bin.h). */
class BinGrid {
public:
    using BinId = BinStore::BinId;
    static constexpr BinId kNoBin = BinStore::kNoBin;
    using UpdatedCell = VisibilityIndex::UpdatedCell;
    static constexpr int kBlockShift = VisibilityIndex::kBlockShift;
    static constexpr int kBlockCells = VisibilityIndex::kBlockCells;

    explicit BinGrid(double cellSize_m = 0.02);

    /** @name Geometry and storage (BinStore's, forwarded)
     * @{ */
    const BinStore& store() const { return m_store; }
    size_t binCount() const { return m_store.binCount(); }
    static bool binIndexOf(double height_m, double binHeight_m, int16_t& n) {
        return BinStore::binIndexOf(height_m, binHeight_m, n);
    }
    double cellCenter_m(int index) const { return m_store.cellCenter_m(index); }
    int cellIndex(double coord_m) const { return m_store.cellIndex(coord_m); }
    double cellSize_m() const { return m_store.cellSize_m(); }
    /** Removes every bin of one cell; the block bounds stay conservative. */
    void clearCell(int ix, int iy) { m_store.clearCell(ix, iy); }
    /** BinStore::editBins; the block bounds stay conservative. */
    template <typename F>
    size_t editBins(int ix, int iy, F&& f) {
        return m_store.editBins(ix, iy, std::forward<F>(f));
    }
    bool empty() const { return m_store.empty(); }
    static int floorToInt(double v) { return BinStore::floorToInt(v); }
    template <typename F>
    void forEachBin(int ix, int iy, F&& f) const {
        m_store.forEachBin(ix, iy, std::forward<F>(f));
    }
    Lattice lattice() const { return m_store.lattice(); }
    const CellWindow& window() const { return m_store.window(); }
    /** @} */

    /** Drops all bins and sets an empty window; the cell size may change. */
    void reset(double cellSize_m, const CellWindow& window);
    /** Enlarges the window to include `w` (union), keeping every bin; costs nothing (tiles are
     * allocated when written). */
    void growToInclude(const CellWindow& w) { m_store.growToInclude(w); }
    /** Translates the window to a new origin, same size. Cells that leave are passed to
     * `onLeave(ix, iy)` (while still readable) and then cleared; cells still inside are untouched.
     * Tiles left outside the window are freed. Cost: proportional to the allocated tiles. */
    template <typename OnLeave>
    void moveWindowTo(int ix0, int iy0, OnLeave&& onLeave) {
        m_store.moveWindowTo(ix0, iy0, onLeave, [this](size_t s) { m_index.forgetSlot(s); });
        forgetLastTile();
    }
    void moveWindowTo(int ix0, int iy0) {
        moveWindowTo(ix0, iy0, [](int, int) {});
    }
    /** @} */

    /** @name A memory budget: tiles on disk (BinStore::spillTile)
     * A tile on disk reads as empty: it comes back on the first write into it, and by
     * reloadTilesNear before anything reads it.
     * @{ */
    /** Memory the allocated tiles, their index and the bins in use take [bytes]. */
    size_t residentBytes() const {
        return m_store.residentBytes() + m_store.tileCount() * VisibilityIndex::kBytesPerTile;
    }
    /** Writes tiles farther than `reach_m` from (x_m, y_m) [m, grid frame] to `file`, farthest
     * first, until residentBytes() <= targetBytes; returns the tiles written. */
    size_t spillFarTiles(double x_m, double y_m, double reach_m, size_t targetBytes,
                         const std::shared_ptr<TileStoreFile>& file);
    /** Reads back every tile on disk within `reach_m` of (x_m, y_m) (all with an infinite
     * reach); returns the tiles read. */
    size_t reloadTilesNear(double x_m, double y_m, double reach_m);
    /** Reads back every tile on disk (before a read of the whole grid). */
    size_t reloadAllTiles() {
        return reloadTilesNear(0, 0, std::numeric_limits<double>::infinity());
    }
    bool hasSpilledTiles() const { return m_store.spilledTileCount() > 0; }
    size_t spilledTileCount() const { return m_store.spilledTileCount(); }

    /** @name The insertion core
     * @{ */
    /** Fuses points given in the map frame (eqs 13-15). `continuityBound_m` is Delta_zmax of eq 14
     * for a laser scan, or infinity (stereo, depth: eq 13 only). `pose`: the pose's part of
     * each point's variances (PosePropagator::apply's), kept by the bins (Bin.h); without it
     * the points have none known. */
    InsertStats insertPoints(const PointsWithCov& mapPoints, const BinUpdateParams& params,
                             double continuityBound_m = std::numeric_limits<double>::infinity(),
                             const PoseVariances* pose = nullptr);
    /** The same for `count` points from `mapPoints` (and `pose`'s first `count`). */
    InsertStats insertPoints(const PointWithCov* mapPoints, size_t count,
                             const BinUpdateParams& params,
                             double continuityBound_m = std::numeric_limits<double>::infinity(),
                             const PoseVariances* pose = nullptr);

    /** Moves sensor-frame points to the map frame with `propagator` (PosePropagator::apply, on
     * blocks of 256 points) and fuses them as insertPoints does, so the map-frame batch never
     * exists in memory: a 640 x 480 frame then streams 11 MB once instead of three times. The
     * result is bit-identical to apply() followed by insertPoints(): the same per-point
     * arithmetic in the same order (a run of points in one bin stays open across blocks). */
    InsertStats insertSensorPoints(
        const PosePropagator& propagator, const PointsWithCov& sensorPoints,
        const BinUpdateParams& params,
        double continuityBound_m = std::numeric_limits<double>::infinity());

    /** Threads of the insertion core (1 or 2): with 2, an observation of many points (at least
     * 16 blocks of 256) is propagated and classified on a helper thread while this thread
     * updates the bins in point order: the same bins bit for bit, on two cores. 1 by default. */
    void setInsertionThreads(int threads) { m_insertionThreads = threads; }

    /** Fuses one height measurement into cell (ix, iy), which must be inside the window.
     * Returns false if a gate refused it (counted in `stats`). */
    bool insertHeight(int ix, int iy, double height_m, double variance_m2,
                      const BinUpdateParams& params, double continuityBound_m, InsertStats& stats);

    /** Fuses a bin estimated elsewhere (another grid) into cell (ix, iy): Kalman fusion of its
     * height and variance, certainty and point count added; no gates. The cell must be inside the
     * window. */
    void fuseBin(int ix, int iy, const BinEstimate& other, const BinUpdateParams& params);
    /** Appends a bin as stored elsewhere (deserialization, grid-to-grid copies). */
    void appendBin(int ix, int iy, const BinEstimate& bin);
    /** @} */

    /** The cell's winning bin: most certain, ties broken by the lower variance; nullptr if the cell
     * has no bin with certainty > 0 or is outside the window. */
    const Bin* winningBin(int ix, int iy) const;
    /** Whether bin b wins over `best` (nullptr: none yet) by winningBin()'s rule. */
    static bool winsOver(const Bin& b, const Bin* best) {
        return b.certainty > 0 &&
               (!best || b.certainty > best->certainty ||
                (b.certainty == best->certainty && b.variance_m2 < best->variance_m2));
    }

    /** @name The visibility index (VisibilityIndex)
     * @{ */
    const VisibilityIndex& visibilityIndex() const { return m_index; }
    /** Starts a new update cycle: forgets which cells were updated. */
    void beginCycle() { m_index.beginCycle(); }
    const std::vector<UpdatedCell>& updatedCells() const { return m_index.updatedCells(); }
    bool updatedThisCycle(int ix, int iy) const {
        return window().contains(ix, iy) && m_index.updatedThisCycle(m_store.slot(ix, iy));
    }
    /** See VisibilityIndex::cellMaxHeight_m; -infinity outside the window. */
    float cellMaxHeight_m(int ix, int iy) const {
        return window().contains(ix, iy) ? m_index.cellMaxHeight_m(m_store.slot(ix, iy))
                                         : -std::numeric_limits<float>::infinity();
    }
    /** Highest bin height ever stored (an upper bound on every bin's height) [m]. */
    double maxHeight_m() const { return m_index.maxHeight_m(); }
    /** See VisibilityIndex::noteClearance; nothing outside the window or in an unallocated tile. */
    void noteClearance(int ix, int iy, double height_m) {
        if (window().contains(ix, iy))
            m_index.noteClearance(m_store.slot(ix, iy), static_cast<float>(height_m));
    }
    /** See VisibilityIndex::clearance_m; +infinity outside the window. */
    float clearance_m(int ix, int iy) const {
        return window().contains(ix, iy) ? m_index.clearance_m(m_store.slot(ix, iy))
                                         : std::numeric_limits<float>::infinity();
    }
    static int blockOf(int cellIndex) { return VisibilityIndex::blockOf(cellIndex); }
    /** See VisibilityIndex::blockMaxHeight_m. */
    float blockMaxHeight_m(int bx, int by) const {
        constexpr int kShift = BinStore::kTileShift - kBlockShift;  // blocks to tiles
        return m_index.blockMaxHeight_m(m_store.tileNumber(bx >> kShift, by >> kShift), bx, by);
    }
    /** @} */

    /** Memory held by the grid [bytes]: the store and the visibility index. Independent of the
     * vertical extent. */
    size_t memoryBytes() const { return m_store.memoryBytes() + m_index.memoryBytes(); }

    /** Standard deviation of a bin's estimate (binSigma_m) [m]. */
    static double sigma_m(const BinEstimate& b, const BinUpdateParams& p) {
        return binSigma_m(b, p);
    }

private:
    /** The insertion core over `count` map-frame points, a block at a time:
     * `fillBlock(begin, n, block)` writes points begin .. begin + n - 1 into `block`. */
    /** The slot of cell (ix, iy) for a write: its tile allocated (and indexed) if it had none.
     * Consecutive points mostly share a tile: the last one is remembered. */
    size_t writableSlot(int ix, int iy) {
        if (BinStore::tileOf(ix) == m_lastTileX && BinStore::tileOf(iy) == m_lastTileY)
            return m_lastTileBase + BinStore::slotInTile(ix, iy);
        return writableSlotInNewTile(ix, iy);
    }
    size_t writableSlotInNewTile(int ix, int iy);
    /** Forgets the remembered tile (tiles were freed or dropped). */
    void forgetLastTile() { m_lastTileX = std::numeric_limits<int>::min(); }
    template <typename BlockSource>
    InsertStats insertBlocks(size_t count, BlockSource&& fillBlock, const BinUpdateParams& params,
                             double continuityBound_m);
    /** Gates 13 and bin range passed: eq 14 and the per-point update (eq 15, BinAccumulator) of
     * bin n of cell (ix, iy) at `slot`; `weight` = 1 / variance_m2. */
    bool fuseMeasurement(size_t slot, int ix, int iy, int16_t n, double height_m,
                         double variance_m2, double weight, const BinUpdateParams& params,
                         double continuityBound_m, InsertStats& stats, float x_m,
                         float y_m,  //!< its place feeds the plane moments; NaN: no place
                         uint8_t poseHeightCode,  //!< poseSigmaCode of its pose parts; 0: none
                         uint8_t poseHorizontalCode);

    BinStore m_store;
    VisibilityIndex m_index;
    /** The tile of the last write and its first slot (writableSlot). */
    int m_lastTileX = std::numeric_limits<int>::min(), m_lastTileY = 0;
    size_t m_lastTileBase = 0;
    int m_insertionThreads = 1;
};

}  // namespace multibin
