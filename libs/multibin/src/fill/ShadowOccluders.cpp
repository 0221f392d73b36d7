/* Part of the multibin elevation-mapping library. */
#include "multibin/fill/ShadowOccluders.h"

#include <algorithm>
#include <cmath>

namespace multibin::fill {

namespace {

/** Median of v (reordered) [same unit]; v not empty. */
double median(std::vector<double>& v) {
    std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(v.size() / 2), v.end());
    return v[v.size() / 2];
}

/** Gradient (d/dx, d/dy) of the plane fitted (least squares) to the measured cells of the 5 x 5
 * window around cell (x, y) [m per cell]; zero with fewer than 6 cells. A plane averages the
 * cells' noise out, which differences of neighbours would count as slope. */
void planeGradient(const HeightRaster& r, int x, int y, double& gx, double& gy) {
    gx = gy = 0;
    double n = 0, sx = 0, sy = 0, sh = 0, sxx = 0, syy = 0, sxy = 0, sxh = 0, syh = 0;
    for (int dy = -2; dy <= 2; dy++)
        for (int dx = -2; dx <= 2; dx++) {
            if (!r.inside(x + dx, y + dy) || !r.isMeasured(r.index(x + dx, y + dy))) continue;
            const double h = r.height_m[r.index(x + dx, y + dy)];
            n++, sx += dx, sy += dy, sh += h;
            sxx += dx * dx, syy += dy * dy, sxy += dx * dy, sxh += dx * h, syh += dy * h;
        }
    if (n < 6) return;
    // Centred normal equations of h = a + gx dx + gy dy.
    const double cxx = sxx - sx * sx / n, cyy = syy - sy * sy / n, cxy = sxy - sx * sy / n;
    const double cxh = sxh - sx * sh / n, cyh = syh - sy * sh / n;
    const double det = cxx * cyy - cxy * cxy;
    if (!(det > 1e-9)) return;
    gx = (cyy * cxh - cxy * cyh) / det, gy = (cxx * cyh - cxy * cxh) / det;
}

/** Slope of the visible surface at (x, y) along the unit vector (ux, uy) [m per cell], as a
 * magnitude; with island, the steepest slope (no direction to look along). */
double slopeAlong(const HeightRaster& r, int x, int y, double ux, double uy, bool island) {
    double gx, gy;
    planeGradient(r, x, y, gx, gy);
    return island ? std::hypot(gx, gy) : std::abs(ux * gx + uy * gy);
}

/** One gap of a raster: which cells are in it, and how far across it a look may go. */
struct Gap {
    const HeightRaster& r;
    const std::vector<int>& cells;
    std::vector<char> isGap;
    double maxDist = 0;  //!< its bounding box's diagonal, plus one [cells]

