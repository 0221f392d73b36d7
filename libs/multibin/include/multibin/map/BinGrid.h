/* Part of the multibin elevation-mapping library. */
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "multibin/geometry/Lattice.h"
#include "multibin/geometry/PointsWithCovariance.h"
#include "multibin/map/MapTypes.h"

namespace multibin {

class PosePropagator;

/** One vertical bin of a cell: a certainty counter and a 1-D Kalman height estimate (eq 15).
 * 24 bytes; bins live in a pool shared by all cells, chained per cell. */
struct Bin {
    float height_m = 0;     //!< Kalman height estimate [m]
    float variance_m2 = 0;  //!< Kalman variance, without the floor [m^2]
    float certainty = 0;    //!< certainty counter c (eqs 13-14)
    uint32_t pointCount = 0;
    int16_t index = 0;  //!< vertical bin index n: covers [n, n+1) * binHeight [m]
    uint16_t reserved = 0;
    uint32_t next = 0;  //!< next bin of the same cell in the pool, or BinGrid::kNoBin
};
static_assert(sizeof(Bin) == 24, "a bin must stay within 24 bytes");

/** The 2.5D grid of multi-bin cells with the shared insertion core.
 *
 * Storage is a circular buffer over the cell window (grid_map style): cell (ix, iy) lives in slot
 * (ix mod nx) + (iy mod ny) nx, so moving the window only clears the slots of the cells that enter,
 * and growing it re-slots the cell heads without touching any bin. Memory: 12 B per cell of the
 * window (chain head, update-cycle stamp and index), 12 B per block of 256 cells (local height
 * bound) and 24 B per bin. */
class BinGrid {
public:
    static constexpr uint32_t kNoBin = std::numeric_limits<uint32_t>::max();

    explicit BinGrid(double cellSize_m = 0.02);

    double cellSize_m() const { return m_cellSize_m; }
    const CellWindow& window() const { return m_window; }
    /** The grid's cells as the library's one lattice type (cell size and window). */
    Lattice lattice() const { return Lattice{m_cellSize_m, m_window}; }
    /** Index of the cell containing a coordinate [m]; clamped far outside any window, so
     * absurd coordinates never overflow (NaN gives the upper limit). */
    int cellIndex(double coord_m) const {
        constexpr double kLimit = std::numeric_limits<int>::max() / 4;
        double f = coord_m * m_invCellSize;
        if (!(f < kLimit)) f = kLimit;  // also NaN
        if (f < -kLimit) f = -kLimit;
        return floorToInt(f);
    }
    /** Vertical bin index of a height [m]: floor(height / binHeight); false if it does not fit
     * the int16 bin index (or is NaN). */
    static bool binIndexOf(double height_m, double binHeight_m, int16_t& n) {
        const double q = height_m / binHeight_m;
        if (!(q >= std::numeric_limits<int16_t>::min() &&
              q < double(std::numeric_limits<int16_t>::max()) + 1.0))
            return false;
        n = static_cast<int16_t>(floorToInt(q));
        return true;
    }
    /** floor(v) for finite |v| < 2^31, without a libm call (baseline x86-64 has no SSE4.1
     * rounding instruction). */
    static int floorToInt(double v) {
        const int t = static_cast<int>(v);  // truncates towards zero
        return t - (v < double(t) ? 1 : 0);
    }
    double cellCenter_m(int index) const { return (index + 0.5) * m_cellSize_m; }

    /** Drops all bins and sets an empty window; the cell size may change. */
    void reset(double cellSize_m, const CellWindow& window);
    /** Enlarges the window to include `w` (union), keeping every bin. */
    void growToInclude(const CellWindow& w);
    /** Translates the window to a new origin, same size. Cells that leave are passed to
     * `onLeave(ix, iy)` (while still readable) and then cleared; cells still inside are untouched.
     * Cost: proportional to the cells that enter. */
    template <typename OnLeave>
    void moveWindowTo(int ix0, int iy0, OnLeave&& onLeave);
    void moveWindowTo(int ix0, int iy0) {
        moveWindowTo(ix0, iy0, [](int, int) {});
    }

