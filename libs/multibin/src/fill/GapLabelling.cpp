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

std::vector<Gap> collectGaps(const HeightRaster& r, const std::vector<int>& label,
                             const std::vector<int>& sizes, const FillOptions& o) {
    // Measured cells per window, from a summed-area table: O(1) per cell.
    const int nx = r.nx(), ny = r.ny();
    const int half = o.medianWindow_cells / 2;
    std::vector<int> sat(size_t(nx + 1) * size_t(ny + 1), 0);
    auto S = [&](int x, int y) -> int& { return sat[size_t(y) * size_t(nx + 1) + size_t(x)]; };
    for (int iy = 0; iy < ny; iy++)
        for (int ix = 0; ix < nx; ix++)
            S(ix + 1, iy + 1) = int(r.isMeasured(r.index(ix, iy))) + S(ix, iy + 1) +
                                S(ix + 1, iy) - S(ix, iy);
    auto knownInWindow = [&](int ix, int iy) {
        const int xa = std::max(ix - half, 0), xb = std::min(ix + half + 1, nx);
        const int ya = std::max(iy - half, 0), yb = std::min(iy + half + 1, ny);
        return S(xb, yb) - S(xa, yb) - S(xb, ya) + S(xa, ya);
    };

    std::vector<Gap> gaps(sizes.size());
    for (size_t id = 0; id < sizes.size(); id++)
        if (sizes[id] <= o.maxGapCells) gaps[id].cells.reserve(size_t(sizes[id]));
    for (size_t k = 0; k < r.size(); k++) {
        const int id = label[k];
        if (id < 0 || sizes[size_t(id)] > o.maxGapCells) continue;
        gaps[size_t(id)].cells.push_back(int(k));
        if (knownInWindow(int(k) % nx, int(k) / nx) < o.medianMinKnown)
            gaps[size_t(id)].medianReach = false;
    }
    return gaps;
}

}  // namespace multibin::fill
