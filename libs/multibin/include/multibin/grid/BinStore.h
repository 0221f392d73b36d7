/* Part of the multibin elevation-mapping library. */
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <unordered_map>
#include <vector>

#include "multibin/geometry/Lattice.h"
#include "multibin/grid/Bin.h"
#include "multibin/grid/TileStoreFile.h"

namespace multibin {

/** The storage of a 2.5D multi-bin grid: cells, their bins and the window, and nothing about how
 * bins are updated (BinUpdate.h) or indexed for the visibility constraint (VisibilityIndex.h).
 *
 * Window: the cells the grid may store (a fixed extent, the moving window of the dual grid's local
 * grid, or the growing cover of the data). It is bookkeeping only: growing it costs nothing.
 * Cells: tiles of kTileCells x kTileCells cells, allocated on the first write into them and found
 * through a two-level directory (groups of kGroupTiles x kGroupTiles tiles, 4 KB each, allocated
 * when a tile of theirs is, found in a hash table of the groups), so memory follows the ground
 * seen, not the window: two places a continent apart cost two groups. A cell's slot is its tile's
 * number times kTileSlots plus its place in the tile (row-major); tile 0 is the empty tile, never
 * written, that every cell of an unallocated tile reads. Bins: one pool shared by all cells,
 * chained per cell in insertion order and addressed by a BinId, so callers hold ids, never pointers
 * (the pool may reallocate). Memory: 16 KB per tile (4 B per cell), 4 KB and at most 48 B of hash
 * table per group of tiles touched, and 64 B per bin. Tiles on disk: a tile may be written to a
 * TileStoreFile and freed (spillTile), its bins' pool entries reused; it reads as empty until
 * reloadTile brings it back (BinGrid does on the first write into it, the map before a read). */
class BinStore {
public:
    using BinId = uint32_t;
    static constexpr BinId kNoBin = std::numeric_limits<uint32_t>::max();
    static constexpr int kTileShift = 6;
    static constexpr int kTileCells = 1 << kTileShift;  //!< tile side [cells]
    static constexpr size_t kTileSlots = size_t(kTileCells) * kTileCells;
    static constexpr int kGroupShift = 5;
    static constexpr int kGroupTiles = 1 << kGroupShift;  //!< directory group side [tiles]

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
    /** How far from the map origin a growing window may reach [cells]: half the clamp of
     * clampedCellCoordinate, so a clamped coordinate never lands in a cell of the window. */
    static constexpr int kGrowthLimitCells = 1 << 28;
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
    /** Tile index of a cell index (floor division by kTileCells). */
    static int tileOf(int cellIndex) { return cellIndex >> kTileShift; }  // arithmetic shift
    /** @} */

    /** @name The window
     * @{ */
    /** Drops all bins and tiles and sets the window; the cell size may change. */
    void reset(double cellSize_m, const CellWindow& window);
    /** Enlarges the window to the union with `w`, keeping every bin; false if it already held
     * `w`. Costs nothing: tiles are allocated when written. */
    bool growToInclude(const CellWindow& w);
    /** Translates the window to a new origin, same size. Each cell that leaves and holds bins is
     * passed to `onLeave(ix, iy)` (while still readable), tile by tile, row by row in a tile;
     * then its bins are released and `onCleared(slot)` is called for every slot of a leaving
     * cell of an allocated tile. Tiles left with no cell in the window are freed. Cost:
     * proportional to the allocated tiles. */
    template <typename OnLeave, typename OnCleared>
    void moveWindowTo(int ix0, int iy0, OnLeave&& onLeave, OnCleared&& onCleared);
    /** @} */

