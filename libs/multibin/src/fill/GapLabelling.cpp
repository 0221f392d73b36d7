/* Part of the multibin elevation-mapping library. */
#include "multibin/fill/GapLabelling.h"

#include <algorithm>

namespace multibin::fill {

std::vector<int> labelGaps(const HeightRaster& r, std::vector<int>& sizes) {
    std::vector<int> label(r.size(), -1);
    sizes.clear();
    std::vector<int> stack;
    for (int iy = 0; iy < r.ny(); iy++)
        for (int ix = 0; ix < r.nx(); ix++) {
            const size_t k0 = r.index(ix, iy);
            if (label[k0] != -1 || r.isMeasured(k0)) continue;
            const int id = int(sizes.size());
            sizes.push_back(0);
            label[k0] = id;
            stack.assign(1, int(k0));
            while (!stack.empty()) {
                const int k = stack.back();
                stack.pop_back();
                sizes[id]++;
                const int x = k % r.nx(), y = k / r.nx();
                const int nb[4][2] = {{x - 1, y}, {x + 1, y}, {x, y - 1}, {x, y + 1}};
                for (const auto& p : nb) {
                    if (!r.inside(p[0], p[1])) continue;
                    const size_t kk = r.index(p[0], p[1]);
                    if (label[kk] == -1 && !r.isMeasured(kk)) {
                        label[kk] = id;
                        stack.push_back(int(kk));
                    }
                }
            }
        }
    return label;
}

bool medianReaches(const HeightRaster& r, const std::vector<int>& cells, const FillOptions& o) {
    const int half = o.medianWindow_cells / 2;
    for (int k : cells) {
        // Measured cells in the window around the cell, clipped to the raster.
        const int ix = k % r.nx(), iy = k / r.nx();
        const int xa = std::max(ix - half, 0), xb = std::min(ix + half + 1, r.nx());
        const int ya = std::max(iy - half, 0), yb = std::min(iy + half + 1, r.ny());
        int known = 0;
        for (int y = ya; y < yb; y++)
            for (int x = xa; x < xb; x++) known += int(r.isMeasured(r.index(x, y)));
        if (known < o.medianMinKnown) return false;
    }
    return true;
}

std::vector<Gap> collectGaps(const HeightRaster& r, const std::vector<int>& label,
                             const std::vector<int>& sizes, const FillOptions& o) {
    std::vector<Gap> gaps(sizes.size());
    for (size_t id = 0; id < sizes.size(); id++)
        if (sizes[id] <= o.maxGapCells) gaps[id].cells.reserve(size_t(sizes[id]));
    for (size_t k = 0; k < r.size(); k++) {
        const int id = label[k];
        if (id >= 0 && sizes[size_t(id)] <= o.maxGapCells) gaps[size_t(id)].cells.push_back(int(k));
    }
    for (Gap& g : gaps) g.medianReach = medianReaches(r, g.cells, o);
    return gaps;
}

}  // namespace multibin::fill