    Gap(const HeightRaster& raster, const std::vector<int>& gapCells)
        : r(raster), cells(gapCells), isGap(raster.size(), 0) {
        const int nx = r.nx();
        int x0 = nx, x1 = -1, y0 = r.ny(), y1 = -1;
        for (int k : cells) {
            isGap[size_t(k)] = 1;
            const int x = k % nx, y = k / nx;
            x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
        }
        maxDist = std::hypot(x1 - x0 + 1, y1 - y0 + 1) + 1;
    }
    bool inGap(int x, int y) const { return r.inside(x, y) && isGap[r.index(x, y)]; }
    bool measured(int x, int y) const { return r.inside(x, y) && r.isMeasured(r.index(x, y)); }
};

/** The measured cells touching the gap (8-neighbours), once each. */
std::vector<int> rimOf(const Gap& g) {
    const HeightRaster& r = g.r;
    std::vector<char> seen(r.size(), 0);
    std::vector<int> rim;
    for (int k : g.cells) {
        const int x = k % r.nx(), y = k / r.nx();
        for (int dy = -1; dy <= 1; dy++)
            for (int dx = -1; dx <= 1; dx++)
                if (g.measured(x + dx, y + dy) && !seen[r.index(x + dx, y + dy)]) {
                    seen[r.index(x + dx, y + dy)] = 1;
                    rim.push_back(int(r.index(x + dx, y + dy)));
                }
    }
    return rim;
}

/** Rim cell (ox, oy)'s inward normal (ux, uy): the gap cells of the 5 x 5 window, weighted by
 * 1 / distance. Returns true for an island: a cell with the gap all around it (a stray return
 * inside a shadow) has no inward side, and gets (1, 0). */
bool inwardNormal(const Gap& g, int ox, int oy, double& ux, double& uy) {
    ux = uy = 0;
    for (int dy = -2; dy <= 2; dy++)
        for (int dx = -2; dx <= 2; dx++)
            if ((dx || dy) && g.inGap(ox + dx, oy + dy)) {
                const double d2 = dx * dx + dy * dy;
                ux += dx / d2, uy += dy / d2;
            }
    // A straight rim gives a norm of about 4.
    const double norm = std::hypot(ux, uy);
    const bool island = norm < 1.0;
    if (island)
        ux = 1, uy = 0;
    else
        ux /= norm, uy /= norm;
    return island;
}

/** A measured cell beyond the gap, seen from a rim cell. */
struct Hit {
    double h_m, sigma_m, dist;  //!< its height and sigma [m], distance from the rim cell [cells]
    int x, y;
};

/** The first measured cells beyond the gap from rim cell (ox, oy), looking along its inward
 * normal (nxv, nyv): a fan of five directions within +-30 degrees, or eight all round for an
 * island. A look that meets a measured cell before the gap, another gap or the raster's edge
 * finds nothing. */
void lookAcross(const Gap& g, int ox, int oy, double nxv, double nyv, bool island,
                std::vector<Hit>& hits) {
    const HeightRaster& r = g.r;
    constexpr double kPi = 3.14159265358979323846;
    const double fan_rad[5] = {-kPi / 6, -kPi / 12, 0, kPi / 12, kPi / 6};
    hits.clear();
    for (int q = 0; q < (island ? 8 : 5); q++) {
        const double a = island ? q * kPi / 4 : fan_rad[q];
        const double ux = std::cos(a) * nxv - std::sin(a) * nyv;
        const double uy = std::sin(a) * nxv + std::cos(a) * nyv;
        int px = ox, py = oy;
        bool enteredGap = false;
        for (double t = 0.5; t <= g.maxDist; t += 0.5) {
            const int x = int(std::lround(ox + t * ux)), y = int(std::lround(oy + t * uy));
            if (x == px && y == py) continue;
            px = x, py = y;
            if (g.inGap(x, y)) {
                enteredGap = true;
                continue;
            }
            if (enteredGap && g.measured(x, y)) {
                const size_t f = r.index(x, y);
                hits.push_back({r.height_m[f], r.sigma_m[f], t, x, y});
            }
            break;
        }
    }
}

/** An occluder rim cell, and the height halfway down its step [m]. */
struct Occluder {
    int k;
    double threshold_m;
};

/** The rim cells that stand above the far side by a step the sigmas and slopes do not explain
 * (ShadowOccluders.h). */
std::vector<Occluder> occluderRimCells(const Gap& g, const std::vector<int>& rim,
                                       const FillOptions& o) {
    const HeightRaster& r = g.r;
    std::vector<Occluder> occluders;
    std::vector<Hit> hits;
    std::vector<double> hitSigma;
    for (int k : rim) {
        const int ox = k % r.nx(), oy = k / r.nx();
        double nxv, nyv;
        const bool island = inwardNormal(g, ox, oy, nxv, nyv);
        lookAcross(g, ox, oy, nxv, nyv, island, hits);
        if (hits.size() < 3) continue;  // the fan mostly does not see across
        // The far side: the hit of median height, with the hits' median sigma (one stray cell
        // must not hide the step, nor fake one).
        std::nth_element(hits.begin(), hits.begin() + std::ptrdiff_t(hits.size() / 2), hits.end(),
                         [](const Hit& a, const Hit& b) { return a.h_m < b.h_m; });
        const Hit far = hits[hits.size() / 2];
        hitSigma.clear();
        for (const auto& h : hits) hitSigma.push_back(h.sigma_m);
        const double sf = median(hitSigma);
        const double ho = r.height_m[size_t(k)], so = r.sigma_m[size_t(k)];
        const double drop = ho - far.h_m;
        const double slope = std::max(slopeAlong(r, ox, oy, nxv, nyv, island),
                                      slopeAlong(r, far.x, far.y, nxv, nyv, island));
        const double explained =
            std::sqrt(so * so + sf * sf + (far.dist * slope) * (far.dist * slope));
        if (drop > o.shadowOccluders.stepSigmas * explained)
            occluders.push_back({k, ho - 0.5 * drop});
    }
    return occluders;
}

/** Whether a step runs through the gap: it is seen where it enters and where it leaves, as an
 * occluder rim cell next to a rim cell below its halfway height. A shadow's edge bounds the gap
 * and shows so at one end at most; two places or more (more than 2 cells apart) are a step. */
bool stepRunsThrough(const Gap& g, const std::vector<int>& rim,
                     const std::vector<Occluder>& occluders) {
    const HeightRaster& r = g.r;
    const int nx = r.nx();
    std::vector<char> isRim(r.size(), 0);
    for (int k : rim) isRim[size_t(k)] = 1;
    std::vector<int> contacts;  // one occluder rim cell per place
    for (const auto& oc : occluders) {
        const int x = oc.k % nx, y = oc.k / nx;
        bool seen = false;
        for (int dy = -1; dy <= 1; dy++)
            for (int dx = -1; dx <= 1; dx++)
                seen |= (dx || dy) && g.measured(x + dx, y + dy) &&
                        isRim[r.index(x + dx, y + dy)] &&
                        r.height_m[r.index(x + dx, y + dy)] < oc.threshold_m;
        if (!seen) continue;
        bool known = false;
        for (int c : contacts) known |= std::max(std::abs(c % nx - x), std::abs(c / nx - y)) <= 2;
        if (!known) contacts.push_back(oc.k);
    }
    return contacts.size() >= 2;
}

/** Marks each occluder's top: measured cells joined to its rim cell through cells above halfway
 * down its step, within `reach` cells (Chebyshev) of it. */
void markOccluderTops(const Gap& g, const std::vector<Occluder>& occluders, int reach,
                      std::vector<char>& mark) {
    const HeightRaster& r = g.r;
    const int nx = r.nx();
    std::vector<int> stamp(r.size(), -1), queue;
    for (size_t q = 0; q < occluders.size(); q++) {
        const auto& oc = occluders[q];
        const int ox = oc.k % nx, oy = oc.k / nx;
        queue.assign(1, oc.k);
        stamp[size_t(oc.k)] = int(q);
        for (size_t head = 0; head < queue.size(); head++) {
            const int k = queue[head], x = k % nx, y = k / nx;
            mark[size_t(k)] = 1;
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++) {
                    const int xx = x + dx, yy = y + dy;
                    if (std::max(std::abs(xx - ox), std::abs(yy - oy)) > reach) continue;
                    if (!g.measured(xx, yy)) continue;
                    const size_t kk = r.index(xx, yy);
                    if (stamp[kk] == int(q) || !(r.height_m[kk] > oc.threshold_m)) continue;
                    stamp[kk] = int(q);
                    queue.push_back(int(kk));
                }
        }
    }
}

