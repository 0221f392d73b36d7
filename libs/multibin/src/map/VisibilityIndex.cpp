/* Part of the multibin elevation-mapping library. */
#include "multibin/map/VisibilityIndex.h"

#include "multibin/map/BinStore.h"

namespace multibin {

void VisibilityIndex::reset(const CellWindow& w) {
    setWindow(w);
    m_stamps.assign(w.cellCount(), CellStamp{});
    m_blocks.assign(size_t(m_blockNx) * size_t(m_blockNy), BlockSlot{});
    m_updated.clear();
    m_maxHeight_m = -std::numeric_limits<double>::infinity();
}

void VisibilityIndex::regrow(const BinStore& store) {
    const CellWindow& w = store.window();
    setWindow(w);
    // Growth happens between update cycles: the cycle bookkeeping starts afresh (the new slots
    // carry no stamp).
    m_stamps.assign(w.cellCount(), CellStamp{});
    m_updated.clear();
    m_blocks.assign(size_t(m_blockNx) * size_t(m_blockNy), BlockSlot{});
    store.forEachStoredBin(
        [&](int ix, int iy, const Bin& b) { noteHeight(store.slot(ix, iy), ix, iy, b.height_m); });
}

void VisibilityIndex::setWindow(const CellWindow& w) {
    // One block more than the window spans at most, so the blocks meeting it never share a slot.
    m_blockX0 = blockOf(w.ix0);
    m_blockY0 = blockOf(w.iy0);
    m_blockNx = w.nx > 0 ? (w.nx + kBlockCells - 1) / kBlockCells + 1 : 0;
    m_blockNy = w.ny > 0 ? (w.ny + kBlockCells - 1) / kBlockCells + 1 : 0;
    m_blockOriginX = BinStore::floorMod(m_blockX0, m_blockNx);
    m_blockOriginY = BinStore::floorMod(m_blockY0, m_blockNy);
    m_lastBlockX = std::numeric_limits<int>::min();
}

void VisibilityIndex::beginCycle() {
    m_updated.clear();
    if (++m_cycle == 0) {  // wrapped: no stale stamp may match the new cycle
        for (CellStamp& cs : m_stamps) cs.cycle = 0;
        m_cycle = 1;
    }
}

}  // namespace multibin
