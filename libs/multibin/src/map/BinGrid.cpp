/* Part of the multibin elevation-mapping library. */
#include "multibin/map/BinGrid.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <exception>
#include <memory>
#include <stdexcept>
#include <thread>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

#include "multibin/geometry/PosePropagation.h"
#include "multibin/util/Counters.h"
#include "multibin/util/VectorClones.h"

#include "../util/HelperThread.h"

namespace multibin {

InsertStats& InsertStats::operator+=(const InsertStats& o) {
    return util::addMembers(
        *this, o, &InsertStats::accepted, &InsertStats::outOfRange, &InsertStats::notFinite,
        &InsertStats::badCovariance, &InsertStats::outsideMap, &InsertStats::outsideBinRange,
        &InsertStats::tooUncertain, &InsertStats::continuityRejected, &InsertStats::seenBelow);
}

BinGrid::BinGrid(double cellSize_m) : BinStore(cellSize_m) { m_index.reset(window()); }

void BinGrid::reset(double cellSize_m, const CellWindow& window) {
    BinStore::reset(cellSize_m, window);
    m_index.reset(window);
}

void BinGrid::growToInclude(const CellWindow& w) {
    if (BinStore::growToInclude(w)) m_index.regrow(store());
}

void BinGrid::appendBin(int ix, int iy, const BinEstimate& bin) {
    BinStore::appendBin(ix, iy, bin);
    m_index.noteHeight(slot(ix, iy), ix, iy, bin.height_m);
}

void BinGrid::fuseBin(int ix, int iy, const BinEstimate& other, const BinUpdateParams& params) {
    if (!window().contains(ix, iy))
        throw std::out_of_range("BinGrid::fuseBin: cell outside the window");
    int16_t n;
    if (!binIndexOf(other.height_m, params.binHeight_m, n)) return;
    bool added;
    const size_t s = slot(ix, iy);
    Bin& bin = BinStore::bin(findOrAddBin(s, n, added));
    if (added) {
        static_cast<BinEstimate&>(bin) = other;
        bin.index = n;
    } else {
        fuse(bin.height_m, bin.variance_m2, other.height_m, other.variance_m2);
        mergePlaneMoments(bin.plane, other.plane);
        lowerPoseSigmaCodes(bin, other.poseHeightSigmaCode, other.poseHorizontalSigmaCode);
        bin.certainty += other.certainty;
        util::addSaturating(bin.pointCount, other.pointCount);
    }
    m_index.noteHeight(s, ix, iy, bin.height_m);
}

const Bin* BinGrid::winningBin(int ix, int iy) const {
    const Bin* best = nullptr;
    forEachBin(ix, iy, [&](const Bin& bin) {
        if (!(bin.certainty > 0)) return;
        if (!best || bin.certainty > best->certainty ||
            (bin.certainty == best->certainty && bin.variance_m2 < best->variance_m2))
            best = &bin;
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
    return fuseMeasurement(slot(ix, iy), ix, iy, n, height_m, variance_m2, params,
                           continuityBound_m, stats, std::nanf(""), std::nanf(""), 0, 0);
}

bool BinGrid::fuseMeasurement(size_t s, int ix, int iy, int16_t n, double height_m,
                              double variance_m2, const BinUpdateParams& params,
                              double continuityBound_m, InsertStats& stats, float x_m, float y_m,
                              uint8_t poseHeightCode, uint8_t poseHorizontalCode) {
    Bin& bin = BinStore::bin(findOrAddBin(s, n));
    if (!passesEq14(bin, height_m, continuityBound_m)) {
        stats.continuityRejected++;
        return false;
    }
    addMeasurement(bin, height_m, variance_m2, params);
    if (!std::isnan(x_m))  // a height without a place (insertHeight) says nothing of the slope
        addPlanePoint(bin.plane, float(x_m - cellCenter_m(ix)), float(y_m - cellCenter_m(iy)),
                      float(height_m), float(1.0 / variance_m2));
    lowerPoseSigmaCodes(bin, poseHeightCode, poseHorizontalCode);
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
    alignas(64) uint32_t slot[kPointBlock];  // as BinStore::slot, below 2^32 cells
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
    int originSlotX, originSlotY;
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
        int sx = dx + g.originSlotX, sy = dy + g.originSlotY;
        sx -= nx * int(sx >= nx);
        sy -= ny * int(sy >= ny);
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
        cb.slot[i] = (uint32_t(sx) + uint32_t(sy) * uint32_t(nx)) * uint32_t(inWindow);
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

/** Blocks in flight between the two stages of the pipeline: 8 x 14 kB, inside the L2 cache. */
constexpr size_t kPipelineRing = 8;
/** The pipeline pays from about this many blocks on (handing a task to the helper thread costs
 * about as much as a few blocks' work): a 30 000-return lidar revolution, a stereo or depth frame,
 * not a 683-beam laser scan. */
constexpr size_t kPipelineMinBlocks = 16;

inline void pauseCore() {
#if defined(__x86_64__) || defined(__i386__)
    _mm_pause();  // a spin-wait hint: frees the core's resources for its other hyperthread
#endif
}

/** Waits for `ready()` (the helper thread, for a free slot of the ring): spins briefly (the other
 * stage is usually a block away), then yields the core. */
template <class Ready>
void waitUntil(Ready&& ready) {
    for (int spins = 0; !ready(); spins++) {
        if (spins < 1024)
            pauseCore();
        else
            std::this_thread::yield();
    }
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

template <typename Classify, typename Update>
bool BinGrid::insertPipelined(size_t blocks, Classify& classify, Update& updateBins) {
    // Two stages on two cores: the helper thread propagates and classifies blocks ahead while
    // this thread updates the bins in point order, so the bins are those of one thread, bit for
    // bit; only this thread touches the grid. This thread does not wait for the helper: a block
    // the helper has not delivered when its turn comes (the helper not awake yet, or its core
    // taken by another process) is classified here, and the helper moves past it.
    std::unique_ptr<ClassifiedStage[]> ring(new ClassifiedStage[kPipelineRing]);
    std::atomic<size_t> slotHolds[kPipelineRing];  // 1 + the block a slot holds; 0: none yet
    for (std::atomic<size_t>& h : slotHolds) h.store(0, std::memory_order_relaxed);
    std::atomic<size_t> nextForHelper{0}, consumed{0};
    std::atomic<bool> done{false};
    auto produce = [&]() {
        try {
            for (;;) {
                const size_t j = nextForHelper.fetch_add(1, std::memory_order_relaxed);
                if (j >= blocks) return;
                // Slot j % ring is free once block j - ring has been consumed.
                waitUntil([&] {
                    return j < consumed.load(std::memory_order_acquire) + kPipelineRing ||
                           done.load(std::memory_order_relaxed);
                });
                if (done.load(std::memory_order_relaxed)) return;
                if (j < consumed.load(std::memory_order_acquire)) continue;  // done here
                classify(j, ring[j % kPipelineRing]);
                slotHolds[j % kPipelineRing].store(j + 1, std::memory_order_release);
            }
        } catch (...) {
            // Nothing is lost: this thread classifies every block the helper does not deliver.
        }
    };
    HelperThread& helper = HelperThread::shared();
    if (!helper.tryStart(produce)) return false;  // busy with another map: one core
    auto stopHelper = [&] {
        done.store(true, std::memory_order_relaxed);
        helper.wait();  // at most the block it is classifying
    };
    ClassifiedStage own;  // a block classified on this thread
    try {
        for (size_t j = 0; j < blocks; j++) {
            const std::atomic<size_t>& holds = slotHolds[j % kPipelineRing];
            bool ready = holds.load(std::memory_order_acquire) == j + 1;
            // Wait briefly for a block the helper has claimed (about one block's work).
            for (int spin = 0;
                 !ready && spin < 64 && nextForHelper.load(std::memory_order_relaxed) > j; spin++) {
                pauseCore();
                ready = holds.load(std::memory_order_acquire) == j + 1;
            }
            if (ready) {
                updateBins(ring[j % kPipelineRing]);
            } else {
                // Keep the helper off block j if it has not claimed it yet.
                size_t next = nextForHelper.load(std::memory_order_relaxed);
                while (next <= j && !nextForHelper.compare_exchange_weak(
                                        next, j + 1, std::memory_order_relaxed)) {
                }
                classify(j, own);
                updateBins(own);
            }
            consumed.store(j + 1, std::memory_order_release);
        }
    } catch (...) {
        stopHelper();
        throw;
    }
    stopHelper();
    return true;
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
    const CellWindow w = window();
    const ClassifyGeometry geometry{inverseCellSize(), w,      originSlotX(),
                                    originSlotY(),     params, kMinFusedVariance_m2};

    // The open run: consecutive accepted points in one bin. Its plane moments are a copy, written
    // back when the run closes, so the per-point update stays in registers.
    struct Run {
        BinId bin = kNoBin;
        size_t slot = 0;
        int16_t n = 0;
        int ix = 0, iy = 0;
        uint32_t points = 0;
        HeightInformation sum;
        PlaneMoments plane;
        double cellX_m = 0, cellY_m = 0;  // the cell's centre [m]
        double maxHeight_m = 0;
        // Its first point's pose parts' codes: the run's points are neighbours of one frame,
        // whose pose parts differ by far less than the codes' steps (BinUpdate.h).
        uint8_t poseHeightCode = 0, poseHorizontalCode = 0;
        bool frozen = false;  // the bin has zero variance: its height cannot move
    } run;
    const bool wholeIncrement = isExactWholeFloat(params.certaintyIncrement);
    auto closeRun = [&]() {
        if (run.bin == kNoBin) return;
        Bin& bin = BinStore::bin(run.bin);
        if (!run.frozen) {
            bin.height_m = static_cast<float>(run.sum.height_m());
            bin.variance_m2 = static_cast<float>(run.sum.variance_m2());
        }
        bin.plane = run.plane;
        addCertainty(bin.certainty, params.certaintyIncrement, run.points, wholeIncrement);
        lowerPoseSigmaCodes(bin, run.poseHeightCode, run.poseHorizontalCode);
        util::addSaturating(bin.pointCount, run.points);
        m_index.noteUpdate(run.slot, run.ix, run.iy, run.maxHeight_m, run.points);
        run.bin = kNoBin;
    };

    size_t rejected[kStatusCount] = {};
    // Calls fuse(i) for each accepted point i of a block, in order, and counts the others by
    // reason; returns the accepted count.
    auto forAccepted = [&](const ClassifiedStage& stage, auto&& fuse)
        __attribute__((always_inline)) {
        const PointBlock& pts = stage.points;
        const ClassifiedBlock& cb = stage.classes;
        size_t accepted = stage.count;
        for (size_t i = 0; i < stage.count; i++) {
            if (cb.status[i] != kAccept) {  // rare: counted per reason after the loop
                uint8_t status = cb.status[i];
                if (status == kCheckSingular) {  // zero or singular: an exact pose, fused as it is
                    const SymmetricCov3 c{pts.v[3][i], pts.v[4][i], pts.v[5][i],
                                          pts.v[6][i], pts.v[7][i], pts.v[8][i]};
                    status = isSingularCovariance(c) ? cb.statusAfterCovariance[i]
                                                     : uint8_t(kBadCovariance);
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
    };
    // Pass 2, in point order: the bin updates of one classified block, point by point for a
    // laser (eq 14) and by runs otherwise, each its own loop.
    // Inlined into both loops below: called through a function, the run and the counters live
    // in memory and the bin update is 6 % slower.
    auto updateBins = [&](const ClassifiedStage& stage) __attribute__((always_inline)) {
        const PointBlock& pts = stage.points;
        const ClassifiedBlock& cb = stage.classes;
        if (perPoint) {  // fuseMeasurement counts what it accepts or refuses (eq 14)
            forAccepted(
                stage, [&](size_t i) __attribute__((always_inline)) {
                    fuseMeasurement(cb.slot[i], cb.ix[i], cb.iy[i], static_cast<int16_t>(cb.bin[i]),
                                    pts.v[2][i],
                                    std::max<double>(pts.v[8][i], kMinFusedVariance_m2), params,
                                    continuityBound_m, stats, pts.v[0][i], pts.v[1][i],
                                    cb.poseCode[0][i], cb.poseCode[1][i]);
                });
            return;
        }
        stats.accepted += forAccepted(
            stage, [&](size_t i) __attribute__((always_inline)) {
                const float x = pts.v[0][i], y = pts.v[1][i];
                const double h = pts.v[2][i];
                const double weight = cb.weight[i];
                const size_t s = size_t(cb.slot[i]);
                const int16_t n = static_cast<int16_t>(cb.bin[i]);
                if (run.bin == kNoBin || run.slot != s || run.n != n) {
                    closeRun();
                    run.bin = findOrAddBin(s, n);
                    run.slot = s;
                    run.n = n;
                    run.ix = cb.ix[i];
                    run.iy = cb.iy[i];
                    run.points = 0;
                    run.maxHeight_m = h;
                    run.poseHeightCode = cb.poseCode[0][i];
                    run.poseHorizontalCode = cb.poseCode[1][i];
                    const Bin& bin = BinStore::bin(run.bin);
                    run.plane = bin.plane;
                    run.cellX_m = cellCenter_m(run.ix);
                    run.cellY_m = cellCenter_m(run.iy);
                    run.frozen = bin.pointCount > 0 && !(bin.variance_m2 > 0);
                    run.sum = HeightInformation{};
                    if (bin.pointCount > 0 && !run.frozen)
                        run.sum.add(bin.height_m, bin.variance_m2);
                }
                run.sum.addWeighted(h, weight);
                addPlanePoint(run.plane, float(x - run.cellX_m), float(y - run.cellY_m), float(h),
                              float(weight));
                run.maxHeight_m = std::max(run.maxHeight_m, h);
                run.points++;
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
    if (!(m_insertionThreads >= 2 && blocks >= kPipelineMinBlocks &&
          insertPipelined(blocks, classify, updateBins))) {
        ClassifiedStage stage;
        for (size_t j = 0; j < blocks; j++) {
            classify(j, stage);
            updateBins(stage);
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
