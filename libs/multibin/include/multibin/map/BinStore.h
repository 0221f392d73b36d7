/* Part of the multibin elevation-mapping library. */
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "multibin/geometry/Lattice.h"
#include "multibin/map/Bin.h"

namespace multibin {

/** The storage of a 2.5D multi-bin grid: cells, their bins and the moving window, and nothing
 * about how bins are updated (BinUpdate.h) or indexed for the visibility constraint
 * (VisibilityIndex.h).
 *
 * Cells: a circular buffer over the cell window (grid_map style): cell (ix, iy) lives in slot
 * (ix mod nx) + (iy mod ny) nx, so moving the window only clears the slots of the cells that
 * enter, and growing it re-slots the cell heads without touching any bin. Bins: one pool shared
 * by all cells, chained per cell in insertion order and addressed by a BinId, so callers hold
 * ids, never pointers (the pool may reallocate). Memory: 4 B per cell of the window and 64 B per
 * bin. */
class BinStore {
public:
    using BinId = uint32_t;
    static constexpr BinId kNoBin = std::numeric_limits<uint32_t>::max();

    explicit BinStore(double cellSize_m = 0.02);

    /** @name Geometry
     * @{ */
    double cellSize_m() const { return m_cellSize_m; }
    const CellWindow& window() const { return m_window; }
    /** The cells of the window with their size. */
    Lattice lattice() const { return Lattice{m_cellSize_m, m_window}; }
    /** Index of the cell containing a coordinate [m]; clamped far outside any window, so
     * absurd coordinates never overflow (NaN gives the upper limit). */
    int cellIndex(double coord_m) const {
        return floorToInt(clampedCellCoordinate(coord_m * m_invCellSize));
    }
    /** A coordinate in cells [-], clamped to +-2^29 (NaN to the upper limit): far outside any
     * window, and its floor fits an int. Selects only, so loops over points vectorise. */
    static double clampedCellCoordinate(double f) {
        constexpr double kLimit = std::numeric_limits<int>::max() / 4;
        f = f < kLimit ? f : kLimit;  // also NaN
        return f < -kLimit ? -kLimit : f;
    }
    /** Vertical bin index of a height [m]: floor(height / binHeight); false if it does not fit
     * the int16 bin index (or is NaN). */
    static bool binIndexOf(double height_m, double binHeight_m, int16_t& n) {
        const double q = height_m / binHeight_m;
        if (!binIndexFits(q)) return false;
        n = static_cast<int16_t>(floorToInt(q));
        return true;
    }
    /** Whether floor(q) of a height in bins fits the int16 bin index (false for NaN). */
    static bool binIndexFits(double q) {
        return (q >= std::numeric_limits<int16_t>::min()) &
               (q < double(std::numeric_limits<int16_t>::max()) + 1.0);
    }
    /** floor(v) for finite |v| < 2^31, without a libm call (baseline x86-64 has no SSE4.1
     * rounding instruction) and without a branch. */
    static int floorToInt(double v) {
        const int t = static_cast<int>(v);  // truncates towards zero
        return t - int(v < double(t));
    }
    double cellCenter_m(int index) const { return (index + 0.5) * m_cellSize_m; }
    /** 1 / cell size, the factor cellIndex applies [1/m]. */
    double inverseCellSize() const { return m_invCellSize; }
    /** The slot coordinates of the window's first cell (ix0 mod nx, iy0 mod ny): slot() in
     * closed form for code that computes slots in bulk. */
    int originSlotX() const { return m_originSlotX; }
    int originSlotY() const { return m_originSlotY; }
    /** i mod n in [0, n) (0 for an empty axis): the slot coordinate of index i on an axis of n. */
    static int floorMod(int i, int n) { return n > 0 ? ((i % n) + n) % n : 0; }
    /** @} */

    /** @name The window
     * @{ */
    /** Drops all bins and sets an empty window; the cell size may change. */
    void reset(double cellSize_m, const CellWindow& window);
    /** Enlarges the window to the union with `w`, keeping every bin; false if it already held
     * `w` (nothing changed). Every cell moves to a new slot. */
    bool growToInclude(const CellWindow& w);
    /** Translates the window to a new origin, same size. Cells that leave are passed to
     * `onLeave(ix, iy)` (while still readable) and then cleared; the slot of every cell that
     * enters is passed to `onEnter(slot)`; cells still inside are untouched. Cost: proportional
     * to the cells that enter. */
    template <typename OnLeave, typename OnEnter>
    void moveWindowTo(int ix0, int iy0, OnLeave&& onLeave, OnEnter&& onEnter);
    /** Slots: one per cell of the window, numbered 0 .. window().cellCount() - 1. */
    size_t slot(int ix, int iy) const {
        int sx = ix - m_window.ix0 + m_originSlotX, sy = iy - m_window.iy0 + m_originSlotY;
        if (sx >= m_window.nx) sx -= m_window.nx;
        if (sy >= m_window.ny) sy -= m_window.ny;
        return size_t(sx) + size_t(sy) * size_t(m_window.nx);
    }
    /** @} */