    /** @name Tiles and slots
     * @{ */
    /** The slot of cell (ix, iy): in the empty tile (slots 0 .. kTileSlots - 1, read only) if
     * its tile holds nothing. Any cell, in the window or not. */
    size_t slot(int ix, int iy) const {
        return tileBase(tileNumber(tileOf(ix), tileOf(iy))) + slotInTile(ix, iy);
    }
    /** The first slot of tile number t. */
    static size_t tileBase(uint32_t t) { return size_t(t) << (2 * kTileShift); }
    /** The slot of cell (ix, iy) in its tile, allocated if it had none (`tileAdded` tells), for
     * a write. */
    size_t writableSlot(int ix, int iy, bool& tileAdded);
    /** Cell (ix, iy)'s place in its tile, row-major. */
    static size_t slotInTile(int ix, int iy) {
        return (size_t(iy & (kTileCells - 1)) << kTileShift) + size_t(ix & (kTileCells - 1));
    }
    /** The number of the tile (tx, ty): 0 (the empty tile) if it is not allocated. */
    uint32_t tileNumber(int tx, int ty) const {
        const uint32_t group = groupNumber(tx >> kGroupShift, ty >> kGroupShift);
        return m_groups[group][size_t(ty & (kGroupTiles - 1)) * kGroupTiles +
                               size_t(tx & (kGroupTiles - 1))];
    }
    /** Slots in use or free, the empty tile's included: per-slot arrays kept beside the store
     * (VisibilityIndex) have this size. */
    size_t slotCount() const { return m_heads.size(); }
    /** Number of allocated tiles. */
    size_t tileCount() const { return m_tileXY.size() - 1 - m_freeTiles.size(); }
    /** Calls f(tx, ty) for every allocated tile, in allocation order. */
    template <typename F>
    void forEachTile(F&& f) const {
        for (size_t t = 1; t < m_tileXY.size(); t++)
            if (m_tileXY[t].allocated) f(m_tileXY[t].tx, m_tileXY[t].ty);
    }
    /** Calls f(t, tx, ty) for every allocated tile: its number and coordinates. */
    template <typename F>
    void forEachTileNumber(F&& f) const {
        for (uint32_t t = 1; t < m_tileXY.size(); t++)
            if (m_tileXY[t].allocated) f(t, m_tileXY[t].tx, m_tileXY[t].ty);
    }
    /** @} */

    /** @name Tiles on disk
     * @{ */
    /** Writes the bins of allocated tile number t to `file` (in chain order, so reloadTile
     * restores each cell as it was) and frees the tile and its bins. Returns the bins written. */
    size_t spillTile(uint32_t t, const std::shared_ptr<TileStoreFile>& file);
    /** Whether tile (tx, ty) is on disk. */
    bool isSpilled(int tx, int ty) const {
        return !m_spilled.empty() && m_spilled.count(tileKey(tx, ty)) > 0;
    }
    size_t spilledTileCount() const { return m_spilled.size(); }
    /** Tiles written to disk and read back since the last reset. */
    size_t tilesSpilled() const { return m_tilesSpilled; }
    size_t tilesReloaded() const { return m_tilesReloaded; }
    bool hasSpilledTiles() const { return !m_spilled.empty(); }
    /** Calls f(tx, ty) for every tile on disk. */
    template <typename F>
    void forEachSpilledTile(F&& f) const {
        for (const auto& [key, record] : m_spilled) f(int32_t(key >> 32), int32_t(key));
    }
    /** If allocated tile number t (just added, empty) is on disk, reads its bins back into it
     * and calls onBin(slot, ix, iy, const Bin&) for each; false if it was not on disk. */
    template <typename OnBin>
    bool reloadTile(uint32_t t, OnBin&& onBin);
    /** Memory the allocated tiles and the bins in use take [bytes]: what a memory budget
     * bounds (the pool keeps its capacity, reused by the next bins). */
    size_t residentBytes() const {
        return tileCount() * (kTileSlots * sizeof(BinId) + kTileCells * sizeof(uint64_t)) +
               (binCount() - m_spilledBins) * sizeof(Bin) + m_groups.size() * sizeof(TileGroup);
    }
    /** @} */