    /** Fuses points given in the map frame (eqs 13-15). `continuityBound_m` is Delta_zmax of eq 14
     * for a laser scan, or infinity (stereo, depth: eq 13 only). */
    InsertStats insertPoints(const PointsWithCov& mapPoints, const BinUpdateParams& params,
                             double continuityBound_m = std::numeric_limits<double>::infinity());
    /** The same for `count` points from `mapPoints`. */
    InsertStats insertPoints(const PointWithCov* mapPoints, size_t count,
                             const BinUpdateParams& params,
                             double continuityBound_m = std::numeric_limits<double>::infinity());

    /** Moves sensor-frame points to the map frame with `propagator` (PosePropagator::apply) and
     * fuses them (insertPoints), 256 points at a time, so the map-frame batch never exists in
     * memory: a 640 x 480 frame then streams 11 MB once instead of three times. The result is
     * bit-identical to apply() followed by insertPoints(): the same per-point arithmetic in the
     * same order (a run of points in one bin stays open across blocks). */
    InsertStats insertSensorPoints(
        const PosePropagator& propagator, const PointsWithCov& sensorPoints,
        const BinUpdateParams& params,
        double continuityBound_m = std::numeric_limits<double>::infinity());

    /** Fuses one height measurement into cell (ix, iy), which must be inside the window.
     * Returns false if a gate refused it (counted in `stats`). */
    bool insertHeight(int ix, int iy, double height_m, double variance_m2,
                      const BinUpdateParams& params, double continuityBound_m, InsertStats& stats);

    /** Fuses a bin estimated elsewhere (another grid) into cell (ix, iy): Kalman fusion of its
     * height and variance, certainty and point count added; no gates. The cell must be inside the
     * window. */
    void fuseBin(int ix, int iy, const Bin& other, const BinUpdateParams& params);

    /** The cell's winning bin: most certain, ties broken by the lower variance; nullptr if the cell
     * has no bin with certainty > 0 or is outside the window. */
    const Bin* winningBin(int ix, int iy) const;

    /** Calls f(const Bin&) for every bin of the cell (any certainty). */
    template <typename F>
    void forEachBin(int ix, int iy, F&& f) const {
        if (!m_window.contains(ix, iy)) return;
        for (uint32_t b = m_cells[slot(ix, iy)].head; b != kNoBin; b = m_pool[b].next) f(m_pool[b]);
    }

    /** Calls f(Bin&) for every bin of the cell; a bin for which f returns false is removed.
     * Returns the number of bins removed. */
    template <typename F>
    size_t editBins(int ix, int iy, F&& f);

    /** @name Update cycles: which cells one observation updated (for the visibility constraint).
     * @{ */
    /** A cell updated in the current cycle, with the highest height accepted into it [m]. */
    struct UpdatedCell {
        int ix, iy;
        float maxHeight_m;
        uint32_t points;  //!< points accepted into the cell in this cycle
    };
    /** Starts a new cycle: forgets which cells were updated. */
    void beginCycle();
    const std::vector<UpdatedCell>& updatedCells() const { return m_updated; }
    bool updatedThisCycle(int ix, int iy) const {
        if (!m_window.contains(ix, iy)) return false;
        return m_cells[slot(ix, iy)].cycle == m_cycle;
    }
    /** Highest bin height ever stored (an upper bound on every bin's height) [m]. */
    double maxHeight_m() const { return m_maxHeight_m; }
    /** @} */

    /** @name Local height bound: blocks of kBlockCells x kBlockCells cells. Block (bx, by) holds
     * cells bx kBlockCells .. bx kBlockCells + kBlockCells - 1 (and likewise in y), so a cell's
     * block is (ix >> kBlockShift, iy >> kBlockShift). Kept up to date on every insertion (one
     * compare per run of points); conservative on removal: the bound never goes down while the
     * block stays in the window, which costs the visibility constraint time, never correctness.
     * @{ */
    static constexpr int kBlockShift = 4;
    static constexpr int kBlockCells = 1 << kBlockShift;
    /** Block index of a cell index (floor division by kBlockCells). */
    static int blockOf(int cellIndex) { return cellIndex >> kBlockShift; }  // arithmetic shift
    /** An upper bound on the height of every bin stored in a cell of block (bx, by) [m], to
     * within 1e-6 (1 + |bound|): the highest height fused into it since it entered the window,
     * rounded to float (bins hold float heights, weighted means of what was fused); -infinity if
     * none (or the block lies outside the window). */
    float blockMaxHeight_m(int bx, int by) const {
        int sx = bx - m_blockX0, sy = by - m_blockY0;
        if (sx < 0 || sy < 0 || sx >= m_blockNx || sy >= m_blockNy)
            return -std::numeric_limits<float>::infinity();
        sx += m_blockOriginX;
        sy += m_blockOriginY;
        if (sx >= m_blockNx) sx -= m_blockNx;
        if (sy >= m_blockNy) sy -= m_blockNy;
        const BlockSlot& b = m_blocks[size_t(sx) + size_t(sy) * size_t(m_blockNx)];
        return b.bx == bx && b.by == by ? b.maxHeight_m : -std::numeric_limits<float>::infinity();
    }
    /** @} */