/** Marks the stray returns inside the shadow: measured islands of at most kIsland cells with
 * nothing but this gap around them (a mixed pixel between the edge and the far ground, an
 * outlier). One or two returns do not describe the hidden surface; they stay measured, but are
 * not its data. */
void markStrayIslands(const Gap& g, const std::vector<int>& rim, std::vector<char>& mark) {
    const HeightRaster& r = g.r;
    constexpr size_t kIsland = 2;
    std::vector<int> component;
    for (int k : rim) {
        if (mark[size_t(k)]) continue;
        component.assign(1, k);
        bool enclosed = true;
        for (size_t head = 0; head < component.size() && enclosed; head++) {
            const int x = component[head] % r.nx(), y = component[head] / r.nx();
            for (int dy = -1; dy <= 1 && enclosed; dy++)
                for (int dx = -1; dx <= 1 && enclosed; dx++) {
                    if ((!dx && !dy) || g.inGap(x + dx, y + dy)) continue;
                    if (!g.measured(x + dx, y + dy)) {
                        enclosed = false;  // the raster's edge or another unknown cell
                        continue;
                    }
                    const int kk = int(r.index(x + dx, y + dy));
                    if (std::find(component.begin(), component.end(), kk) == component.end())
                        component.push_back(kk);
                    if (component.size() > kIsland) enclosed = false;
                }
        }
        if (enclosed)
            for (int kk : component) mark[size_t(kk)] = 1;
    }
}

