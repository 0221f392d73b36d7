/* Part of the multibin elevation-mapping library. */
#include "multibin/BinGrid.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace multibin {

InsertStats& InsertStats::operator+=(const InsertStats& o) {
    accepted += o.accepted;
    outOfRange += o.outOfRange;
    notFinite += o.notFinite;
    badCovariance += o.badCovariance;
    outsideMap += o.outsideMap;
    outsideBinRange += o.outsideBinRange;
    tooUncertain += o.tooUncertain;
    continuityRejected += o.continuityRejected;
    return *this;
}

BinGrid::BinGrid(double cellSize_m) { reset(cellSize_m, CellWindow{}); }

void BinGrid::reset(double cellSize_m, const CellWindow& window) {
    if (!(cellSize_m > 0) || !std::isfinite(cellSize_m))
        throw std::invalid_argument("BinGrid: cell size must be positive and finite, got " +
                                    std::to_string(cellSize_m));
    if (window.nx < 0 || window.ny < 0)
        throw std::invalid_argument("BinGrid: negative window size");
    m_cellSize_m = cellSize_m;
    m_invCellSize = 1.0 / cellSize_m;
    setWindow(window);
    m_heads.assign(window.cellCount(), kNoBin);
    m_stamp.assign(window.cellCount(), 0);
    m_updatedIndex.assign(window.cellCount(), 0);
    m_updated.clear();
    m_maxHeight_m = -std::numeric_limits<double>::infinity();
    m_pool.clear();
    m_freeHead = kNoBin;
    m_freeCount = 0;
}

void BinGrid::growToInclude(const CellWindow& w) {
    if (w.nx <= 0 || w.ny <= 0) return;
    CellWindow nw;
    if (m_window.nx == 0 || m_window.ny == 0) {
        nw = w;
    } else {
        nw.ix0 = std::min(m_window.ix0, w.ix0);
        nw.iy0 = std::min(m_window.iy0, w.iy0);
        nw.nx = std::max(m_window.ix0 + m_window.nx, w.ix0 + w.nx) - nw.ix0;
        nw.ny = std::max(m_window.iy0 + m_window.ny, w.iy0 + w.ny) - nw.iy0;
    }
    if (nw == m_window) return;
    std::vector<uint32_t> heads(nw.cellCount(), kNoBin);
    const CellWindow old = m_window;
    for (int iy = old.iy0; iy < old.iy0 + old.ny; iy++)
        for (int ix = old.ix0; ix < old.ix0 + old.nx; ix++) {
            const uint32_t h = m_heads[slot(ix, iy)];
            if (h == kNoBin) continue;
            int sx = ix % nw.nx, sy = iy % nw.ny;
            if (sx < 0) sx += nw.nx;
            if (sy < 0) sy += nw.ny;
            heads[size_t(sx) + size_t(sy) * size_t(nw.nx)] = h;
        }
    m_heads.swap(heads);
    setWindow(nw);
    // Growth happens between update cycles: the cycle bookkeeping starts afresh.
    m_stamp.assign(nw.cellCount(), 0);
    m_updatedIndex.assign(nw.cellCount(), 0);
    m_updated.clear();
}

void BinGrid::setWindow(const CellWindow& w) {
    m_window = w;
    auto residue = [](int i, int n) { return n > 0 ? ((i % n) + n) % n : 0; };
    m_originSlotX = residue(w.ix0, w.nx);
    m_originSlotY = residue(w.iy0, w.ny);
}

void BinGrid::beginCycle() {
    m_updated.clear();
    if (++m_cycle == 0) {  // wrapped: no stale stamp may match the new cycle
        std::fill(m_stamp.begin(), m_stamp.end(), 0);
        m_cycle = 1;
    }
}

void BinGrid::noteUpdate(size_t s, int ix, int iy, double height_m) {
    m_maxHeight_m = std::max(m_maxHeight_m, height_m);
    if (m_stamp[s] != m_cycle) {
        m_stamp[s] = m_cycle;
        m_updatedIndex[s] = static_cast<uint32_t>(m_updated.size());
        m_updated.push_back({ix, iy, float(height_m), 1});
    } else {
        UpdatedCell& u = m_updated[m_updatedIndex[s]];
        u.maxHeight_m = std::max(u.maxHeight_m, float(height_m));
        u.points++;
    }
}

