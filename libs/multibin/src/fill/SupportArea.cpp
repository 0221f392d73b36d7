/* Part of the multibin elevation-mapping library. */
#include "multibin/fill/SupportArea.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "multibin/fill/Kriging.h"

namespace multibin::fill {

SupportArea::SupportArea(const HeightRaster& r, const FillOptions& o, std::vector<int> gapCells)
    : cells(std::move(gapCells)), m_nx(r.nx()) {
    x0 = r.nx(), x1 = -1, y0 = r.ny(), y1 = -1;
    for (int k : cells) {
        const int x = k % r.nx(), y = k / r.nx();
        x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
    }
    side = std::max(x1 - x0 + 1, y1 - y0 + 1) + 2 * o.supportMargin_cells;
    // Centre the square on the gap, then slide it inside the raster where it fits.
    auto place = [&](int lo, int hi, int n) {
        int start = (lo + hi + 1) / 2 - side / 2;
        start = std::min(start, n - side);
        return std::max(start, 0);
    };
    sx = place(x0, x1, r.nx()), sy = place(y0, y1, r.ny());
    ex = std::min(sx + side, r.nx()), ey = std::min(sy + side, r.ny());

    // Training points: measured cells of the area, the ones nearest the gap first if capped.
    // Distance to the gap itself (multi-source breadth-first search, 8-neighbour steps), not to
    // its bounding box: for a long or L-shaped gap the box says little.
    const int bw = ex - sx, bh = ey - sy;
    std::vector<int> gapDist(size_t(bw) * size_t(bh), -1);
    std::vector<int> queue;
    queue.reserve(gapDist.size());
    for (int k : cells) {
        const size_t b = size_t(k / r.nx() - sy) * size_t(bw) + size_t(k % r.nx() - sx);
        gapDist[b] = 0;
        queue.push_back(int(b));
    }
    for (size_t head = 0; head < queue.size(); head++) {
        const int b = queue[head], bx = b % bw, by = b / bw;
        for (int dy = -1; dy <= 1; dy++)
            for (int dx = -1; dx <= 1; dx++) {
                const int nx = bx + dx, ny = by + dy;
                if (nx < 0 || ny < 0 || nx >= bw || ny >= bh) continue;
                const size_t nb = size_t(ny) * size_t(bw) + size_t(nx);
                if (gapDist[nb] >= 0) continue;
                gapDist[nb] = gapDist[size_t(b)] + 1;
                queue.push_back(int(nb));
            }
    }
    for (int iy = sy; iy < ey; iy++)
        for (int ix = sx; ix < ex; ix++) {
            const size_t k = r.index(ix, iy);
            if (!r.isMeasured(k)) continue;
            training.push_back({SurfaceSample{ix - sx, iy - sy, r.height_m[k], r.sigma_m[k]},
                                gapDist[size_t(iy - sy) * size_t(bw) + size_t(ix - sx)]});
        }
    for (const auto& c : training) {
        all.push_back(c.s);
        (c.gapDist <= 2 ? rim : beyondRim).push_back(c.s);
    }
    gapI = 0.5 * (x0 + x1) - sx, gapJ = 0.5 * (y0 + y1) - sy;
    keepNearestToGap(training, size_t(o.maxTrainingPoints), gapI, gapJ);
    samples.reserve(training.size());
    for (const auto& c : training) samples.push_back(c.s);
    if (!samples.empty()) {
        heightLo_m = heightHi_m = samples[0].h_m;
        for (const auto& s : samples)
            heightLo_m = std::min(heightLo_m, s.h_m), heightHi_m = std::max(heightHi_m, s.h_m);
    }
}

int SupportArea::i(size_t c) const { return cells[c] % m_nx - sx; }
int SupportArea::j(size_t c) const { return cells[c] / m_nx - sy; }

void keepNearestToGap(std::vector<TrainingPoint>& cand, size_t count, double ci, double cj) {
    using Cand = TrainingPoint;
    if (cand.size() <= count) return;
    std::stable_sort(cand.begin(), cand.end(),
                     [](const Cand& a, const Cand& b) { return a.gapDist < b.gapDist; });
    const int cut = cand[count - 1].gapDist;
    const auto lo =
        std::find_if(cand.begin(), cand.end(), [&](const Cand& c) { return c.gapDist == cut; });
    const auto hi = std::find_if(lo, cand.end(), [&](const Cand& c) { return c.gapDist > cut; });
    const size_t left = count - size_t(lo - cand.begin()), ring = size_t(hi - lo);
    if (left < ring) {
        auto angle = [&](const Cand& c) { return std::atan2(c.s.j - cj, c.s.i - ci); };
        std::stable_sort(lo, hi, [&](const Cand& a, const Cand& b) { return angle(a) < angle(b); });
        // Place t of `left` takes the ring's point floor((t + 0.5) ring / left): evenly spread.
        for (size_t t = 0; t < left; t++)
            *(lo + std::ptrdiff_t(t)) = *(lo + std::ptrdiff_t((2 * t + 1) * ring / (2 * left)));
    }
    cand.resize(count);
}

std::vector<SurfaceSample> nearestToGap(const SupportArea& a, size_t count) {
    std::vector<TrainingPoint> nearCand = a.training;
    keepNearestToGap(nearCand, count, a.gapI, a.gapJ);
    std::vector<SurfaceSample> near;
    for (const auto& c : nearCand) near.push_back(c.s);
    return near;
}

std::vector<double> semivariogram(const HeightRaster& r, int x0, int y0, int w, int h, int maxLag) {
    const int xa = std::max(x0, 0), ya = std::max(y0, 0);
    const int xb = std::min(x0 + w, r.nx()), yb = std::min(y0 + h, r.ny());
    const int bw = std::max(xb - xa, 0), bh = std::max(yb - ya, 0);
    std::vector<double> box(size_t(bw) * size_t(bh), std::numeric_limits<double>::quiet_NaN());
    for (int iy = ya; iy < yb; iy++)
        for (int ix = xa; ix < xb; ix++) {
            const size_t k = r.index(ix, iy);
            if (r.isMeasured(k))
                box[size_t(iy - ya) * size_t(bw) + size_t(ix - xa)] = r.height_m[k];
        }
    return gridSemivariogram(box, bw, bh, maxLag);
}

}  // namespace multibin::fill
