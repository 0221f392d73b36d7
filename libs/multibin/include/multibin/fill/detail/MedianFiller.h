/* Part of the multibin elevation-mapping library. Internal to gap filling. */
#pragma once

#include <cstddef>
#include <vector>

#include "multibin/fill/FillOptions.h"
#include "multibin/fill/HeightRaster.h"

namespace multibin::fill::detail {

/** Weighted-median filling of single cells (the skeleton of medianSkeletonWeight); `usable`
 * tells which cells count as data. */
class MedianFiller {
public:
    MedianFiller(const HeightRaster& r, const FillOptions& o);

    /** Fills cell (ix, iy) of `out` from the cells of `out` flagged in `usable`; false (and the
     * cell untouched) if the window holds fewer than medianMinKnown of them. */
    bool fillCell(int ix, int iy, FillResult& out, const std::vector<char>& usable);

    /** Fills `cells` pass after pass, each pass using the cells filled by earlier passes; returns
     * how many were filled. */
    int fillRepeated(const std::vector<int>& cells, FillResult& out, std::vector<char>& usable);

private:
    struct Offset {
        int di, dj;
        std::ptrdiff_t linear;  // di + dj * nx
        double w;
    };
    struct Sample {
        float h, s, w;  // height [m], sigma [m], skeleton weight [cells]
    };
    int m_half = 2;
    const HeightRaster& m_r;
    const FillOptions& m_o;
    std::vector<Offset> m_offsets;
    std::vector<Sample> m_vals;
};

}  // namespace multibin::fill::detail