    /** @name Bins
     * @{ */
    Bin& bin(BinId b) { return m_pool[b]; }
    const Bin& bin(BinId b) const { return m_pool[b]; }
    /** The bin of index n in the cell at `slot`, appended to its chain (all estimates zero) if
     * missing; `added` tells which. */
    BinId findOrAddBin(size_t slot, int16_t n, bool& added);
    BinId findOrAddBin(size_t slot, int16_t n) {
        bool added;
        return findOrAddBin(slot, n, added);
    }
    /** Appends a bin with this estimate to the chain of cell (ix, iy), inside the window. */
    BinId appendBin(int ix, int iy, const BinEstimate& estimate);
    /** Calls f(const Bin&) for every bin of the cell, in chain order; nothing outside the
     * window. */
    template <typename F>
    void forEachBin(int ix, int iy, F&& f) const {
        if (!m_window.contains(ix, iy)) return;
        for (BinId b = m_heads[slot(ix, iy)]; b != kNoBin; b = m_pool[b].next) f(m_pool[b]);
    }
    /** Calls f(ix, iy, const Bin&) for every bin of the window. */
    template <typename F>
    void forEachStoredBin(F&& f) const {
        const CellWindow& w = m_window;
        for (int iy = w.iy0; iy < w.iy0 + w.ny; iy++)
            for (int ix = w.ix0; ix < w.ix0 + w.nx; ix++)
                for (BinId b = m_heads[slot(ix, iy)]; b != kNoBin; b = m_pool[b].next)
                    f(ix, iy, m_pool[b]);
    }
    /** Calls f(Bin&) for every bin of the cell; a bin for which f returns false is removed.
     * Returns the number of bins removed. */
    template <typename F>
    size_t editBins(int ix, int iy, F&& f);
    /** Removes every bin of one cell. */
    void clearCell(int ix, int iy);
    /** Number of bins in use, over all cells. */
    size_t binCount() const { return m_pool.size() - m_freeCount; }
    bool empty() const { return binCount() == 0; }
    /** Memory held [bytes]: the cell heads and the bin pool with its spare capacity. */
    size_t memoryBytes() const {
        return m_heads.capacity() * sizeof(BinId) + m_pool.capacity() * sizeof(Bin);
    }
    /** @} */

private:
    void setWindow(const CellWindow& w);
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
    BinId allocateBin();
    void releaseChain(BinId head);
    void release(BinId b) {
        m_pool[b].next = m_freeHead;
        m_freeHead = b;
        m_freeCount++;
    }

    double m_cellSize_m;
    double m_invCellSize = 1.0;  //!< 1 / cell size [1/m]
    CellWindow m_window;
    int m_originSlotX = 0, m_originSlotY = 0;  //!< ix0 mod nx, iy0 mod ny
    std::vector<BinId> m_heads;                //!< per slot: the cell's first bin, or kNoBin
    std::vector<Bin> m_pool;                   //!< all bins; free ones chained from m_freeHead
    BinId m_freeHead = kNoBin;
    size_t m_freeCount = 0;
};

inline BinStore::BinId BinStore::findOrAddBin(size_t s, int16_t n, bool& added) {
    BinId prev = kNoBin, b = m_heads[s];
    while (b != kNoBin && m_pool[b].index != n) {
        prev = b;
        b = m_pool[b].next;
    }
    added = b == kNoBin;
    if (added) {
        b = allocateBin();  // may reallocate the pool: hold indices, not pointers
        m_pool[b].index = n;
        m_pool[b].next = kNoBin;
        (prev == kNoBin ? m_heads[s] : m_pool[prev].next) = b;
    }
    return b;
}

template <typename OnLeave, typename OnEnter>
void BinStore::moveWindowTo(int ix0, int iy0, OnLeave&& onLeave, OnEnter&& onEnter) {
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
    const int newOriginX = floorMod(ix0, newW.nx), newOriginY = floorMod(iy0, newW.ny);
    auto handleEntering = [&](int ix, int iy) {
        // The entering cell's slot in the new window is the leaver's slot in the old one.
        const size_t s = slotIn(newW, newOriginX, newOriginY, ix, iy);
        onEnter(s);
        if (m_heads[s] == kNoBin) return;
        // The old-window cell sharing this slot.
        onLeave(oldW.ix0 + wrap(ix - oldW.ix0, oldW.nx), oldW.iy0 + wrap(iy - oldW.iy0, oldW.ny));
        releaseChain(m_heads[s]);
        m_heads[s] = kNoBin;
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
size_t BinStore::editBins(int ix, int iy, F&& f) {
    if (!m_window.contains(ix, iy)) return 0;
    size_t removed = 0;
    const size_t s = slot(ix, iy);
    BinId prev = kNoBin, b = m_heads[s];
    while (b != kNoBin) {
        const BinId next = m_pool[b].next;
        if (f(m_pool[b])) {
            prev = b;
        } else {
            (prev == kNoBin ? m_heads[s] : m_pool[prev].next) = next;
            release(b);
            removed++;
        }
        b = next;
    }
    return removed;
}

}  // namespace multibin
