/* Part of the multibin elevation-mapping library. */
#pragma once

#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace multibin::fill {

/** Values of type T on the cells of an unbounded lattice, stored in tiles of kSide x kSide cells
 * allocated on first write (a hash table finds them), so memory follows the cells written, not
 * their bounding box; an unwritten cell reads `empty`. The tiles share one array (freed whole,
 * not left as holes in the heap); a pointer into it holds until the next tile is added. The
 * fill's sparse input, its labels and its result (SparseFill.h). */
template <typename T>
class TiledCells {
public:
    static constexpr int kShift = 6;
    static constexpr int kSide = 1 << kShift;  //!< tile side [cells], as the grid's tiles
    static constexpr size_t kTileCells = size_t(kSide) * kSide;

    TiledCells() = default;
    explicit TiledCells(const T& empty) : m_empty(empty) {}

    /** The value of cell (ix, iy): `empty` if its tile was never written. */
    const T& get(int ix, int iy) const {
        const T* t = findTile(ix >> kShift, iy >> kShift);
        return t ? t[inTile(ix, iy)] : m_empty;
    }
    /** The value of cell (ix, iy), its tile added (all `empty`) if it had none. */
    T& at(int ix, int iy) { return tile(ix >> kShift, iy >> kShift)[inTile(ix, iy)]; }
    /** The kTileCells cells of tile (tx, ty), row-major, the tile added (all `empty`) if missing.
     */
    T* tile(int tx, int ty) { return tileCells(tileNumber(tx, ty)); }
    /** Room for `tiles` tiles in all: adding them then copies no tile (the tiles' array grows by
     * reallocation otherwise, each copy touching fresh pages). */
    void reserve(size_t tiles) {
        m_cells.reserve(tiles * kTileCells);
        m_xy.reserve(tiles);
        m_index.reserve(tiles);
    }
    /** Tile (tx, ty)'s number (the order of addition; it never changes), the tile added (all
     * `empty`) if missing. */
    size_t tileNumber(int tx, int ty) {
        const auto [it, added] = m_index.try_emplace(key(tx, ty), uint32_t(m_xy.size()));
        if (added) {
            m_cells.resize(m_cells.size() + kTileCells, m_empty);
            m_xy.push_back({tx, ty});
        }
        return it->second;
    }
    /** Tile (tx, ty)'s number, or -1 if it was never written. */
    long findTileNumber(int tx, int ty) const {
        const auto it = m_index.find(key(tx, ty));
        return it == m_index.end() ? -1 : long(it->second);
    }
    /** The kTileCells cells of tile number `n` (< tileCount()), row-major. */
    T* tileCells(size_t n) { return m_cells.data() + n * kTileCells; }
    const T* tileCells(size_t n) const { return m_cells.data() + n * kTileCells; }
    /** The cells of tile (tx, ty), or nullptr if it was never written. */
    const T* findTile(int tx, int ty) const {
        const long n = findTileNumber(tx, ty);
        return n < 0 ? nullptr : tileCells(size_t(n));
    }
    /** Calls f(tx, ty, const T* cells) for every tile (kTileCells cells), in order of addition
     * (tile number 0, 1, ...). */
    template <typename F>
    void forEachTile(F&& f) const {
        for (size_t t = 0; t < m_xy.size(); t++)
            f(m_xy[t].tx, m_xy[t].ty, m_cells.data() + t * kTileCells);
    }
    size_t tileCount() const { return m_xy.size(); }
    /** The value of a cell never written. */
    const T& empty() const { return m_empty; }
    /** Memory held [bytes]: the tiles and the hash table's nodes (about 32 B per tile). */
    size_t memoryBytes() const {
        return m_cells.capacity() * sizeof(T) + m_xy.capacity() * sizeof(TileXY) +
               m_index.size() * 32 + m_index.bucket_count() * sizeof(void*);
    }
    /** Cell (ix, iy)'s place in its tile, row-major. */
    static size_t inTile(int ix, int iy) {
        return (size_t(iy & (kSide - 1)) << kShift) + size_t(ix & (kSide - 1));
    }

private:
    struct TileXY {
        int tx, ty;
    };
    static uint64_t key(int tx, int ty) { return uint64_t(uint32_t(tx)) << 32 | uint32_t(ty); }

    T m_empty{};
    std::unordered_map<uint64_t, uint32_t> m_index;  // tile key -> its number
    std::vector<T> m_cells;                          // tile number * kTileCells + inTile
    std::vector<TileXY> m_xy;                        // per tile number: (tx, ty)
};

}  // namespace multibin::fill
