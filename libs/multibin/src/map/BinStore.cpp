/* Part of the multibin elevation-mapping library. */
#include "multibin/map/BinStore.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace multibin {

BinStore::BinStore(double cellSize_m) { reset(cellSize_m, CellWindow{}); }

void BinStore::reset(double cellSize_m, const CellWindow& window) {
    if (!(cellSize_m > 0) || !std::isfinite(cellSize_m))
        throw std::invalid_argument("BinGrid: cell size must be positive and finite, got " +
                                    std::to_string(cellSize_m));
    if (window.nx < 0 || window.ny < 0)
        throw std::invalid_argument("BinGrid: negative window size");
    m_cellSize_m = cellSize_m;
    m_invCellSize = 1.0 / cellSize_m;
    setWindow(window);
    m_heads.assign(window.cellCount(), kNoBin);
    m_pool.clear();
    m_freeHead = kNoBin;
    m_freeCount = 0;
}

bool BinStore::growToInclude(const CellWindow& w) {
    if (w.nx <= 0 || w.ny <= 0) return false;
    CellWindow nw;
    if (m_window.nx == 0 || m_window.ny == 0) {
        nw = w;
    } else {
        nw.ix0 = std::min(m_window.ix0, w.ix0);
        nw.iy0 = std::min(m_window.iy0, w.iy0);
        nw.nx = std::max(m_window.ix0 + m_window.nx, w.ix0 + w.nx) - nw.ix0;
        nw.ny = std::max(m_window.iy0 + m_window.ny, w.iy0 + w.ny) - nw.iy0;
    }
    if (nw == m_window) return false;
    std::vector<BinId> heads(nw.cellCount(), kNoBin);
    const CellWindow old = m_window;
    for (int iy = old.iy0; iy < old.iy0 + old.ny; iy++)
        for (int ix = old.ix0; ix < old.ix0 + old.nx; ix++) {
            const BinId h = m_heads[slot(ix, iy)];
            if (h == kNoBin) continue;
            heads[size_t(floorMod(ix, nw.nx)) + size_t(floorMod(iy, nw.ny)) * size_t(nw.nx)] = h;
        }
    m_heads.swap(heads);
    setWindow(nw);
    return true;
}

void BinStore::setWindow(const CellWindow& w) {
    m_window = w;
    m_originSlotX = floorMod(w.ix0, w.nx);
    m_originSlotY = floorMod(w.iy0, w.ny);
}

BinStore::BinId BinStore::allocateBin() {
    if (m_freeHead != kNoBin) {
        const BinId b = m_freeHead;
        m_freeHead = m_pool[b].next;
        m_freeCount--;
        m_pool[b] = Bin{};
        return b;
    }
    if (m_pool.size() >= kNoBin - 1) throw std::length_error("BinGrid: bin pool is full");
    m_pool.emplace_back();
    return static_cast<BinId>(m_pool.size() - 1);
}

void BinStore::releaseChain(BinId head) {
    while (head != kNoBin) {
        const BinId next = m_pool[head].next;
        release(head);
        head = next;
    }
}

void BinStore::clearCell(int ix, int iy) {
    if (!m_window.contains(ix, iy)) return;
    BinId& head = m_heads[slot(ix, iy)];
    releaseChain(head);
    head = kNoBin;
}

BinStore::BinId BinStore::appendBin(int ix, int iy, const BinEstimate& estimate) {
    if (!m_window.contains(ix, iy))
        throw std::out_of_range("BinGrid::appendBin: cell outside the window");
    const BinId b = allocateBin();  // may reallocate the pool: hold indices, not pointers
    static_cast<BinEstimate&>(m_pool[b]) = estimate;
    m_pool[b].next = kNoBin;
    const size_t s = slot(ix, iy);
    BinId last = m_heads[s];
    if (last == kNoBin) {
        m_heads[s] = b;
        return b;
    }
    while (m_pool[last].next != kNoBin) last = m_pool[last].next;
    m_pool[last].next = b;
    return b;
}

}  // namespace multibin