/** Marks the stray returns on the far rim: a rim cell standing off the median of its measured
 * 8-neighbours by more than their spread (1.4826 MAD) and the sigmas explain. */
void markStrayRimCells(const Gap& g, const std::vector<int>& rim, const FillOptions& o,
                       std::vector<char>& mark) {
    const HeightRaster& r = g.r;
    std::vector<double> nb, nbSigma;
    for (int k : rim) {
        if (mark[size_t(k)]) continue;
        const int x = k % r.nx(), y = k / r.nx();
        nb.clear(), nbSigma.clear();
        for (int dy = -1; dy <= 1; dy++)
            for (int dx = -1; dx <= 1; dx++)
                if ((dx || dy) && g.measured(x + dx, y + dy)) {
                    nb.push_back(r.height_m[r.index(x + dx, y + dy)]);
                    nbSigma.push_back(r.sigma_m[r.index(x + dx, y + dy)]);
                }
        if (nb.empty()) continue;
        const double med = median(nb), medSigma = median(nbSigma);
        for (double& v : nb) v = std::abs(v - med);
        const double spread = 1.4826 * median(nb);
        const double s = r.sigma_m[size_t(k)];
        if (std::abs(r.height_m[size_t(k)] - med) >
            o.shadowOccluders.stepSigmas * std::sqrt(s * s + medSigma * medSigma + spread * spread))
            mark[size_t(k)] = 1;
    }
}

}  // namespace

ShadowOccluders findShadowOccluders(const HeightRaster& r, const std::vector<int>& cells,
                                    const FillOptions& o) {
    ShadowOccluders out;
    const Gap gap(r, cells);
    const std::vector<int> rim = rimOf(gap);
    const std::vector<Occluder> occluders = occluderRimCells(gap, rim, o);
    // A shadow is a strip behind its edge: area ~ length x width, and at least as long as wide,
    // so its occluder's rim is at least sqrt(area) cells long. A few cells that see lower
    // ground across a compact gap are a step the gap hides, not the edge that hid it.
    if (occluders.empty() || double(occluders.size()) < std::sqrt(double(cells.size()))) return out;
    if (stepRunsThrough(gap, rim, occluders)) return out;  // filled as any other gap
    out.rimCells = int(occluders.size());
    std::vector<char> mark(r.size(), 0);
    markOccluderTops(gap, occluders, o.shadowOccluders.reach_cells, mark);
    markStrayIslands(gap, rim, mark);
    markStrayRimCells(gap, rim, o, mark);
    for (size_t k = 0; k < mark.size(); k++)
        if (mark[k]) out.cells.push_back(int(k));
    return out;
}

HeightRaster withoutOccluders(const HeightRaster& r, const ShadowOccluders& occ) {
    HeightRaster masked = r;
    for (int k : occ.cells) masked.setUnknown(k % r.nx(), k / r.nx());
    return masked;
}

}  // namespace multibin::fill
