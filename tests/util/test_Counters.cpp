/* Counters saturate instead of wrapping (issue 16.7): a bin's point count (uint32_t) through
 * every path that adds to it, and the statistics structs summed with util::addMembers. */
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>

#include "multibin/grid/BinGrid.h"
#include "multibin/grid/BinUpdate.h"
#include "multibin/sensors/SensorStats.h"
#include "multibin/util/Counters.h"

namespace {
constexpr uint32_t kMax = std::numeric_limits<uint32_t>::max();

multibin::BinEstimate binWithPoints(uint32_t points) {
    multibin::BinEstimate b;
    b.height_m = 0.01f;
    b.variance_m2 = 1e-4f;
    b.certainty = 1;
    b.pointCount = points;
    return b;
}

uint32_t pointsOfTheBinAt(const multibin::BinGrid& g, int ix, int iy) {
    uint32_t n = 0;
    g.forEachBin(ix, iy, [&](const multibin::Bin& b) { n = b.pointCount; });
    return n;
}
}  // namespace

TEST(Counters, AddSaturatingStopsAtTheMaximum) {
    uint32_t c = kMax - 2;
    multibin::util::addSaturating(c, 1u);
    EXPECT_EQ(c, kMax - 1);
    multibin::util::addSaturating(c, uint64_t(1) << 40);
    EXPECT_EQ(c, kMax);
    multibin::util::addSaturating(c, 1u);
    EXPECT_EQ(c, kMax);
    size_t s = std::numeric_limits<size_t>::max() - 1;
    multibin::util::addSaturating(s, size_t(5));
    EXPECT_EQ(s, std::numeric_limits<size_t>::max());
}

// A bin 3 points short of 2^32: 10 more points (batch insertion, one at a time, a bin fused from
// the other grid) leave it at the maximum; it wrapped to a handful before.
TEST(Counters, ABinsPointCountSaturates) {
    const multibin::BinUpdateParams params;
    multibin::BinGrid g(0.1);
    g.reset(0.1, multibin::CellWindow{0, 0, 4, 4});
    g.appendBin(1, 1, binWithPoints(kMax - 3));
    multibin::PointsWithCov pts(10);
    for (auto& p : pts) {
        p.point_m = Eigen::Vector3f(0.15f, 0.15f, 0.01f);
        p.cov_m2.xx = p.cov_m2.yy = p.cov_m2.zz = 1e-4f;
    }
    const multibin::InsertStats st = g.insertPoints(pts, params);
    EXPECT_EQ(st.accepted, 10u);
    EXPECT_EQ(pointsOfTheBinAt(g, 1, 1), kMax);

    g.appendBin(2, 2, binWithPoints(kMax - 3));
    multibin::InsertStats st2;
    for (int i = 0; i < 10; i++) g.insertHeight(2, 2, 0.01, 1e-4, params, 1.0, st2);
    EXPECT_EQ(pointsOfTheBinAt(g, 2, 2), kMax);

    g.appendBin(3, 3, binWithPoints(kMax - 3));
    g.fuseBin(3, 3, binWithPoints(10), params);
    EXPECT_EQ(pointsOfTheBinAt(g, 3, 3), kMax);

    multibin::BinEstimate b = binWithPoints(kMax);
    multibin::addMeasurement(b, 0.01, 1e-4, params);
    EXPECT_EQ(b.pointCount, kMax);
}

TEST(Counters, StatisticsSumsSaturate) {
    multibin::InsertStats a, b;
    a.accepted = std::numeric_limits<size_t>::max() - 1;
    b.accepted = 7;
    b.outsideMap = 3;
    a += b;
    EXPECT_EQ(a.accepted, std::numeric_limits<size_t>::max());
    EXPECT_EQ(a.outsideMap, 3u);
    multibin::sensors::LaserStats l, m;
    l.beams = std::numeric_limits<size_t>::max();
    m.beams = 1;
    m.kept = 2;
    l += m;
    EXPECT_EQ(l.beams, std::numeric_limits<size_t>::max());
    EXPECT_EQ(l.kept, 2u);
}