uint32_t BinGrid::allocateBin() {
    if (m_freeHead != kNoBin) {
        const uint32_t b = m_freeHead;
        m_freeHead = m_pool[b].next;
        m_freeCount--;
        m_pool[b] = Bin{};
        return b;
    }
    if (m_pool.size() >= kNoBin - 1) throw std::length_error("BinGrid: bin pool is full");
    m_pool.emplace_back();
    return static_cast<uint32_t>(m_pool.size() - 1);
}

void BinGrid::releaseChain(uint32_t head) {
    while (head != kNoBin) {
        const uint32_t next = m_pool[head].next;
        m_pool[head].next = m_freeHead;
        m_freeHead = head;
        m_freeCount++;
        head = next;
    }
}

void BinGrid::clearCell(int ix, int iy) {
    if (!m_window.contains(ix, iy)) return;
    uint32_t& head = m_heads[slot(ix, iy)];
    releaseChain(head);
    head = kNoBin;
}

void BinGrid::appendBin(int ix, int iy, const Bin& bin) {
    if (!m_window.contains(ix, iy))
        throw std::out_of_range("BinGrid::appendBin: cell outside the window");
    const uint32_t b = allocateBin();  // may reallocate the pool: hold indices, not pointers
    m_pool[b] = bin;
    m_pool[b].next = kNoBin;
    m_maxHeight_m = std::max(m_maxHeight_m, double(bin.height_m));
    const size_t s = slot(ix, iy);
    uint32_t last = m_heads[s];
    if (last == kNoBin) {
        m_heads[s] = b;
        return;
    }
    while (m_pool[last].next != kNoBin) last = m_pool[last].next;
    m_pool[last].next = b;
}

void BinGrid::fuseBin(int ix, int iy, const Bin& other, const BinUpdateParams& params) {
    if (!m_window.contains(ix, iy))
        throw std::out_of_range("BinGrid::fuseBin: cell outside the window");
    const double binPos = std::floor(other.height_m / params.binHeight_m);
    if (!(binPos >= std::numeric_limits<int16_t>::min() &&
          binPos <= std::numeric_limits<int16_t>::max()))
        return;
    const auto n = static_cast<int16_t>(binPos);
    const size_t s = slot(ix, iy);
    uint32_t prev = kNoBin, b = m_heads[s];
    while (b != kNoBin && m_pool[b].index != n) {
        prev = b;
        b = m_pool[b].next;
    }
    if (b == kNoBin) {
        b = allocateBin();
        m_pool[b] = other;
        m_pool[b].index = n;
        m_pool[b].next = kNoBin;
        (prev == kNoBin ? m_heads[s] : m_pool[prev].next) = b;
        m_maxHeight_m = std::max(m_maxHeight_m, double(other.height_m));
        return;
    }
    Bin& bin = m_pool[b];
    const double v1 = bin.variance_m2, v2 = other.variance_m2;
    const double K = v1 + v2 > 0 ? v1 / (v1 + v2) : 0.5;
    bin.height_m = static_cast<float>(bin.height_m - K * (bin.height_m - other.height_m));
    bin.variance_m2 = static_cast<float>((1.0 - K) * v1);
    bin.certainty += other.certainty;
    bin.pointCount += other.pointCount;
    m_maxHeight_m = std::max(m_maxHeight_m, double(bin.height_m));
}

const Bin* BinGrid::winningBin(int ix, int iy) const {
    if (!m_window.contains(ix, iy)) return nullptr;
    const Bin* best = nullptr;
    for (uint32_t b = m_heads[slot(ix, iy)]; b != kNoBin; b = m_pool[b].next) {
        const Bin& bin = m_pool[b];
        if (!(bin.certainty > 0)) continue;
        if (!best || bin.certainty > best->certainty ||
            (bin.certainty == best->certainty && bin.variance_m2 < best->variance_m2))
            best = &bin;
    }
    return best;
}

