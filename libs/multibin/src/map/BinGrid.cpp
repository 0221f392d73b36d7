/* Part of the multibin elevation-mapping library. */
#include "multibin/map/BinGrid.h"

#include <array>

#include "multibin/geometry/PosePropagation.h"

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
    m_cells.assign(window.cellCount(), CellSlot{});
    m_blocks.assign(size_t(m_blockNx) * size_t(m_blockNy), BlockSlot{});
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
    std::vector<CellSlot> cells(nw.cellCount());
    const CellWindow old = m_window;
    for (int iy = old.iy0; iy < old.iy0 + old.ny; iy++)
        for (int ix = old.ix0; ix < old.ix0 + old.nx; ix++) {
            const uint32_t h = m_cells[slot(ix, iy)].head;
            if (h == kNoBin) continue;
            int sx = ix % nw.nx, sy = iy % nw.ny;
            if (sx < 0) sx += nw.nx;
            if (sy < 0) sy += nw.ny;
            cells[size_t(sx) + size_t(sy) * size_t(nw.nx)].head = h;
        }
    m_cells.swap(cells);
    setWindow(nw);
    rebuildBlocks();
    // Growth happens between update cycles: the cycle bookkeeping starts afresh (the new slots
    // carry no stamp).
    m_updated.clear();
}

void BinGrid::setWindow(const CellWindow& w) {
    m_window = w;
    m_originSlotX = residue(w.ix0, w.nx);
    m_originSlotY = residue(w.iy0, w.ny);
    // One block more than the window spans at most, so the blocks meeting it never share a slot.
    m_blockX0 = blockOf(w.ix0);
    m_blockY0 = blockOf(w.iy0);
    m_blockNx = w.nx > 0 ? (w.nx + kBlockCells - 1) / kBlockCells + 1 : 0;
    m_blockNy = w.ny > 0 ? (w.ny + kBlockCells - 1) / kBlockCells + 1 : 0;
    m_blockOriginX = residue(m_blockX0, m_blockNx);
    m_blockOriginY = residue(m_blockY0, m_blockNy);
    m_lastBlockX = std::numeric_limits<int>::min();
}

void BinGrid::rebuildBlocks() {
    m_blocks.assign(size_t(m_blockNx) * size_t(m_blockNy), BlockSlot{});
    m_lastBlockX = std::numeric_limits<int>::min();
    const CellWindow& w = m_window;
    for (int iy = w.iy0; iy < w.iy0 + w.ny; iy++)
        for (int ix = w.ix0; ix < w.ix0 + w.nx; ix++)
            for (uint32_t b = m_cells[slot(ix, iy)].head; b != kNoBin; b = m_pool[b].next)
                raiseBlock(ix, iy, m_pool[b].height_m);
}

