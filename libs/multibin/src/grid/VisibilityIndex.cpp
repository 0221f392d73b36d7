/* Part of the multibin elevation-mapping library. */
#include "multibin/grid/VisibilityIndex.h"

namespace multibin {

namespace {
constexpr size_t kBlocksInTile =
    size_t(VisibilityIndex::kBlocksPerTile) * VisibilityIndex::kBlocksPerTile;
}

void VisibilityIndex::reset() {
    m_stamps.assign(BinStore::kTileSlots, CellStamp{});
    m_blocks.assign(kBlocksInTile, -std::numeric_limits<float>::infinity());
    m_updated.clear();
    m_maxHeight_m = -std::numeric_limits<double>::infinity();
}

void VisibilityIndex::tileAdded(uint32_t tile, size_t slotCount) {
    if (m_stamps.size() < slotCount) {
        m_stamps.resize(slotCount);
        m_blocks.resize(slotCount / BinStore::kTileSlots * kBlocksInTile,
                        -std::numeric_limits<float>::infinity());
    }
    const size_t first = size_t(tile) * BinStore::kTileSlots;
    std::fill(m_stamps.begin() + first, m_stamps.begin() + first + BinStore::kTileSlots,
              CellStamp{});
    std::fill(m_blocks.begin() + tile * kBlocksInTile,
              m_blocks.begin() + (tile + 1) * kBlocksInTile,
              -std::numeric_limits<float>::infinity());
}

void VisibilityIndex::beginCycle() {
    m_updated.clear();
    if (++m_cycle == 0) {  // wrapped: no stale stamp may match the new cycle
        for (CellStamp& cs : m_stamps) cs.cycle = 0;
        m_cycle = 1;
    }
}

}  // namespace multibin