bool BinGrid::insertHeight(int ix, int iy, double height_m, double variance_m2,
                           const BinUpdateParams& params, double continuityBound_m,
                           InsertStats& stats) {
    // Eq 13 gate: the 99.7 % interval of the measured height must be within Delta_max.
    if (9.0 * variance_m2 > params.maxElevationUncertainty_m * params.maxElevationUncertainty_m) {
        stats.tooUncertain++;
        return false;
    }
    const double binPos = std::floor(height_m / params.binHeight_m);
    if (!(binPos >= std::numeric_limits<int16_t>::min() &&
          binPos <= std::numeric_limits<int16_t>::max())) {
        stats.outsideBinRange++;
        return false;
    }
    const auto n = static_cast<int16_t>(binPos);

    const size_t s = slot(ix, iy);
    uint32_t prev = kNoBin, b = m_heads[s];
    while (b != kNoBin && m_pool[b].index != n) {
        prev = b;
        b = m_pool[b].next;
    }
    if (b == kNoBin) {
        b = allocateBin();  // may reallocate the pool: hold indices, not pointers
        m_pool[b].index = n;
        m_pool[b].next = kNoBin;
        (prev == kNoBin ? m_heads[s] : m_pool[prev].next) = b;
    }
    Bin& bin = m_pool[b];

    // Eq 14: a laser point must agree with a bin that is already certain (c > 0); a bin without
    // certainty has no height to compare against and accepts the point.
    if (bin.certainty > 0 && std::abs(height_m - bin.height_m) > continuityBound_m) {
        stats.continuityRejected++;
        return false;
    }
    bin.certainty += params.certaintyIncrement;
    // Eq 15, a static 1-D Kalman filter; the first point initialises the bin.
    if (bin.pointCount == 0) {
        bin.height_m = static_cast<float>(height_m);
        bin.variance_m2 = static_cast<float>(variance_m2);
    } else {
        const double var = bin.variance_m2;
        const double K = var / (var + variance_m2);
        bin.height_m = static_cast<float>(bin.height_m - K * (bin.height_m - height_m));
        bin.variance_m2 = static_cast<float>((1.0 - K) * var);
    }
    bin.pointCount++;
    stats.accepted++;
    noteUpdate(s, ix, iy, height_m);
    return true;
}

InsertStats BinGrid::insertPoints(const PointsWithCov& mapPoints, const BinUpdateParams& params,
                                  double continuityBound_m) {
    InsertStats stats;
    for (const PointWithCov& p : mapPoints) {
        const SymmetricCov3& c = p.cov_m2;
        if (!std::isfinite(p.point_m.x()) || !std::isfinite(p.point_m.y()) ||
            !std::isfinite(p.point_m.z()) || !std::isfinite(c.xx) || !std::isfinite(c.xy) ||
            !std::isfinite(c.xz) || !std::isfinite(c.yy) || !std::isfinite(c.yz) ||
            !std::isfinite(c.zz)) {
            stats.notFinite++;
            continue;
        }
        // Positive-definite by Sylvester's criterion (leading minors), in double.
        const double m1 = c.xx, m2 = double(c.xx) * c.yy - double(c.xy) * c.xy;
        const double m3 = c.xx * (double(c.yy) * c.zz - double(c.yz) * c.yz) -
                          c.xy * (double(c.xy) * c.zz - double(c.yz) * c.xz) +
                          c.xz * (double(c.xy) * c.yz - double(c.yy) * c.xz);
        if (!(m1 > 0 && m2 > 0 && m3 > 0)) {
            stats.badCovariance++;
            continue;
        }
        const int ix = cellIndex(p.point_m.x()), iy = cellIndex(p.point_m.y());
        if (!m_window.contains(ix, iy)) {
            stats.outsideMap++;
            continue;
        }
        insertHeight(ix, iy, p.point_m.z(), c.zz, params, continuityBound_m, stats);
    }
    return stats;
}

}  // namespace multibin
