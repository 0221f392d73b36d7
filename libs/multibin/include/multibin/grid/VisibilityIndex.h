/* Part of the multibin elevation-mapping library. */
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "multibin/grid/BinStore.h"

namespace multibin {

/** What the visibility constraint needs to know about a grid beyond its bins: which cells the
 * current observation updated (update cycles) and upper bounds on the bins' heights, per cell
 * and per block of cells; and what the lines of sight say of the ground, the clearance of each
 * cell (for the gap fill). Kept beside a BinStore with its slot numbering (per tile); BinGrid
 * keeps the two in step. Memory: 16 B per cell of an allocated tile (update-cycle stamp and
 * index, height bound, clearance), 4 B per block of 256 cells. */
class VisibilityIndex {
public:
    /** A cell updated in the current cycle, with the highest height accepted into it [m]. */
    struct UpdatedCell {
        int ix, iy;
        float maxHeight_m;
        uint32_t points;  //!< points accepted into the cell in this cycle
    };

    /** Forgets everything: only the store's empty tile. */
    void reset();
    /** The store allocated tile `tile` (new or reused), now holding `slotCount` slots in all: its
     * cells were not updated in this cycle and hold no bin. */
    void tileAdded(uint32_t tile, size_t slotCount);
    /** A cell left the window at `slot`: it was not updated in this cycle and holds no bin. */
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
        const float h = static_cast<float>(height_m);  // rounded to nearest: see blockMaxHeight_m
        float& blockMax_m = m_blocks[blockSlot(slot, ix, iy)];
        blockMax_m = std::max(blockMax_m, h);
        float& cellMax_m = m_stamps[slot].maxHeight_m;
        cellMax_m = std::max(cellMax_m, h);
    }
    /** Highest bin height ever stored (an upper bound on every bin's height) [m]. */
    double maxHeight_m() const { return m_maxHeight_m; }
    /** @} */

    /** An upper bound on the height of every bin of the cell at `slot` [m], as
     * blockMaxHeight_m's for its block (the same rounding and the same conservative removal):
     * the visibility constraint tests a cell's bins only where this says they may conflict. */
    float cellMaxHeight_m(size_t slot) const { return m_stamps[slot].maxHeight_m; }

    /** @name Clearance: the lowest height at which a line of sight passed over a cell without a
     * return there, an upper bound on its ground (the gap fill bounds filled cells by it). Kept
     * while the cell's tile stays allocated; +infinity where no line passed (and in the empty
     * tile, which is never written).
     * @{ */
    /** A line of sight passed over the cell at `slot` at `height_m` [m]. */
    void noteClearance(size_t slot, float height_m) {
        if (slot < BinStore::kTileSlots) return;  // the empty tile: read only
        float& c = m_stamps[slot].clearance_m;
        c = std::min(c, height_m);
    }
    float clearance_m(size_t slot) const { return m_stamps[slot].clearance_m; }
    /** @} */

    /** @name Local height bound: blocks of kBlockCells x kBlockCells cells. Block (bx, by) holds
     * cells bx kBlockCells .. bx kBlockCells + kBlockCells - 1 (and likewise in y), so a cell's
     * block is (ix >> kBlockShift, iy >> kBlockShift); a tile of the store holds
     * kBlocksPerTile x kBlocksPerTile blocks. Kept up to date on every insertion (one compare per
     * run of points); conservative on removal: the bound never goes down while the block's tile
     * stays allocated, which costs the visibility constraint time, never correctness.
     * @{ */
    static constexpr int kBlockShift = 4;
    static constexpr int kBlockCells = 1 << kBlockShift;
    static constexpr int kBlocksPerTile = BinStore::kTileCells / kBlockCells;
    /** Block index of a cell index (floor division by kBlockCells). */
    static int blockOf(int cellIndex) { return cellIndex >> kBlockShift; }  // arithmetic shift
    /** An upper bound on the height of every bin stored in a cell of block (bx, by), which lies
     * in tile number `tile` of the store [m], to within 1e-6 (1 + |bound|): the highest height
     * fused into it since its tile was allocated, rounded to float (bins hold float heights,
     * weighted means of what was fused); -infinity if none (the empty tile: none ever). */
    float blockMaxHeight_m(uint32_t tile, int bx, int by) const {
        return m_blocks[size_t(tile) * kBlocksPerTile * kBlocksPerTile +
                        size_t(by & (kBlocksPerTile - 1)) * kBlocksPerTile +
                        size_t(bx & (kBlocksPerTile - 1))];
    }
    /** @} */

    /** Memory per allocated tile of the store [bytes]: its stamps and block bounds. */
    static const size_t kBytesPerTile;
    /** Memory held [bytes]: stamps, the list of updated cells, the block bounds. */
    size_t memoryBytes() const {
        return m_stamps.capacity() * sizeof(CellStamp) +
               m_updated.capacity() * sizeof(UpdatedCell) + m_blocks.capacity() * sizeof(float);
    }

private:
    /** The entry of m_blocks of the block holding cell (ix, iy) at `slot`. */
    static size_t blockSlot(size_t slot, int ix, int iy) {
        constexpr int kInTile = BinStore::kTileCells - 1;
        return (slot >> (2 * BinStore::kTileShift)) * kBlocksPerTile * kBlocksPerTile +
               size_t((iy & kInTile) >> kBlockShift) * kBlocksPerTile +
               size_t((ix & kInTile) >> kBlockShift);
    }

    struct CellStamp {
        uint32_t cycle = 0;         //!< the update cycle that last updated the cell
        uint32_t updatedIndex = 0;  //!< its entry in m_updated, valid in that cycle
        float maxHeight_m = -std::numeric_limits<float>::infinity();  //!< cellMaxHeight_m
        float clearance_m = std::numeric_limits<float>::infinity();   //!< clearance_m
    };
    std::vector<CellStamp> m_stamps;     //!< per slot of the store
    std::vector<UpdatedCell> m_updated;  //!< cells updated in this cycle, in first-update order
    uint32_t m_cycle = 1;
    double m_maxHeight_m = -std::numeric_limits<double>::infinity();
    std::vector<float> m_blocks;  //!< per tile of the store, its blocks' bounds, row-major
};

inline const size_t VisibilityIndex::kBytesPerTile =
    BinStore::kTileSlots * sizeof(CellStamp) + kBlocksPerTile * kBlocksPerTile * sizeof(float);

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
