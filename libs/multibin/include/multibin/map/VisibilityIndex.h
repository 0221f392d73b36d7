/* Part of the multibin elevation-mapping library. */
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "multibin/geometry/Lattice.h"

namespace multibin {

class BinStore;

/** What the visibility constraint needs to know about a grid beyond its bins: which cells the
 * current observation updated (update cycles) and upper bounds on the bins' heights, per cell
 * and per block of cells. Kept beside a BinStore with the same window and slot numbering;
 * BinGrid keeps the two in step. Memory: 12 B per cell of the window (update-cycle stamp and
 * index, height bound), 12 B per block of 256 cells. */
class VisibilityIndex {
public:
    /** A cell updated in the current cycle, with the highest height accepted into it [m]. */
    struct UpdatedCell {
        int ix, iy;
        float maxHeight_m;
        uint32_t points;  //!< points accepted into the cell in this cycle
    };

    /** Forgets everything; a window of `w`. */
    void reset(const CellWindow& w);
    /** The store's window moved (same size): block geometry follows, the bounds are kept (a
     * slot's tag tells whether its block is still the one stored). */
    void moveWindow(const CellWindow& w) { setWindow(w); }
    /** The store's window grew: fresh stamps, no updated cell, bounds rebuilt from every bin. */
    void regrow(const BinStore& store);
    /** A cell entered the window at `slot`: it was not updated in this cycle and holds no bin. */
    void forgetSlot(size_t slot) { m_stamps[slot] = CellStamp{}; }

    /** @name Update cycles: which cells one observation updated.
     * @{ */
    /** Starts a new cycle: forgets which cells were updated. */
    void beginCycle();
    const std::vector<UpdatedCell>& updatedCells() const { return m_updated; }
    bool updatedThisCycle(size_t slot) const { return m_stamps[slot].cycle == m_cycle; }
    /** Records `points` accepted points into cell (ix, iy) at `slot`, the highest at
     * `height_m` [m]; raises the bounds. */
    void noteUpdate(size_t slot, int ix, int iy, double height_m, uint32_t points);
    /** A bin of cell (ix, iy) at `slot` now holds `height_m` [m] (stored or fused from
     * elsewhere). */
    void noteHeight(size_t slot, int ix, int iy, double height_m) {
        m_maxHeight_m = std::max(m_maxHeight_m, height_m);
        raiseBlock(ix, iy, height_m);
        float& cellMax_m = m_stamps[slot].maxHeight_m;
        cellMax_m = std::max(cellMax_m, static_cast<float>(height_m));
    }
    /** Highest bin height ever stored (an upper bound on every bin's height) [m]. */
    double maxHeight_m() const { return m_maxHeight_m; }
    /** @} */

    /** An upper bound on the height of every bin of the cell at `slot` [m], as
     * blockMaxHeight_m's for its block (the same rounding and the same conservative removal):
     * the visibility constraint tests a cell's bins only where this says they may conflict. */
    float cellMaxHeight_m(size_t slot) const { return m_stamps[slot].maxHeight_m; }

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

    /** Memory held [bytes]: stamps, the list of updated cells, the block table. */
    size_t memoryBytes() const {
        return m_stamps.capacity() * sizeof(CellStamp) +
               m_updated.capacity() * sizeof(UpdatedCell) + m_blocks.capacity() * sizeof(BlockSlot);
    }

private:
    /** Sets the block table's geometry for window `w` (not its contents). */
    void setWindow(const CellWindow& w);
    /** Raises the bound of the block of cell (ix, iy), inside the window, to `height_m` [m]. */
    void raiseBlock(int ix, int iy, double height_m);

    struct CellStamp {
        uint32_t cycle = 0;         //!< the update cycle that last updated the cell
        uint32_t updatedIndex = 0;  //!< its entry in m_updated, valid in that cycle
        float maxHeight_m = -std::numeric_limits<float>::infinity();  //!< cellMaxHeight_m
    };
    std::vector<CellStamp> m_stamps;     //!< per slot of the store
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
};

// Inline: called per run of points; out of line they would go through the PLT.
inline void VisibilityIndex::raiseBlock(int ix, int iy, double height_m) {
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

inline void VisibilityIndex::noteUpdate(size_t s, int ix, int iy, double height_m,
                                        uint32_t points) {
    noteHeight(s, ix, iy, height_m);
    CellStamp& cs = m_stamps[s];
    if (cs.cycle == m_cycle) {
        UpdatedCell& u = m_updated[cs.updatedIndex];
        u.maxHeight_m = std::max(u.maxHeight_m, float(height_m));
        u.points += points;
    } else {
        cs.cycle = m_cycle;
        cs.updatedIndex = static_cast<uint32_t>(m_updated.size());
        // Written field by field into the vector: a pushed temporary was assembled on the stack
        // with 4-byte stores and read back as one 16-byte load, a store-forwarding stall.
        UpdatedCell& u = m_updated.emplace_back();
        u.ix = ix;
        u.iy = iy;
        u.maxHeight_m = float(height_m);
        u.points = points;
    }
}

}  // namespace multibin