    /** Removes every bin of one cell. */
    void clearCell(int ix, int iy);
    /** Appends a bin as stored elsewhere (deserialization, grid-to-grid copies). */
    void appendBin(int ix, int iy, const Bin& bin);

    /** Number of bins in use, over all cells. */
    size_t binCount() const { return m_pool.size() - m_freeCount; }
    /** Memory held by the grid [bytes]: per cell of the window a bin-chain head and an
     * update-cycle stamp and index (12 B), the bin pool (24 B per bin, with the vector's spare
     * capacity), the list of cells updated in the current cycle and the block height bounds
     * (12 B per block of 256 cells). Independent of the vertical extent. */
    size_t memoryBytes() const {
        return m_cells.capacity() * sizeof(CellSlot) + m_pool.capacity() * sizeof(Bin) +
               m_updated.capacity() * sizeof(UpdatedCell) + m_blocks.capacity() * sizeof(BlockSlot);
    }
    bool empty() const { return binCount() == 0; }

    /** Reported standard deviation of a bin: sqrt(max(variance, floor)) [m]. */
    static double sigma_m(const Bin& b, const BinUpdateParams& p) {
        return std::sqrt(std::max<double>(b.variance_m2, p.varianceFloor_m2));
    }

private:
    /** Storage slot of a cell inside the window: (ix mod nx) + (iy mod ny) nx, computed from the
     * window origin's residues without a division. */
    size_t slot(int ix, int iy) const {
        return slotIn(m_window, m_originSlotX, m_originSlotY, ix, iy);
    }
    static size_t slotIn(const CellWindow& w, int originSlotX, int originSlotY, int ix, int iy) {
        int sx = ix - w.ix0 + originSlotX, sy = iy - w.iy0 + originSlotY;
        if (sx >= w.nx) sx -= w.nx;
        if (sy >= w.ny) sy -= w.ny;
        return size_t(sx) + size_t(sy) * size_t(w.nx);
    }
    /** d mod n in [0, n) for n > 0; no division for |d| < 2n (every overlapping move). */
    static int wrap(int d, int n) {
        if (d >= n) d -= n;
        if (d < 0) d += n;
        return d >= 0 && d < n ? d : ((d % n) + n) % n;
    }
    /** i mod n in [0, n) (0 for an empty axis). */
    static int residue(int i, int n) { return n > 0 ? ((i % n) + n) % n : 0; }
    /** Sets the window and the block table's geometry (not its contents). */
    void setWindow(const CellWindow& w);
    /** The insertion core over `count` map-frame points, fetched a classification block at a time
     * by `blockAt(begin, n)` (a pointer to points begin .. begin + n - 1). */
    template <typename BlockSource>
    InsertStats insertBlocks(size_t count, BlockSource&& blockAt, const BinUpdateParams& params,
                             double continuityBound_m);
    /** Rebuilds the block table from every bin (after the window changed size). */
    void rebuildBlocks();
    /** Raises the bound of the block of cell (ix, iy), inside the window, to `height_m` [m]. */
    void raiseBlock(int ix, int iy, double height_m);
    uint32_t allocateBin();
    void releaseChain(uint32_t head);
    /** The bin of index n in the cell at `slot`, appended to its chain if missing. */
    uint32_t findOrAddBin(size_t slot, int16_t n);
    /** Records `points` accepted points into cell (ix, iy), the highest at `height_m` [m]. */
    void noteUpdate(size_t slot, int ix, int iy, double height_m, uint32_t points);
    /** Gates 13 and bin range passed: eq 14 and the per-point Kalman update (eq 15). */
    bool fuseMeasurement(size_t slot, int ix, int iy, int16_t n, double height_m,
                         double variance_m2, const BinUpdateParams& params,
                         double continuityBound_m, InsertStats& stats);

