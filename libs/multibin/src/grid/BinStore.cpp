/* Part of the multibin elevation-mapping library. */
#include "multibin/grid/BinStore.h"

#include <algorithm>
#include <cmath>
#include <cstring>
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
    m_window = window;
    m_heads.assign(kTileSlots, kNoBin);  // the empty tile
    m_rowBits.assign(kTileCells, 0);
    m_tileXY.assign(1, TileKey{});
    m_freeTiles.clear();
    m_groupTable.assign(16, GroupKey{});
    m_groupHashShift = 64 - 4;
    m_groups.assign(1, TileGroup{});  // value-initialised: all zero
    m_pool.clear();
    m_freeHead = kNoBin;
    m_freeCount = 0;
    m_spilled.clear();
    m_spilledBins = 0;
    m_tilesSpilled = m_tilesReloaded = 0;
    m_tileFile.reset();
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
    m_window = nw;
    return true;
}

uint32_t BinStore::addGroup(int gx, int gy) {
    size_t h = groupSlot(gx, gy);
    if (m_groupTable[h].group != 0) return m_groupTable[h].group;
    if (2 * m_groups.size() > m_groupTable.size()) {  // load above 1/2 with this one: rehash
        std::vector<GroupKey> old(2 * m_groupTable.size());
        old.swap(m_groupTable);
        m_groupHashShift--;
        for (const GroupKey& k : old)
            if (k.group != 0) m_groupTable[groupSlot(k.gx, k.gy)] = k;
        h = groupSlot(gx, gy);
    }
    const uint32_t group = static_cast<uint32_t>(m_groups.size());
    m_groups.emplace_back().fill(0);
    m_groupTable[h] = GroupKey{gx, gy, group};
    return group;
}

uint32_t BinStore::addTile(int tx, int ty) {
    addGroup(tx >> kGroupShift, ty >> kGroupShift);
    uint32_t t;
    if (!m_freeTiles.empty()) {
        t = m_freeTiles.back();
        m_freeTiles.pop_back();
    } else {
        if (m_heads.size() + kTileSlots > size_t(std::numeric_limits<uint32_t>::max()))
            throw std::length_error("BinGrid: more tiles than slots can number");
        t = static_cast<uint32_t>(m_tileXY.size());
        m_tileXY.emplace_back();
        m_heads.resize(m_heads.size() + kTileSlots, kNoBin);
        m_rowBits.resize(m_rowBits.size() + kTileCells, 0);
    }
    m_tileXY[t] = TileKey{tx, ty, true};
    tileEntry(tx, ty) = t;
    return t;
}

uint32_t& BinStore::tileEntry(int tx, int ty) {
    return m_groups[groupNumber(tx >> kGroupShift, ty >> kGroupShift)]
                   [size_t(ty & (kGroupTiles - 1)) * kGroupTiles + size_t(tx & (kGroupTiles - 1))];
}

void BinStore::freeTile(uint32_t t) {
    TileKey& k = m_tileXY[t];
    tileEntry(k.tx, k.ty) = 0;
    k.allocated = false;
    m_freeTiles.push_back(t);
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
    const size_t s = slot(ix, iy);
    if (m_heads[s] == kNoBin) return;  // the empty tile's heads among them
    releaseChain(m_heads[s]);
    m_heads[s] = kNoBin;
    markEmpty(s);
}

BinStore::BinId BinStore::appendBin(size_t s, const BinEstimate& estimate) {
    const BinId b = allocateBin();  // may reallocate the pool: hold indices, not pointers
    static_cast<BinEstimate&>(m_pool[b]) = estimate;
    m_pool[b].next = kNoBin;
    BinId last = m_heads[s];
    if (last == kNoBin) {
        m_heads[s] = b;
        markHolding(s);
        return b;
    }
    while (m_pool[last].next != kNoBin) last = m_pool[last].next;
    m_pool[last].next = b;
    return b;
}

size_t BinStore::spillTile(uint32_t t, const std::shared_ptr<TileStoreFile>& file) {
    // One record: bins per cell, then the bins in cell and chain order.
    std::vector<uint32_t> counts(kTileSlots, 0);
    std::vector<BinEstimate> bins;
    BinId* heads = m_heads.data() + tileBase(t);
    for (size_t place = 0; place < kTileSlots; place++) {
        for (BinId b = heads[place]; b != kNoBin; b = m_pool[b].next) {
            bins.push_back(m_pool[b]);
            counts[place]++;
        }
    }
    std::vector<char> record(kTileSlots * sizeof(uint32_t) + bins.size() * sizeof(BinEstimate));
    std::memcpy(record.data(), counts.data(), kTileSlots * sizeof(uint32_t));
    if (!bins.empty())
        std::memcpy(record.data() + kTileSlots * sizeof(uint32_t), bins.data(),
                    bins.size() * sizeof(BinEstimate));
    const uint64_t offset = file->append(record.data(), record.size());  // throws: tile kept
    for (size_t place = 0; place < kTileSlots; place++) {
        releaseChain(heads[place]);
        heads[place] = kNoBin;
    }
    std::fill_n(m_rowBits.begin() + std::ptrdiff_t(size_t(t) << kTileShift), kTileCells, 0);
    const TileKey k = m_tileXY[t];
    m_spilled[tileKey(k.tx, k.ty)] = SpilledTile{offset, uint32_t(bins.size())};
    m_spilledBins += bins.size();
    m_tilesSpilled++;
    m_tileFile = file;
    freeTile(t);
    return bins.size();
}

void BinStore::readSpilled(const SpilledTile& record, std::vector<uint32_t>& counts,
                           std::vector<BinEstimate>& bins) const {
    counts.resize(kTileSlots);
    bins.resize(record.bins);
    m_tileFile->read(record.offset, counts.data(), kTileSlots * sizeof(uint32_t));
    uint64_t total = 0;
    for (uint32_t c : counts) total += c;
    if (total != record.bins)
        throw std::runtime_error(
            "CMultiBinElevationMap: a tile read back from the tile store in '" +
            m_tileFile->directory() + "' does not hold the bins written");
    if (record.bins > 0)
        m_tileFile->read(record.offset + kTileSlots * sizeof(uint32_t), bins.data(),
                         bins.size() * sizeof(BinEstimate));
}

}  // namespace multibin
