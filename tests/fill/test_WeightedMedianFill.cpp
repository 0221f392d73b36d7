/* The weighted median fill (WeightedMedianFill.h). */
#include <gtest/gtest.h>

#include <cmath>

#include "fill_test_util.h"
#include "multibin/fill/GapFilling.h"
#include "multibin/fill/WeightedMedianFill.h"

using multibin::HeightSource;
using namespace multibin::fill;
using namespace fill_test;

TEST(WeightedMedian, OuterCellsOutweighInnerOnes) {
    // Centre unknown; the 8 inner cells at 0.10 m (weights 1 and sqrt 2, total 9.66); six outer
    // cells at 0.20 m: four corners (2 sqrt 2) and two edge centres (2), total 15.3. The plain
    // median (8 against 6) would say 0.10; the skeleton says 0.20.
    HeightRaster r(5, 5, 0.015);
    for (int iy = 1; iy <= 3; iy++)
        for (int ix = 1; ix <= 3; ix++)
            if (ix != 2 || iy != 2) r.setMeasured(ix, iy, 0.10f, 0.002f);
    for (auto [x, y] : {std::pair{0, 0}, {4, 0}, {0, 4}, {4, 4}, {2, 0}, {0, 2}})
        r.setMeasured(x, y, 0.20f, 0.004f);
    FillOptions o;
    o.sigmaModel = FillSigmaModel::Paper;
    const auto f = weightedMedianFill(r, o);
    const size_t c = f.index(2, 2);
    EXPECT_EQ(f.source[c], HeightSource::FilledMedian);
    EXPECT_FLOAT_EQ(f.height_m[c], 0.20f);
    // Paper sigma: the same weights over the neighbours' sigma.
    const double wIn = 4 + 4 * std::sqrt(2.0), wOut = 4 * 2 * std::sqrt(2.0) + 2 * 2;
    EXPECT_NEAR(f.sigma_m[c], (0.002 * wIn + 0.004 * wOut) / (wIn + wOut), 1e-7);
    EXPECT_DOUBLE_EQ(medianSkeletonWeight(2, 1), std::sqrt(5.0));

    // Calibrated sigma: neighbour noise plus gain * weighted spread about the median.
    o.sigmaModel = FillSigmaModel::Calibrated;
    const auto g = weightedMedianFill(r, o);
    const double var = (4e-6 * wIn + 16e-6 * wOut) / (wIn + wOut);
    const double spread = 0.01 * wIn / (wIn + wOut);
    EXPECT_NEAR(g.sigma_m[c], std::sqrt(var + std::pow(o.medianSigmaGain, 2) * spread), 1e-6);
}

TEST(WeightedMedian, FillsOnlyNeverObservedCellsAndNeverWritesZero) {
    auto r = rasterFrom(12, [](int ix, int iy) { return 0.05 + 0.001 * ix + 0.002 * iy; });
    hide(r, 3, 3, 2, 1);
    r.certainty[r.index(8, 8)] = 0;  // certainty 0 but a height: still "never observed"
    FillOptions o;
    const auto f = weightedMedianFill(r, o);
    for (size_t k = 0; k < r.size(); k++) {
        if (r.isMeasured(k)) {
            EXPECT_EQ(f.source[k], HeightSource::Measured);
            EXPECT_EQ(f.height_m[k], r.height_m[k]);
            EXPECT_EQ(f.sigma_m[k], r.sigma_m[k]);
        } else {
            EXPECT_EQ(f.source[k], HeightSource::FilledMedian);
            EXPECT_GT(f.height_m[k], 0.05f);
        }
    }
    EXPECT_EQ(f.stats.median, 3);

    // Nothing to fill from: NaN stays NaN, never zero.
    HeightRaster empty(10, 10, 0.015);
    const auto e = fillGaps(empty, o);
    for (size_t k = 0; k < empty.size(); k++) {
        EXPECT_EQ(e.source[k], HeightSource::Unknown);
        EXPECT_TRUE(std::isnan(e.height_m[k]));
    }
    // One lonely measurement, too few for medianMinKnown = 3: still NaN.
    HeightRaster lonely(10, 10, 0.015);
    lonely.setMeasured(5, 5, 0.1f, 0.002f);
    o.maxGapCells = 10;  // the whole rest is one big gap: left Unfilled
    const auto l = fillGaps(lonely, o);
    EXPECT_EQ(l.stats.unfilled, 99);
}

TEST(WeightedMedian, RepeatedPassesFillALargeGapFromTheRim) {
    auto r = rasterFrom(20, [](int, int) { return 0.07; });
    hide(r, 5, 5, 10, 10);
    FillOptions o;
    const auto once = weightedMedianFill(r, o, false);
    EXPECT_EQ(once.stats.median, 100 - 36);  // the 6 x 6 core is beyond a 5 x 5 window
    const auto all = weightedMedianFill(r, o, true);
    EXPECT_EQ(all.stats.median, 100);
    for (size_t k = 0; k < r.size(); k++) EXPECT_NEAR(all.height_m[k], 0.07, 1e-7);
}