    /** @name Bins
     * @{ */
    Bin& bin(BinId b) { return m_pool[b]; }
    const Bin& bin(BinId b) const { return m_pool[b]; }
    /** The bin of index n in the cell at `slot` (a writable one), appended to its chain (all
     * estimates zero) if missing; `added` tells which. */
    BinId findOrAddBin(size_t slot, int16_t n, bool& added);
    BinId findOrAddBin(size_t slot, int16_t n) {
        bool added;
        return findOrAddBin(slot, n, added);
    }
    /** Appends a bin with this estimate to the chain of the cell at `slot` (a writable one). */
    BinId appendBin(size_t slot, const BinEstimate& estimate);
    /** Whether the cell at `slot` holds a bin: one load, for loops over a tile's slots
     * (tileBase(tileNumber(tx, ty)) + slotInTile(ix, iy)) that skip empty cells; the window is
     * the caller's to check, as forEachBin does. */
    bool slotHoldsBins(size_t slot) const { return m_heads[slot] != kNoBin; }
    /** The cells of row r (0 .. kTileCells - 1, from the tile's first cell) of tile number t
     * that hold a bin: bit c for column c. A sparse tile's cells are found by its rows' bits,
     * 64 cells a word, instead of their slots. */
    uint64_t rowHoldingBins(uint32_t t, int r) const {
        return m_rowBits[(size_t(t) << kTileShift) + size_t(r)];
    }
    /** Calls f(const Bin&) for every bin of the cell, in chain order; nothing outside the
     * window. */
    template <typename F>
    void forEachBin(int ix, int iy, F&& f) const {
        if (!m_window.contains(ix, iy)) return;
        for (BinId b = m_heads[slot(ix, iy)]; b != kNoBin; b = m_pool[b].next) f(m_pool[b]);
    }
    /** Calls f(ix, iy, const Bin&) for every bin, tile by tile, row by row in a tile. */
    template <typename F>
    void forEachStoredBin(F&& f) const;
    /** Calls f(Bin&) for every bin of the cell; a bin for which f returns false is removed.
     * Returns the number of bins removed. */
    template <typename F>
    size_t editBins(int ix, int iy, F&& f);
    /** Removes every bin of one cell. */
    void clearCell(int ix, int iy);
    /** Number of bins in use, over all cells, those of tiles on disk included. */
    size_t binCount() const { return m_pool.size() - m_freeCount + m_spilledBins; }
    bool empty() const { return binCount() == 0; }
    /** Memory held [bytes]: the tiles' cell heads, the directory and the bin pool with its spare
     * capacity. */
    size_t memoryBytes() const {
        return m_heads.capacity() * sizeof(BinId) + m_rowBits.capacity() * sizeof(uint64_t) +
               m_groupTable.capacity() * sizeof(GroupKey) +
               m_groups.capacity() * sizeof(TileGroup) + m_tileXY.capacity() * sizeof(TileKey) +
               m_pool.capacity() * sizeof(Bin);
    }
    /** @} */

private:
    struct TileKey {
        int32_t tx = 0, ty = 0;
        bool allocated = false;
    };
    static uint64_t tileKey(int tx, int ty) { return uint64_t(uint32_t(tx)) << 32 | uint32_t(ty); }
    /** Where a tile on disk is: its record's offset in m_tileFile and its bin count. */
    struct SpilledTile {
        uint64_t offset = 0;
        uint32_t bins = 0;
    };
    /** Reads the record of a tile on disk: bins per cell (kTileSlots uint32), then the bins. */
    void readSpilled(const SpilledTile& record, std::vector<uint32_t>& counts,
                     std::vector<BinEstimate>& bins) const;
    /** Allocates tile (tx, ty) (reusing a freed one if any); returns its number. */
    uint32_t addTile(int tx, int ty);
    /** Frees an allocated tile whose cells hold no bin. */
    void freeTile(uint32_t t);
    /** A group of tiles in the hash table: its coordinates and number (0: an empty entry). */
    struct GroupKey {
        int32_t gx = 0, gy = 0;
        uint32_t group = 0;
    };
    /** The entry of m_groupTable where group (gx, gy) is, or the empty one where it would be. */
    size_t groupSlot(int gx, int gy) const {
        const uint64_t key = uint64_t(uint32_t(gx)) << 32 | uint32_t(gy);
        size_t h = size_t((key * 0x9E3779B97F4A7C15ull) >> m_groupHashShift);  // Fibonacci hashing
        while (m_groupTable[h].group != 0 && (m_groupTable[h].gx != gx || m_groupTable[h].gy != gy))
            h = (h + 1) & (m_groupTable.size() - 1);  // linear probing; never full (load <= 1/2)
        return h;
    }
    /** The number of group (gx, gy) in m_groups: 0 (the empty group) if none. */
    uint32_t groupNumber(int gx, int gy) const { return m_groupTable[groupSlot(gx, gy)].group; }
    /** The number of group (gx, gy), added (all its tiles absent) if missing. */
    uint32_t addGroup(int gx, int gy);
    /** The entry of tile (tx, ty) in its group, which must exist. */
    uint32_t& tileEntry(int tx, int ty);
    /** Tile numbers of a group of tiles, row-major; group 0 is all zero (no tile). */
    using TileGroup = std::array<uint32_t, size_t(kGroupTiles) * kGroupTiles>;
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
    std::vector<BinId> m_heads;  //!< per slot: the cell's first bin, or kNoBin
    /** Per tile row (slot >> kTileShift): bit c set when the row's slot c holds a bin (its
     * head is not kNoBin), kept by every write of a head. */
    std::vector<uint64_t> m_rowBits;
    static_assert(kTileCells == 64, "a tile row's cells are the bits of one word");
    void markHolding(size_t s) { m_rowBits[s >> kTileShift] |= uint64_t(1) << (s & 63); }
    void markEmpty(size_t s) { m_rowBits[s >> kTileShift] &= ~(uint64_t(1) << (s & 63)); }
    std::vector<TileKey> m_tileXY;       //!< per tile number: its tile coordinates (0: empty tile)
    std::vector<uint32_t> m_freeTiles;   //!< tile numbers freed, reused first
    std::vector<GroupKey> m_groupTable;  //!< open addressing, a power of two in size
    int m_groupHashShift = 60;           //!< 64 - log2(m_groupTable.size())
    std::vector<TileGroup> m_groups;     //!< [0]: the empty group
    std::vector<Bin> m_pool;             //!< all bins; free ones chained from m_freeHead
    BinId m_freeHead = kNoBin;
    size_t m_freeCount = 0;
    std::shared_ptr<TileStoreFile> m_tileFile;            //!< where spilled tiles are
    std::unordered_map<uint64_t, SpilledTile> m_spilled;  //!< tiles on disk, by tileKey
    size_t m_spilledBins = 0;                             //!< their bins
    size_t m_tilesSpilled = 0, m_tilesReloaded = 0;
};

template <typename OnBin>
bool BinStore::reloadTile(uint32_t t, OnBin&& onBin) {
    if (m_spilled.empty()) return false;
    const TileKey k = m_tileXY[t];
    const auto it = m_spilled.find(tileKey(k.tx, k.ty));
    if (it == m_spilled.end()) return false;
    std::vector<uint32_t> counts;
    std::vector<BinEstimate> bins;
    readSpilled(it->second, counts, bins);
    m_spilledBins -= it->second.bins;
    m_spilled.erase(it);
    m_tilesReloaded++;
    size_t next = 0;
    for (size_t place = 0; place < kTileSlots; place++) {
        const int ix = k.tx * kTileCells + int(place & (kTileCells - 1));
        const int iy = k.ty * kTileCells + int(place >> kTileShift);
        const size_t s = tileBase(t) + place;
        for (uint32_t j = 0; j < counts[place]; j++) {
            const BinId b = appendBin(s, bins[next++]);
            onBin(s, ix, iy, m_pool[b]);
        }
    }
    return true;
}

inline size_t BinStore::writableSlot(int ix, int iy, bool& tileAdded) {
    const int tx = tileOf(ix), ty = tileOf(iy);
    uint32_t t = tileNumber(tx, ty);
    tileAdded = t == 0;
    if (tileAdded) t = addTile(tx, ty);
    return tileBase(t) + slotInTile(ix, iy);
}

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
        if (prev == kNoBin) markHolding(s);
    }
    return b;
}

