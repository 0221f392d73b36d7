/* Gap labelling (GapLabelling.h): four-connected gaps and their sizes. */
#include <gtest/gtest.h>

#include <vector>

#include "fill_test_util.h"
#include "multibin/fill/GapLabelling.h"

using namespace multibin::fill;
using namespace fill_test;

TEST(GapComponents, LabelsFourConnectedGaps) {
    auto r = rasterFrom(6, [](int, int) { return 0.0; });
    hide(r, 0, 0, 2, 2);  // 4 cells
    hide(r, 2, 2, 1, 1);  // diagonal only: a separate gap
    hide(r, 4, 0, 1, 6);  // a column of 6
    std::vector<int> sizes;
    const auto label = labelGaps(r, sizes);
    ASSERT_EQ(sizes.size(), 3u);
    EXPECT_EQ(sizes[label[r.index(0, 0)]], 4);
    EXPECT_EQ(sizes[label[r.index(2, 2)]], 1);
    EXPECT_EQ(sizes[label[r.index(4, 5)]], 6);
    EXPECT_EQ(label[r.index(3, 3)], -1);
}
