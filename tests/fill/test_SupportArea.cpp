/* The semivariogram of a raster window (SupportArea.h), by hand. */
#include <gtest/gtest.h>

#include "fill_test_util.h"
#include "multibin/fill/SupportArea.h"

using namespace multibin::fill;
using namespace fill_test;

TEST(Semivariogram, LinearRampByHand) {
    // z = 0.01 ix: pairs along rows differ by 0.01 h, along columns by 0; in a square box both
    // directions have the same number of pairs, so gamma(h) = 0.5 * (0.01 h)^2 / 2.
    const auto r = rasterFrom(10, [](int ix, int) { return 0.01 * ix; });
    const auto g = semivariogram(r, 0, 0, 10, 10, 4);
    ASSERT_EQ(g.size(), 5u);
    EXPECT_EQ(g[0], 0.0);
    for (int h = 1; h <= 4; h++) EXPECT_NEAR(g[h], 0.25 * 1e-4 * h * h, 1e-9) << "lag " << h;
}