    double m_cellSize_m;
    double m_invCellSize = 1.0;  //!< 1 / cell size [1/m]
    CellWindow m_window;
    int m_originSlotX = 0, m_originSlotY = 0;  //!< ix0 mod nx, iy0 mod ny
    /** Everything kept per cell, together so one cache line serves a cell's every test. */
    struct CellSlot {
        uint32_t head = kNoBin;     //!< first bin of the cell, or kNoBin
        uint32_t cycle = 0;         //!< the update cycle that last updated the cell
        uint32_t updatedIndex = 0;  //!< its entry in m_updated, valid in that cycle
    };
    std::vector<CellSlot> m_cells;       //!< per slot
    std::vector<Bin> m_pool;             //!< all bins; free ones are chained from m_freeHead
    std::vector<UpdatedCell> m_updated;  //!< cells updated in this cycle, in first-update order
    uint32_t m_cycle = 1;
    double m_maxHeight_m = -std::numeric_limits<double>::infinity();
    /** Height bound of one block, tagged with the block it belongs to: blocks whose indices are
     * congruent modulo the table size share a slot, but never while both meet the window (the
     * table is one block larger than the window on each axis). A slot tagged with another
     * block therefore means "no bin in this block". */
    struct BlockSlot {
        int32_t bx = std::numeric_limits<int32_t>::min(), by = 0;
        float maxHeight_m = -std::numeric_limits<float>::infinity();
    };
    std::vector<BlockSlot> m_blocks;   //!< slot (bx mod m_blockNx) + (by mod m_blockNy) m_blockNx
    int m_blockX0 = 0, m_blockY0 = 0;  //!< block of the window's first cell
    int m_blockNx = 0, m_blockNy = 0;  //!< table size: ceil(nx / kBlockCells) + 1, likewise y
    int m_blockOriginX = 0, m_blockOriginY = 0;  //!< m_blockX0 mod m_blockNx, likewise y
    /** The block raised last and its slot (tagged with it); forgotten when the table changes. */
    int m_lastBlockX = std::numeric_limits<int>::min(), m_lastBlockY = 0;
    size_t m_lastBlockSlot = 0;
    uint32_t m_freeHead = kNoBin;
    size_t m_freeCount = 0;
};

// Inline: called per run of points; out of line they would go through the PLT.
inline void BinGrid::raiseBlock(int ix, int iy, double height_m) {
    const int bx = blockOf(ix), by = blockOf(iy);
    const float h = static_cast<float>(height_m);    // rounded to nearest: see blockMaxHeight_m
    if (bx == m_lastBlockX && by == m_lastBlockY) {  // consecutive runs mostly share a block
        BlockSlot& b = m_blocks[m_lastBlockSlot];
        if (h > b.maxHeight_m) b.maxHeight_m = h;
        return;
    }
    int sx = bx - m_blockX0 + m_blockOriginX, sy = by - m_blockY0 + m_blockOriginY;
    if (sx >= m_blockNx) sx -= m_blockNx;
    if (sy >= m_blockNy) sy -= m_blockNy;
    m_lastBlockSlot = size_t(sx) + size_t(sy) * size_t(m_blockNx);
    m_lastBlockX = bx;
    m_lastBlockY = by;
    BlockSlot& b = m_blocks[m_lastBlockSlot];
    if (b.bx == bx && b.by == by) {
        if (h > b.maxHeight_m) b.maxHeight_m = h;
    } else {
        b = {bx, by, h};  // the slot's previous block has left the window
    }
}

inline void BinGrid::noteUpdate(size_t s, int ix, int iy, double height_m, uint32_t points) {
    m_maxHeight_m = std::max(m_maxHeight_m, height_m);
    raiseBlock(ix, iy, height_m);
    CellSlot& cs = m_cells[s];
    if (cs.cycle == m_cycle) {
        UpdatedCell& u = m_updated[cs.updatedIndex];
        u.maxHeight_m = std::max(u.maxHeight_m, float(height_m));
        u.points += points;
    } else {
        cs.cycle = m_cycle;
        cs.updatedIndex = static_cast<uint32_t>(m_updated.size());
        m_updated.push_back({ix, iy, float(height_m), points});
    }
}

inline uint32_t BinGrid::findOrAddBin(size_t s, int16_t n) {
    uint32_t prev = kNoBin, b = m_cells[s].head;
    while (b != kNoBin && m_pool[b].index != n) {
        prev = b;
        b = m_pool[b].next;
    }
    if (b == kNoBin) {
        b = allocateBin();  // may reallocate the pool: hold indices, not pointers
        m_pool[b].index = n;
        m_pool[b].next = kNoBin;
        (prev == kNoBin ? m_cells[s].head : m_pool[prev].next) = b;
    }
    return b;
}

template <typename OnLeave>
void BinGrid::moveWindowTo(int ix0, int iy0, OnLeave&& onLeave) {
    const CellWindow oldW = m_window;
    CellWindow newW = oldW;
    newW.ix0 = ix0;
    newW.iy0 = iy0;
    if (oldW.nx == 0 || oldW.ny == 0) {
        setWindow(newW);
        return;
    }
    // Slots are keyed by (ix mod nx, iy mod ny): a cell that stays keeps its slot. Each entering
    // cell reuses the slot of exactly one leaving cell, so visiting the entering cells (in the new
    // window, not in the old one) and clearing the leaver stored there does all the work.
    const bool disjoint = ix0 >= oldW.ix0 + oldW.nx || ix0 + oldW.nx <= oldW.ix0 ||
                          iy0 >= oldW.iy0 + oldW.ny || iy0 + oldW.ny <= oldW.iy0;
    const int newOriginX = residue(ix0, newW.nx), newOriginY = residue(iy0, newW.ny);
    auto leaverOf = [&](int ix, int iy, int& lx, int& ly) {
        // The old-window cell sharing this slot.
        lx = oldW.ix0 + wrap(ix - oldW.ix0, oldW.nx);
        ly = oldW.iy0 + wrap(iy - oldW.iy0, oldW.ny);
    };
    auto handleEntering = [&](int ix, int iy) {
        // The entering cell's slot in the new window is the leaver's slot in the old one.
        const size_t s = slotIn(newW, newOriginX, newOriginY, ix, iy);
        m_cells[s].cycle = 0;  // the entering cell was not updated in this cycle
        if (m_cells[s].head == kNoBin) return;
        int lx, ly;
        leaverOf(ix, iy, lx, ly);
        onLeave(lx, ly);
        releaseChain(m_cells[s].head);
        m_cells[s].head = kNoBin;
    };
    if (disjoint) {
        for (int iy = iy0; iy < iy0 + oldW.ny; iy++)
            for (int ix = ix0; ix < ix0 + oldW.nx; ix++) handleEntering(ix, iy);
    } else {
        for (int iy = iy0; iy < iy0 + oldW.ny; iy++) {
            const bool rowInOld = iy >= oldW.iy0 && iy < oldW.iy0 + oldW.ny;
            for (int ix = ix0; ix < ix0 + oldW.nx; ix++) {
                if (rowInOld && ix >= oldW.ix0 && ix < oldW.ix0 + oldW.nx) {
                    ix = std::min(ix0 + oldW.nx, oldW.ix0 + oldW.nx) - 1;  // skip kept run
                    continue;
                }
                handleEntering(ix, iy);
            }
        }
    }
    setWindow(newW);
}

template <typename F>
size_t BinGrid::editBins(int ix, int iy, F&& f) {
    if (!m_window.contains(ix, iy)) return 0;
    size_t removed = 0;
    const size_t s = slot(ix, iy);
    uint32_t prev = kNoBin, b = m_cells[s].head;
    while (b != kNoBin) {
        const uint32_t next = m_pool[b].next;
        if (f(m_pool[b])) {
            prev = b;
        } else {
            (prev == kNoBin ? m_cells[s].head : m_pool[prev].next) = next;
            m_pool[b].next = m_freeHead;
            m_freeHead = b;
            m_freeCount++;
            removed++;
        }
        b = next;
    }
    return removed;
}

}  // namespace multibin
