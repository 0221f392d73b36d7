/* Part of the multibin elevation-mapping library. */
#include "multibin/map/BinGrid.h"

#include <algorithm>
#include <array>
#include <stdexcept>

#include "multibin/geometry/PosePropagation.h"
#include "multibin/util/Counters.h"

namespace multibin {

InsertStats& InsertStats::operator+=(const InsertStats& o) {
    return util::addMembers(*this, o, &InsertStats::accepted, &InsertStats::outOfRange,
                            &InsertStats::notFinite, &InsertStats::badCovariance,
                            &InsertStats::outsideMap, &InsertStats::outsideBinRange,
                            &InsertStats::tooUncertain, &InsertStats::continuityRejected);
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
                           continuityBound_m, stats, nullptr);
}

bool BinGrid::fuseMeasurement(size_t s, int ix, int iy, int16_t n, double height_m,
                              double variance_m2, const BinUpdateParams& params,
                              double continuityBound_m, InsertStats& stats,
                              const PointWithCov* point) {
    Bin& bin = BinStore::bin(findOrAddBin(s, n));
    if (!passesEq14(bin, height_m, continuityBound_m)) {
        stats.continuityRejected++;
        return false;
    }
    addMeasurement(bin, height_m, variance_m2, params);
    if (point)  // a height without a place (insertHeight) says nothing of the slope
        addPlanePoint(bin.plane, float(point->point_m.x() - cellCenter_m(ix)),
                      float(point->point_m.y() - cellCenter_m(iy)), float(height_m),
                      float(1.0 / variance_m2));
    stats.accepted++;
    m_index.noteUpdate(s, ix, iy, height_m, 1);
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
    // consecutive points falling into the same bin is fused at once in information form
    // (HeightInformation): the same estimate as the sequential filter up to rounding, without a
    // division chained through every point.
    const bool perPoint = continuityBound_m < std::numeric_limits<double>::infinity();
    const CellWindow w = window();

    // The open run: consecutive accepted points in one bin.
    struct Run {
        BinId bin = kNoBin;
        size_t slot = 0;
        int16_t n = 0;
        int ix = 0, iy = 0;
        uint32_t points = 0;
        HeightInformation sum;
        PlaneMoments* plane = nullptr;    // the bin's: no bin is added while a run is open
        double cellX_m = 0, cellY_m = 0;  // the cell's centre [m]
        double maxHeight_m = 0;
        bool frozen = false;  // the bin has zero variance: its height cannot move
    } run;
    auto closeRun = [&]() {
        if (run.bin == kNoBin) return;
        Bin& bin = BinStore::bin(run.bin);
        if (!run.frozen) {
            bin.height_m = static_cast<float>(run.sum.height_m());
            bin.variance_m2 = static_cast<float>(run.sum.variance_m2());
        }
        for (uint32_t k = 0; k < run.points; k++) bin.certainty += params.certaintyIncrement;
        util::addSaturating(bin.pointCount, run.points);
        m_index.noteUpdate(run.slot, run.ix, run.iy, run.maxHeight_m, run.points);
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
            const int ix = cellIndex(p.point_m.x()), iy = cellIndex(p.point_m.y());
            int16_t n = 0;
            uint8_t status = kAccept;
            if (!isCovariance(c))  // zero or singular: an exact pose, fused as it is
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
            const double h = pts[i].point_m.z();
            const double var = std::max<double>(pts[i].cov_m2.zz, kMinFusedVariance_m2);
            const size_t s = cb.slot[i];
            if (perPoint) {
                fuseMeasurement(s, cb.ix[i], cb.iy[i], cb.bin[i], h, var, params, continuityBound_m,
                                stats, &pts[i]);
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
                Bin& bin = BinStore::bin(run.bin);
                run.plane = &bin.plane;
                run.cellX_m = cellCenter_m(run.ix);
                run.cellY_m = cellCenter_m(run.iy);
                run.frozen = bin.pointCount > 0 && !(bin.variance_m2 > 0);
                run.sum = HeightInformation{};
                if (bin.pointCount > 0 && !run.frozen) run.sum.add(bin.height_m, bin.variance_m2);
            }
            run.sum.add(h, var);
            addPlanePoint(*run.plane, float(pts[i].point_m.x() - run.cellX_m),
                          float(pts[i].point_m.y() - run.cellY_m), float(h), float(1.0 / var));
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