void BinGrid::beginCycle() {
    m_updated.clear();
    if (++m_cycle == 0) {  // wrapped: no stale stamp may match the new cycle
        for (CellSlot& cs : m_cells) cs.cycle = 0;
        m_cycle = 1;
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
    uint32_t& head = m_cells[slot(ix, iy)].head;
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
    raiseBlock(ix, iy, bin.height_m);
    const size_t s = slot(ix, iy);
    uint32_t last = m_cells[s].head;
    if (last == kNoBin) {
        m_cells[s].head = b;
        return;
    }
    while (m_pool[last].next != kNoBin) last = m_pool[last].next;
    m_pool[last].next = b;
}

void BinGrid::fuseBin(int ix, int iy, const Bin& other, const BinUpdateParams& params) {
    if (!m_window.contains(ix, iy))
        throw std::out_of_range("BinGrid::fuseBin: cell outside the window");
    int16_t n;
    if (!binIndexOf(other.height_m, params.binHeight_m, n)) return;
    const size_t s = slot(ix, iy);
    uint32_t prev = kNoBin, b = m_cells[s].head;
    while (b != kNoBin && m_pool[b].index != n) {
        prev = b;
        b = m_pool[b].next;
    }
    if (b == kNoBin) {
        b = allocateBin();
        m_pool[b] = other;
        m_pool[b].index = n;
        m_pool[b].next = kNoBin;
        (prev == kNoBin ? m_cells[s].head : m_pool[prev].next) = b;
        m_maxHeight_m = std::max(m_maxHeight_m, double(other.height_m));
        raiseBlock(ix, iy, other.height_m);
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
    raiseBlock(ix, iy, bin.height_m);
}

const Bin* BinGrid::winningBin(int ix, int iy) const {
    if (!m_window.contains(ix, iy)) return nullptr;
    const Bin* best = nullptr;
    for (uint32_t b = m_cells[slot(ix, iy)].head; b != kNoBin; b = m_pool[b].next) {
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
    if (!params.passesEq13(variance_m2)) {
        stats.tooUncertain++;
        return false;
    }
    int16_t n;
    if (!binIndexOf(height_m, params.binHeight_m, n)) {
        stats.outsideBinRange++;
        return false;
    }
    return fuseMeasurement(slot(ix, iy), ix, iy, n, height_m, variance_m2, params,
                           continuityBound_m, stats);
}

bool BinGrid::fuseMeasurement(size_t s, int ix, int iy, int16_t n, double height_m,
                              double variance_m2, const BinUpdateParams& params,
                              double continuityBound_m, InsertStats& stats) {
    Bin& bin = m_pool[findOrAddBin(s, n)];
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
    noteUpdate(s, ix, iy, height_m, 1);
    return true;
}

namespace {

/** Points classified per block before the sequential bin update. */
constexpr size_t kPointBlock = 256;

enum PointStatus : uint8_t {
    kAccept,
    kNotFinite,
    kBadCovariance,
    kOutsideMap,
    kTooUncertain,
    kOutsideBinRange,
    kStatusCount
};

/** Per-point results of the classification pass over one block. */
struct ClassifiedBlock {
    uint8_t status[kPointBlock];
    int16_t bin[kPointBlock];
    int32_t ix[kPointBlock], iy[kPointBlock];
    uint32_t slot[kPointBlock];
};

}  // namespace

InsertStats BinGrid::insertPoints(const PointsWithCov& mapPoints, const BinUpdateParams& params,
                                  double continuityBound_m) {
    return insertPoints(mapPoints.data(), mapPoints.size(), params, continuityBound_m);
}

InsertStats BinGrid::insertPoints(const PointWithCov* mapPoints, size_t count,
                                  const BinUpdateParams& params, double continuityBound_m) {
    return insertBlocks(
        count, [mapPoints](size_t begin, size_t) { return mapPoints + begin; }, params,
        continuityBound_m);
}

InsertStats BinGrid::insertSensorPoints(const PosePropagator& propagator,
                                        const PointsWithCov& sensorPoints,
                                        const BinUpdateParams& params, double continuityBound_m) {
    // One classification block of map-frame points at a time (9 kB, stays in the L1 cache).
    std::array<PointWithCov, kPointBlock> mapPoints;
    return insertBlocks(
        sensorPoints.size(),
        [&](size_t begin, size_t m) {
            propagator.apply(sensorPoints.data() + begin, mapPoints.data(), m);
            return static_cast<const PointWithCov*>(mapPoints.data());
        },
        params, continuityBound_m);
}

template <typename BlockSource>
InsertStats BinGrid::insertBlocks(size_t count, BlockSource&& blockAt,
                                  const BinUpdateParams& params, double continuityBound_m) {
    InsertStats stats;
    // Eq 14 compares each laser point with the bin height left by the previous point, so with a
    // finite bound points are fused one by one. Without it (stereo, depth: eq 13 only) a run of
    // consecutive points falling into the same bin is fused at once in information form,
    // 1/var = 1/var0 + sum 1/var_i, h/var = h0/var0 + sum h_i/var_i: the same estimate as the
    // sequential filter up to rounding, without a division chained through every point.
    const bool perPoint = continuityBound_m < std::numeric_limits<double>::infinity();
    const CellWindow w = m_window;

    // The open run: consecutive accepted points in one bin.
    struct Run {
        uint32_t bin = kNoBin;
        size_t slot = 0;
        int16_t n = 0;
        int ix = 0, iy = 0;
        uint32_t points = 0;
        double information = 0;     // 1/var [1/m^2]
        double weightedHeight = 0;  // h/var [1/m]
        double maxHeight_m = 0;
        bool frozen = false;  // the bin has zero variance: its height cannot move
    } run;
    auto closeRun = [&]() {
        if (run.bin == kNoBin) return;
        Bin& bin = m_pool[run.bin];
        if (!run.frozen) {
            const double var = 1.0 / run.information;
            bin.height_m = static_cast<float>(run.weightedHeight * var);
            bin.variance_m2 = static_cast<float>(var);
        }
        for (uint32_t k = 0; k < run.points; k++) bin.certainty += params.certaintyIncrement;
        bin.pointCount += run.points;
        noteUpdate(run.slot, run.ix, run.iy, run.maxHeight_m, run.points);
        run.bin = kNoBin;
    };

    ClassifiedBlock cb;
    size_t rejected[kStatusCount] = {};
    for (size_t begin = 0; begin < count; begin += kPointBlock) {
        const size_t m = std::min(kPointBlock, count - begin);
        const PointWithCov* pts = blockAt(begin, m);
        // Pass 1, no bin access: validity, gates that need only the point, cell and bin index.
        for (size_t i = 0; i < m; i++) {
            const PointWithCov& p = pts[i];
            const SymmetricCov3& c = p.cov_m2;
            // All nine values finite iff their sum in double is (nine floats cannot overflow a
            // double; a NaN or infinity makes the sum NaN or infinite): one test, no branches.
            const double sum = double(p.point_m.x()) + double(p.point_m.y()) +
                               double(p.point_m.z()) + double(c.xx) + double(c.xy) + double(c.xz) +
                               double(c.yy) + double(c.yz) + double(c.zz);
            if (!(sum - sum == 0.0)) {
                cb.status[i] = kNotFinite;
                continue;
            }
            // Positive-definite by Sylvester's criterion (leading minors), in double.
            const double m1 = c.xx, m2 = double(c.xx) * c.yy - double(c.xy) * c.xy;
            const double m3 = c.xx * (double(c.yy) * c.zz - double(c.yz) * c.yz) -
                              c.xy * (double(c.xy) * c.zz - double(c.yz) * c.xz) +
                              c.xz * (double(c.xy) * c.yz - double(c.yy) * c.xz);
            const int ix = cellIndex(p.point_m.x()), iy = cellIndex(p.point_m.y());
            int16_t n = 0;
            uint8_t status = kAccept;
            if (!(m1 > 0 && m2 > 0 && m3 > 0))
                status = kBadCovariance;
            else if (!w.contains(ix, iy))
                status = kOutsideMap;
            else if (!params.passesEq13(double(c.zz)))
                status = kTooUncertain;
            else if (!binIndexOf(p.point_m.z(), params.binHeight_m, n))
                status = kOutsideBinRange;
            cb.status[i] = status;
            cb.bin[i] = n;
            cb.ix[i] = ix;
            cb.iy[i] = iy;
            cb.slot[i] = status == kAccept ? static_cast<uint32_t>(slot(ix, iy)) : 0;
        }
        // Pass 2, in point order: the bin updates.
        for (size_t i = 0; i < m; i++) {
            if (cb.status[i] != kAccept) {  // rare: counted per reason after the loop
                rejected[cb.status[i]]++;
                continue;
            }
            const double h = pts[i].point_m.z(), var = pts[i].cov_m2.zz;
            const size_t s = cb.slot[i];
            if (perPoint) {
                fuseMeasurement(s, cb.ix[i], cb.iy[i], cb.bin[i], h, var, params, continuityBound_m,
                                stats);
                continue;
            }
            if (run.bin == kNoBin || run.slot != s || run.n != cb.bin[i]) {
                closeRun();
                run.bin = findOrAddBin(s, cb.bin[i]);
                run.slot = s;
                run.n = cb.bin[i];
                run.ix = cb.ix[i];
                run.iy = cb.iy[i];
                run.points = 0;
                run.maxHeight_m = h;
                const Bin& bin = m_pool[run.bin];
                run.frozen = bin.pointCount > 0 && !(bin.variance_m2 > 0);
                if (bin.pointCount == 0 || run.frozen) {
                    run.information = 0;
                    run.weightedHeight = 0;
                } else {
                    run.information = 1.0 / double(bin.variance_m2);
                    run.weightedHeight = double(bin.height_m) * run.information;
                }
            }
            const double wi = 1.0 / var;
            run.information += wi;
            run.weightedHeight += h * wi;
            run.maxHeight_m = std::max(run.maxHeight_m, h);
            run.points++;
            stats.accepted++;
        }
    }
    closeRun();
    stats.notFinite += rejected[kNotFinite];
    stats.badCovariance += rejected[kBadCovariance];
    stats.outsideMap += rejected[kOutsideMap];
    stats.tooUncertain += rejected[kTooUncertain];
    stats.outsideBinRange += rejected[kOutsideBinRange];
    return stats;
}

}  // namespace multibin
