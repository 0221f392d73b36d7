/* Part of the multibin elevation-mapping library. */
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <unordered_map>
#include <vector>

namespace multibin::fill {

/** Values of type T on the cells of an unbounded lattice, stored in tiles of kSide x kSide cells
 * allocated on first write (a hash table finds them), so memory follows the cells written, not
 * their bounding box; an unwritten cell reads `empty`. A tile's address never changes. The fill's
 * sparse input, its labels and its result (SparseFill.h). */
template <typename T>
class TiledCells {
public:
    static constexpr int kShift = 6;
    static constexpr int kSide = 1 << kShift;  //!< tile side [cells], as the grid's tiles
    static constexpr size_t kTileCells = size_t(kSide) * kSide;
    using Tile = std::array<T, kTileCells>;

    TiledCells() = default;
    explicit TiledCells(const T& empty) : m_empty(empty) {}
    TiledCells(const TiledCells& o) : m_empty(o.m_empty), m_index(o.m_index), m_xy(o.m_xy) {
        for (const auto& t : o.m_tiles) m_tiles.push_back(std::make_unique<Tile>(*t));
    }
    TiledCells& operator=(const TiledCells& o) {
        if (this != &o) *this = TiledCells(o);
        return *this;
    }
    TiledCells(TiledCells&&) noexcept = default;
    TiledCells& operator=(TiledCells&&) noexcept = default;

    /** The value of cell (ix, iy): `empty` if its tile was never written. */
    const T& get(int ix, int iy) const {
        const auto it = m_index.find(key(ix >> kShift, iy >> kShift));
        return it == m_index.end() ? m_empty : (*m_tiles[it->second])[inTile(ix, iy)];
    }
    /** The value of cell (ix, iy), its tile allocated (all `empty`) if it had none. */
    T& at(int ix, int iy) { return tile(ix >> kShift, iy >> kShift)[inTile(ix, iy)]; }
    /** The tile (tx, ty), allocated (all `empty`) if missing. */
    Tile& tile(int tx, int ty) {
        const auto [it, added] = m_index.try_emplace(key(tx, ty), uint32_t(m_tiles.size()));
        if (added) {
            m_tiles.push_back(std::make_unique<Tile>());
            m_tiles.back()->fill(m_empty);
            m_xy.push_back({tx, ty});
        }
        return *m_tiles[it->second];
    }
    /** The tile (tx, ty), or nullptr if it was never written. */
    const Tile* findTile(int tx, int ty) const {
        const auto it = m_index.find(key(tx, ty));
        return it == m_index.end() ? nullptr : m_tiles[it->second].get();
    }
    /** Calls f(tx, ty, const Tile&) for every tile, in allocation order. */
    template <typename F>
    void forEachTile(F&& f) const {
        for (size_t t = 0; t < m_tiles.size(); t++) f(m_xy[t][0], m_xy[t][1], *m_tiles[t]);
    }
    size_t tileCount() const { return m_tiles.size(); }
    /** The value of a cell never written. */
    const T& empty() const { return m_empty; }
    /** Memory held [bytes]: the tiles and the hash table's nodes (about 32 B per tile). */
    size_t memoryBytes() const {
        return m_tiles.size() * sizeof(Tile) + m_tiles.capacity() * sizeof(m_tiles[0]) +
               m_xy.capacity() * sizeof(m_xy[0]) + m_index.size() * 32 +
               m_index.bucket_count() * sizeof(void*);
    }
    /** Cell (ix, iy)'s place in its tile, row-major. */
    static size_t inTile(int ix, int iy) {
        return (size_t(iy & (kSide - 1)) << kShift) + size_t(ix & (kSide - 1));
    }

private:
    static uint64_t key(int tx, int ty) { return uint64_t(uint32_t(tx)) << 32 | uint32_t(ty); }

    T m_empty{};
    std::unordered_map<uint64_t, uint32_t> m_index;  // tile key -> its number
    std::vector<std::unique_ptr<Tile>> m_tiles;      // pointers stay valid as tiles are added
    std::vector<std::array<int, 2>> m_xy;            // per tile number: (tx, ty)
};

}  // namespace multibin::fill