template <typename OnLeave, typename OnCleared>
void BinStore::moveWindowTo(int ix0, int iy0, OnLeave&& onLeave, OnCleared&& onCleared) {
    const CellWindow oldW = m_window;  // kept while leavers are read: onLeave may read them
    CellWindow newW = oldW;
    newW.ix0 = ix0;
    newW.iy0 = iy0;
    auto inside = [](const CellWindow& w, int x0, int y0) {  // a whole tile
        return x0 >= w.ix0 && y0 >= w.iy0 && x0 + kTileCells <= w.ix0 + w.nx &&
               y0 + kTileCells <= w.iy0 + w.ny;
    };
    for (uint32_t t = 1; t < m_tileXY.size(); t++) {
        if (!m_tileXY[t].allocated) continue;
        const int cx0 = m_tileXY[t].tx * kTileCells, cy0 = m_tileXY[t].ty * kTileCells;
        if (inside(newW, cx0, cy0)) continue;
        bool keepsACell = false;
        for (int iy = cy0; iy < cy0 + kTileCells; iy++)
            for (int ix = cx0; ix < cx0 + kTileCells; ix++) {
                if (newW.contains(ix, iy)) {
                    keepsACell = true;
                    continue;
                }
                if (!oldW.contains(ix, iy)) continue;
                const size_t s = tileBase(t) + slotInTile(ix, iy);
                if (m_heads[s] != kNoBin) {
                    onLeave(ix, iy);
                    releaseChain(m_heads[s]);
                    m_heads[s] = kNoBin;
                    markEmpty(s);
                }
                onCleared(s);
            }
        if (!keepsACell) freeTile(t);
    }
    m_window = newW;
}

template <typename F>
void BinStore::forEachStoredBin(F&& f) const {
    for (size_t t = 1; t < m_tileXY.size(); t++) {
        if (!m_tileXY[t].allocated) continue;
        const int cx0 = m_tileXY[t].tx * kTileCells, cy0 = m_tileXY[t].ty * kTileCells;
        const BinId* heads = m_heads.data() + tileBase(uint32_t(t));
        for (int r = 0; r < kTileCells; r++)
            for (uint64_t cells = rowHoldingBins(uint32_t(t), r); cells != 0;
                 cells &= cells - 1) {  // the row's cells holding bins, west to east
                const int c = __builtin_ctzll(cells);
                for (BinId b = heads[r * kTileCells + c]; b != kNoBin; b = m_pool[b].next)
                    f(cx0 + c, cy0 + r, m_pool[b]);
            }
    }
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
    if (m_heads[s] == kNoBin) markEmpty(s);
    return removed;
}

}  // namespace multibin
