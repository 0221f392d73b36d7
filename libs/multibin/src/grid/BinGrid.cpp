/* Part of the multibin elevation-mapping library. */
#include "multibin/grid/BinGrid.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "multibin/geometry/PosePropagation.h"
#include "multibin/grid/BinAccumulator.h"
#include "multibin/util/Counters.h"
#include "multibin/util/VectorClones.h"

#include "InsertionPipeline.h"

namespace multibin {

InsertStats& InsertStats::operator+=(const InsertStats& o) {
    return util::addMembers(
        *this, o, &InsertStats::accepted, &InsertStats::outOfRange, &InsertStats::notFinite,
        &InsertStats::badCovariance, &InsertStats::outsideMap, &InsertStats::outsideBinRange,
        &InsertStats::tooUncertain, &InsertStats::continuityRejected, &InsertStats::seenBelow);
}

BinGrid::BinGrid(double cellSize_m) : m_store(cellSize_m) { m_index.reset(); }

void BinGrid::reset(double cellSize_m, const CellWindow& window) {
    m_store.reset(cellSize_m, window);
    m_index.reset();
    forgetLastTile();
}

size_t BinGrid::writableSlotInNewTile(int ix, int iy) {
    bool tileAdded;
    const size_t s = m_store.writableSlot(ix, iy, tileAdded);
    if (tileAdded) {
        const uint32_t t = uint32_t(s / BinStore::kTileSlots);
        m_index.tileAdded(t, m_store.slotCount());
        m_store.reloadTile(t, [this](size_t slot, int x, int y, const Bin& b) {
            m_index.noteHeight(slot, x, y, b.height_m);
        });
    }
    m_lastTileX = BinStore::tileOf(ix);
    m_lastTileY = BinStore::tileOf(iy);
    m_lastTileBase = s - BinStore::slotInTile(ix, iy);
    return s;
}

namespace {
/** Distance from (x_m, y_m) to the square of tile (tx, ty) [m]. */
double distanceToTile_m(double x_m, double y_m, int tx, int ty, double tileSide_m) {
    const double dx = std::max({tx * tileSide_m - x_m, 0.0, x_m - (tx + 1) * tileSide_m});
    const double dy = std::max({ty * tileSide_m - y_m, 0.0, y_m - (ty + 1) * tileSide_m});
    return std::hypot(dx, dy);
}
}  // namespace

size_t BinGrid::spillFarTiles(double x_m, double y_m, double reach_m, size_t targetBytes,
                              const std::shared_ptr<TileStoreFile>& file) {
    if (residentBytes() <= targetBytes) return 0;
    const double side_m = BinStore::kTileCells * cellSize_m();
    std::vector<std::pair<double, uint32_t>> far;  // (distance, tile number)
    m_store.forEachTileNumber([&](uint32_t t, int tx, int ty) {
        const double d_m = distanceToTile_m(x_m, y_m, tx, ty, side_m);
        if (d_m > reach_m) far.emplace_back(d_m, t);
    });
    // Farthest first; ties by tile number, so the order does not depend on the sort.
    std::sort(far.begin(), far.end(), [](const auto& a, const auto& b) {
        return a.first != b.first ? a.first > b.first : a.second < b.second;
    });
    size_t spilled = 0;
    for (const auto& [d_m, t] : far) {
        if (residentBytes() <= targetBytes) break;
        for (size_t s = BinStore::tileBase(t); s < BinStore::tileBase(t + 1); s++)
            m_index.forgetSlot(s);
        m_store.spillTile(t, file);
        spilled++;
    }
    forgetLastTile();
    return spilled;
}

size_t BinGrid::reloadTilesNear(double x_m, double y_m, double reach_m) {
    if (!m_store.hasSpilledTiles()) return 0;
    const double side_m = BinStore::kTileCells * cellSize_m();
    std::vector<std::pair<int, int>> near;
    m_store.forEachSpilledTile([&](int tx, int ty) {
        if (distanceToTile_m(x_m, y_m, tx, ty, side_m) <= reach_m) near.emplace_back(tx, ty);
    });
    // A write into the tile brings it back (writableSlotInNewTile).
    for (const auto& [tx, ty] : near)
        writableSlot(tx * BinStore::kTileCells, ty * BinStore::kTileCells);
    return near.size();
}

void BinGrid::appendBin(int ix, int iy, const BinEstimate& bin) {
    if (!window().contains(ix, iy))
        throw std::out_of_range("BinGrid::appendBin: cell outside the window");
    const size_t s = writableSlot(ix, iy);
    m_store.appendBin(s, bin);
    m_index.noteHeight(s, ix, iy, bin.height_m);
}

void BinGrid::fuseBin(int ix, int iy, const BinEstimate& other, const BinUpdateParams& params) {
    if (!window().contains(ix, iy))
        throw std::out_of_range("BinGrid::fuseBin: cell outside the window");
    int16_t n;
    if (!binIndexOf(other.height_m, params.binHeight_m, n)) return;
    bool added;
    const size_t s = writableSlot(ix, iy);
    Bin& bin = m_store.bin(m_store.findOrAddBin(s, n, added));
    if (added) {
        static_cast<BinEstimate&>(bin) = other;
        bin.index = n;
    } else {
        BinAccumulator<HeightFusion::kSequential> update;
        update.open(bin, cellCenter_m(ix), cellCenter_m(iy));
        update.merge(other);
        update.close(bin, params, false);
    }
    m_index.noteHeight(s, ix, iy, bin.height_m);
}

const Bin* BinGrid::winningBin(int ix, int iy) const {
    const Bin* best = nullptr;
    forEachBin(ix, iy, [&](const Bin& bin) {
        if (winsOver(bin, best)) best = &bin;
    });
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
    return fuseMeasurement(writableSlot(ix, iy), ix, iy, n, height_m, variance_m2,
                           1.0 / variance_m2, params, continuityBound_m, stats, std::nanf(""),
                           std::nanf(""), 0, 0);
}

bool BinGrid::fuseMeasurement(size_t s, int ix, int iy, int16_t n, double height_m,
                              double variance_m2, double weight, const BinUpdateParams& params,
                              double continuityBound_m, InsertStats& stats, float x_m, float y_m,
                              uint8_t poseHeightCode, uint8_t poseHorizontalCode) {
    Bin& bin = m_store.bin(m_store.findOrAddBin(s, n));
    BinAccumulator<HeightFusion::kSequential> update;
    update.open(bin, cellCenter_m(ix), cellCenter_m(iy));
    if (!update.passesEq14(height_m, continuityBound_m)) {
        stats.continuityRejected++;
        return false;
    }
    if (std::isnan(x_m))  // a height without a place (insertHeight) says nothing of the slope
        update.addHeight(height_m, variance_m2, weight, params);
    else
        update.addPoint(x_m, y_m, height_m, variance_m2, weight, params);
    update.lowerPoseCodes(poseHeightCode, poseHorizontalCode);
    update.close(bin, params, false);
    stats.accepted++;
    m_index.noteUpdate(s, ix, iy, height_m, 1);
    return true;
}

namespace {

constexpr size_t kPointBlock = PointBlock::kCapacity;

enum PointStatus : uint8_t {
    kAccept,
    kNotFinite,
    kBadCovariance,
    kOutsideMap,
    kTooUncertain,
    kOutsideBinRange,
    kStatusCount,
    kCheckSingular = kStatusCount  //!< not positive definite: isSingularCovariance decides
};

/** Per-point results of the classification pass over one block. */
struct ClassifiedBlock {
    alignas(64) double weight[kPointBlock];  //!< 1 / fused variance [1/m^2]
    alignas(64) int32_t ix[kPointBlock], iy[kPointBlock];
    alignas(64) int32_t bin[kPointBlock];
    alignas(64) uint8_t status[kPointBlock];
    /** The status the gates after the covariance's give (window, eq 13, bin range): the
     * status of a kCheckSingular point whose covariance isSingularCovariance accepts. */
    alignas(64) uint8_t statusAfterCovariance[kPointBlock];
    /** poseSigmaCode of the point's pose parts of its height and horizontal variance. */
    alignas(64) uint8_t poseCode[2][kPointBlock];
};

/** What the classification needs of the grid, by value (no aliasing with the block). */
struct ClassifyGeometry {
    double invCellSize;  //!< [1/m]
    CellWindow window;
    BinUpdateParams params;
    /** kMinFusedVariance_m2, passed at run time: with the constant, GCC folds 1 / constant into
     * one arm of the select and the loop no longer vectorises. */
    double minFusedVariance_m2;
};

/** Pass 1 over a block, no bin access: validity, the gates that need only the point, cell, slot
 * and bin index, and the point's weight, with the scalar path's own functions (cellIndex's
 * clamp and floor, binIndexFits, isPositiveDefinite, passesEq13), so every decision and weight is
 * theirs bit for bit. Branch-free so the compiler vectorises it. A point whose covariance is not
 * positive definite gets kCheckSingular (the caller asks isSingularCovariance, rare). */
MULTIBIN_VECTOR_CLONES
void classifyBlock(const ClassifyGeometry& g, const PointBlock& pts, size_t m,
                   ClassifiedBlock& cb) {
    const float* __restrict px = pts.v[0];
    const float* __restrict py = pts.v[1];
    const float* __restrict pz = pts.v[2];
    const float* __restrict cxx = pts.v[3];
    const float* __restrict cxy = pts.v[4];
    const float* __restrict cxz = pts.v[5];
    const float* __restrict cyy = pts.v[6];
    const float* __restrict cyz = pts.v[7];
    const float* __restrict czz = pts.v[8];
    // Comparisons become 0/1 ints combined with & and arithmetic, and every choice a select, so
    // the loops have no control flow and vectorise. Two loops: GCC 12 does not vectorise a
    // clamped double's conversion to int in the same loop as the clamp.
    alignas(64) double cellX[kPointBlock], cellY[kPointBlock], binQ[kPointBlock];
    alignas(64) int32_t flags[kPointBlock];  // gates passed: 1 finite, 2 positive definite,
                                             // 4 eq 13, 8 the bin index fits
    for (size_t i = 0; i < m; i++) {
        const double x = px[i], y = py[i], z = pz[i];
        const double xx = cxx[i], xy = cxy[i], xz = cxz[i], yy = cyy[i], yz = cyz[i], zz = czz[i];
        // All nine values finite iff their sum in double is (nine floats cannot overflow a
        // double; a NaN or infinity makes the sum NaN or infinite).
        const double sum = x + y + z + xx + xy + xz + yy + yz + zz;
        const int finite = int(sum - sum == 0.0);
        const int positiveDefinite = int(isPositiveDefinite(xx, xy, xz, yy, yz, zz));
        const int eq13 = int(g.params.passesEq13(zz));
        const double q = z / g.params.binHeight_m;
        const int binFits = int(BinStore::binIndexFits(q));
        cellX[i] = BinStore::clampedCellCoordinate(x * g.invCellSize);
        cellY[i] = BinStore::clampedCellCoordinate(y * g.invCellSize);
        binQ[i] = binFits ? q : 0.0;
        flags[i] = finite | positiveDefinite << 1 | eq13 << 2 | binFits << 3;
        cb.weight[i] = 1.0 / (zz < g.minFusedVariance_m2 ? g.minFusedVariance_m2 : zz);
    }
    const int nx = g.window.nx, ny = g.window.ny;
    for (size_t i = 0; i < m; i++) {
        const int ix = BinStore::floorToInt(cellX[i]), iy = BinStore::floorToInt(cellY[i]);
        const int dx = ix - g.window.ix0, dy = iy - g.window.iy0;
        const int inWindow = int(dx >= 0) & int(dx < nx) & int(dy >= 0) & int(dy < ny);
        const int f = flags[i];
        const int finite = f & 1, positiveDefinite = f >> 1 & 1, eq13 = f >> 2 & 1,
                  binFits = f >> 3 & 1;
        // The first gate failed decides, in the order of the scalar checks; eq 13 before the
        // window: a point too uncertain to grow the map is too uncertain, wherever it lies.
        const int rest =
            (1 - eq13) * kTooUncertain +
            eq13 * ((1 - inWindow) * kOutsideMap + inWindow * (1 - binFits) * kOutsideBinRange);
        const int status =
            (1 - finite) * kNotFinite +
            finite * ((1 - positiveDefinite) * kCheckSingular + positiveDefinite * rest);
        cb.status[i] = static_cast<uint8_t>(status);
        cb.statusAfterCovariance[i] = static_cast<uint8_t>(rest);
        cb.ix[i] = ix;
        cb.iy[i] = iy;
        cb.bin[i] = BinStore::floorToInt(binQ[i]);
    }
    for (int part = 0; part < 2; part++) {
        const float* __restrict variance = pts.poseVariance_m2[part];
        uint8_t* __restrict code = cb.poseCode[part];
        for (size_t i = 0; i < m; i++) code[i] = poseSigmaCode(variance[i]);
    }
}

/** A block as the first stage leaves it for the bin updates: its points and their classes. */
struct ClassifiedStage {
    PointBlock points;
    ClassifiedBlock classes;
    size_t count = 0;
};

/** Calls fuse(i) for each accepted point i of a classified block, in order, and counts the others
 * in `rejected` by reason; returns the accepted count. */
template <class Fuse>
__attribute__((always_inline)) inline size_t forAccepted(const ClassifiedStage& stage,
                                                         size_t (&rejected)[kStatusCount],
                                                         Fuse&& fuse) {
    const PointBlock& pts = stage.points;
    const ClassifiedBlock& cb = stage.classes;
    size_t accepted = stage.count;
    for (size_t i = 0; i < stage.count; i++) {
        if (cb.status[i] != kAccept) {  // rare: counted per reason after the loop
            uint8_t status = cb.status[i];
            if (status == kCheckSingular) {  // zero or singular: an exact pose, fused as it is
                const SymmetricCov3 c{pts.v[3][i], pts.v[4][i], pts.v[5][i],
                                      pts.v[6][i], pts.v[7][i], pts.v[8][i]};
                status =
                    isSingularCovariance(c) ? cb.statusAfterCovariance[i] : uint8_t(kBadCovariance);
            }
            if (status != kAccept) {
                rejected[status]++;
                accepted--;
                continue;
            }
        }
        fuse(i);
    }
    return accepted;
}

/** Adds the rejections forAccepted counted to `stats`. */
void addRejections(InsertStats& stats, const size_t (&rejected)[kStatusCount]) {
    stats.notFinite += rejected[kNotFinite];
    stats.badCovariance += rejected[kBadCovariance];
    stats.outsideMap += rejected[kOutsideMap];
    stats.tooUncertain += rejected[kTooUncertain];
    stats.outsideBinRange += rejected[kOutsideBinRange];
}

}  // namespace

InsertStats BinGrid::insertPoints(const PointsWithCov& mapPoints, const BinUpdateParams& params,
                                  double continuityBound_m, const PoseVariances* pose) {
    return insertPoints(mapPoints.data(), mapPoints.size(), params, continuityBound_m, pose);
}

InsertStats BinGrid::insertPoints(const PointWithCov* mapPoints, size_t count,
                                  const BinUpdateParams& params, double continuityBound_m,
                                  const PoseVariances* pose) {
    if (pose && (pose->height_m2.size() < count || pose->horizontal_m2.size() < count))
        throw std::invalid_argument("BinGrid::insertPoints: fewer pose variances than points");
    return insertBlocks(
        count,
        [mapPoints, pose](size_t begin, size_t m, PointBlock& block) {
            block.gather(mapPoints + begin, m);
            if (pose) {
                std::copy_n(pose->height_m2.data() + begin, m, block.poseVariance_m2[0]);
                std::copy_n(pose->horizontal_m2.data() + begin, m, block.poseVariance_m2[1]);
            } else {
                for (float* v : block.poseVariance_m2) std::fill_n(v, m, std::nanf(""));
            }
        },
        params, continuityBound_m);
}

InsertStats BinGrid::insertSensorPoints(const PosePropagator& propagator,
                                        const PointsWithCov& sensorPoints,
                                        const BinUpdateParams& params, double continuityBound_m) {
    // One block of map-frame points at a time (9 kB, stays in the L1 cache).
    return insertBlocks(
        sensorPoints.size(),
        [&](size_t begin, size_t m, PointBlock& block) {
            propagator.applyBlock(sensorPoints.data() + begin, m, block);
        },
        params, continuityBound_m);
}

template <typename BlockSource>
InsertStats BinGrid::insertBlocks(size_t count, BlockSource&& fillBlock,
                                  const BinUpdateParams& params, double continuityBound_m) {
    InsertStats stats;
    // Eq 14 compares each laser point with the bin height left by the previous point, so with a
    // finite bound points are fused one by one. Without it (stereo, depth: eq 13 only) a run of
    // consecutive points falling into the same bin is fused at once in information form
    // (HeightInformation): the same estimate as the sequential filter up to rounding, without a
    // division chained through every point.
    const bool perPoint = continuityBound_m < std::numeric_limits<double>::infinity();
    const ClassifyGeometry geometry{m_store.inverseCellSize(), window(), params,
                                    kMinFusedVariance_m2};

    // The open run: consecutive accepted points in one bin. Its update (BinAccumulator) stays in
    // registers and is written back when the run closes.
    struct Run {
        BinId bin = kNoBin;
        size_t slot = 0;
        int16_t n = 0;
        int ix = 0, iy = 0;
        BinAccumulator<HeightFusion::kInformation> update;
    } run;
    const bool wholeIncrement = isExactWholeFloat(params.certaintyIncrement);
    auto closeRun = [&]() {
        if (run.bin == kNoBin) return;
        run.update.close(m_store.bin(run.bin), params, wholeIncrement);
        m_index.noteUpdate(run.slot, run.ix, run.iy, run.update.maxHeight_m(), run.update.points());
        run.bin = kNoBin;
    };

    size_t rejected[kStatusCount] = {};
    // Pass 2, in point order: the bin updates of one classified block, point by point for a
    // laser (eq 14) and by runs otherwise, each its own loop.
    // Inlined into both loops below: called through a function, the run and the counters live
    // in memory and the bin update is 6 % slower.
    auto updateBins = [&](const ClassifiedStage& stage) __attribute__((always_inline)) {
        const PointBlock& pts = stage.points;
        const ClassifiedBlock& cb = stage.classes;
        if (perPoint) {  // fuseMeasurement counts what it accepts or refuses (eq 14)
            forAccepted(
                stage, rejected, [&](size_t i) __attribute__((always_inline)) {
                    fuseMeasurement(writableSlot(cb.ix[i], cb.iy[i]), cb.ix[i], cb.iy[i],
                                    static_cast<int16_t>(cb.bin[i]), pts.v[2][i],
                                    std::max<double>(pts.v[8][i], kMinFusedVariance_m2),
                                    cb.weight[i], params, continuityBound_m, stats, pts.v[0][i],
                                    pts.v[1][i], cb.poseCode[0][i], cb.poseCode[1][i]);
                });
            return;
        }
        stats.accepted += forAccepted(
            stage, rejected, [&](size_t i) __attribute__((always_inline)) {
                const int ix = cb.ix[i], iy = cb.iy[i];
                const int16_t n = static_cast<int16_t>(cb.bin[i]);
                if (run.bin == kNoBin || run.ix != ix || run.iy != iy || run.n != n) {
                    closeRun();
                    run.slot = writableSlot(ix, iy);
                    run.bin = m_store.findOrAddBin(run.slot, n);
                    run.n = n;
                    run.ix = ix;
                    run.iy = iy;
                    run.update.open(m_store.bin(run.bin), cellCenter_m(run.ix),
                                    cellCenter_m(run.iy));
                    // The first point's pose codes: the run's points are neighbours of one frame,
                    // whose pose parts differ by far less than the codes' steps (BinUpdate.h).
                    run.update.lowerPoseCodes(cb.poseCode[0][i], cb.poseCode[1][i]);
                }
                run.update.addPoint(pts.v[0][i], pts.v[1][i], pts.v[2][i],
                                    std::max<double>(pts.v[8][i], kMinFusedVariance_m2),
                                    cb.weight[i], params);
            });
    };
    // Pass 1 of block j: the points (propagated, for sensor points) and their classes.
    const size_t blocks = (count + kPointBlock - 1) / kPointBlock;
    auto classify = [&](size_t j, ClassifiedStage& stage) {
        const size_t begin = j * kPointBlock;
        stage.count = std::min(kPointBlock, count - begin);
        fillBlock(begin, stage.count, stage.points);
        classifyBlock(geometry, stage.points, stage.count, stage.classes);
    };
    if (!(m_insertionThreads >= 2 && blocks >= pipeline::kMinBlocks &&
          pipeline::run<ClassifiedStage>(blocks, classify, updateBins))) {
        ClassifiedStage stage;
        for (size_t j = 0; j < blocks; j++) {
            classify(j, stage);
            updateBins(stage);
        }
    }
    closeRun();
    addRejections(stats, rejected);
    return stats;
}

}  // namespace multibin
