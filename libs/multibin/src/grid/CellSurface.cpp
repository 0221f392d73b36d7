/* Part of the multibin elevation-mapping library. */
#include "multibin/grid/CellSurface.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "multibin/grid/BinUpdate.h"

namespace multibin {

bool cellSurface(const BinGrid& grid, int ix, int iy, const BinUpdateParams& p, CellSurface& out) {
    // The cell's bins gathered by one walk of its chain (one look-up of its slot) and the winner
    // found on the way (winningBin()'s rule); the bins next to it are then looked for here.
    constexpr size_t kInline = 16;
    const Bin* inlineBins[kInline];
    std::vector<const Bin*> more;  // a cell of more than kInline bins
    size_t n = 0;
    const Bin* win = nullptr;
    grid.forEachBin(ix, iy, [&](const Bin& b) {
        if (n < kInline) {
            inlineBins[n] = &b;
        } else {
            if (more.empty()) more.assign(inlineBins, inlineBins + kInline);
            more.push_back(&b);
        }
        n++;
        if (BinGrid::winsOver(b, win)) win = &b;
    });
    if (!win) return false;
    const Bin* const* bins = n <= kInline ? inlineBins : more.data();
    const double floor_m2 = p.varianceFloor_m2;
    HeightInformation surface;
    surface.add(win->height_m, std::max<double>(win->variance_m2, floor_m2));
    uint8_t poseHeightCode = win->poseHeightSigmaCode;
    out.certainty = win->certainty;
    out.firstBin = out.lastBin = win->index;
    for (const int dir : {-1, 1}) {
        for (int index = win->index + dir;; index += dir) {
            const Bin* next = nullptr;
            for (size_t k = 0; k < n; k++)
                if (bins[k]->index == index && bins[k]->certainty > 0) next = bins[k];
            if (!next) break;
            const double v = std::max<double>(next->variance_m2, floor_m2);
            const double h = surface.height_m(), vNow = surface.variance_m2();
            if ((next->height_m - h) * (next->height_m - h) > 9.0 * (v + vNow)) break;
            surface.add(next->height_m, v);
            out.certainty += next->certainty;
            poseHeightCode = leastPoseSigmaCode(poseHeightCode, next->poseHeightSigmaCode);
            (dir < 0 ? out.firstBin : out.lastBin) = index;
        }
    }
    out.height_m = surface.height_m();
    out.variance_m2 = std::max(surface.variance_m2(), floor_m2);
    out.poseVariance_m2 = poseVariance_m2(poseHeightCode);
    return true;
}

namespace {

/** Adds to the variance the spread of the cell's certain bins outside the surface. */
void addOtherBinsSpread(const BinGrid& grid, int ix, int iy, CellSurface& cell) {
    // Certain bins outside the surface: the cell also holds surfaces at other heights (a step
    // inside the cell, its top and its foot seen from different places). The truth of the cell,
    // the mean over its area, lies between them: their spread around the reported height,
    // weighted by each bin's share of the cell's certainty, is part of the cell's uncertainty.
    double otherCertainty = 0, otherSpread_m2 = 0;
    grid.forEachBin(ix, iy, [&](const Bin& b) {
        if (b.certainty <= 0 || (b.index >= cell.firstBin && b.index <= cell.lastBin)) return;
        otherCertainty += b.certainty;
        otherSpread_m2 += b.certainty * (b.height_m - cell.height_m) * (b.height_m - cell.height_m);
    });
    if (otherCertainty > 0) cell.variance_m2 += otherSpread_m2 / (otherCertainty + cell.certainty);
}

/** Combines the estimates of the global and the local grid (either may be missing). */
bool combineGrids(bool haveG, const CellSurface& g, bool haveL, const CellSurface& l,
                  CellSurface& out) {
    if (!haveG && !haveL) return false;
    if (!haveG || !haveL) {
        out = haveG ? g : l;
        return true;
    }
    const double d = l.height_m - g.height_m;
    if (d * d <= 9.0 * (g.variance_m2 + l.variance_m2)) {
        HeightInformation both;
        both.add(g.height_m, g.variance_m2);
        both.add(l.height_m, l.variance_m2);
        out = l;
        out.height_m = both.height_m();
        out.variance_m2 = both.variance_m2();
        out.certainty = g.certainty + l.certainty;
        // Both grids' points were seen from the same poses: their shared part stays.
        out.poseVariance_m2 = std::min(g.poseVariance_m2, l.poseVariance_m2);
    } else {
        out = l.certainty >= g.certainty ? l : g;
    }
    return true;
}

/** A cell's surface with the plane moments of its bins merged. */
struct CellPlane {
    CellSurface surface;
    PlaneMoments moments;
    double points = 0;
    uint8_t poseHorizontalSigmaCode = 0;  //!< least over its bins (BinUpdate.h)
};

/** The most surfaces of one cell heightAt tells apart. */
constexpr int kMaxSurfaces = 4;

/** The surface of the certain bins [first, last] of a cell. */
void planeOfBins(const BinGrid& grid, int ix, int iy, const BinUpdateParams& p, CellPlane& out) {
    HeightInformation h;
    out.moments = PlaneMoments{};
    out.points = 0;
    out.poseHorizontalSigmaCode = 0;
    uint8_t poseHeightCode = 0;
    out.surface.certainty = 0;
    grid.forEachBin(ix, iy, [&](const Bin& b) {
        if (b.certainty <= 0 || b.index < out.surface.firstBin || b.index > out.surface.lastBin)
            return;
        h.add(b.height_m, std::max<double>(b.variance_m2, p.varianceFloor_m2));
        out.surface.certainty += b.certainty;
        poseHeightCode = leastPoseSigmaCode(poseHeightCode, b.poseHeightSigmaCode);
        out.poseHorizontalSigmaCode =
            leastPoseSigmaCode(out.poseHorizontalSigmaCode, b.poseHorizontalSigmaCode);
        mergePlaneMoments(out.moments, b.plane);
        out.points += b.pointCount;
    });
    out.surface.height_m = h.height_m();
    out.surface.variance_m2 = std::max(h.variance_m2(), p.varianceFloor_m2);
    out.surface.poseVariance_m2 = poseVariance_m2(poseHeightCode);
}

/** The surfaces of a cell, most certain first: runs of certain bins with contiguous indices
 * whose heights could come from one surface, point for point (within 3 sigma of the points'
 * own noise, n / sum w per bin). cellSurface's test compares the bins' means, which split a
 * surface lying on a bin boundary once the bins hold many points (each keeps a truncated
 * share, their means a point sigma or more apart); a step of a bin's height or more stays
 * apart. Returns how many. */
int cellPlanes(const BinGrid& grid, int ix, int iy, const BinUpdateParams& p,
               CellPlane (&out)[kMaxSurfaces]) {
    const Bin* bins[32];
    int count = 0;
    grid.forEachBin(ix, iy, [&](const Bin& b) {
        if (b.certainty > 0 && count < 32) bins[count++] = &b;
    });
    if (count == 0) return 0;
    std::sort(bins, bins + count, [](const Bin* a, const Bin* b) { return a->index < b->index; });
    auto pointVariance = [&](const Bin& b) {
        return b.plane.weight > 0 ? b.pointCount / double(b.plane.weight)
                                  : std::max<double>(b.variance_m2, p.varianceFloor_m2);
    };
    int n = 0;
    for (int i = 0; i < count;) {
        int j = i;
        while (j + 1 < count && bins[j + 1]->index == bins[j]->index + 1) {
            const double d = bins[j + 1]->height_m - bins[j]->height_m;
            if (d * d > 9.0 * (pointVariance(*bins[j]) + pointVariance(*bins[j + 1]))) break;
            j++;
        }
        CellPlane c;
        c.surface.firstBin = bins[i]->index;
        c.surface.lastBin = bins[j]->index;
        planeOfBins(grid, ix, iy, p, c);
        // Keep the most certain kMaxSurfaces, most certain first.
        int k = std::min(n, kMaxSurfaces - 1);
        if (n == kMaxSurfaces && !(c.surface.certainty > out[k].surface.certainty)) {
            i = j + 1;
            continue;
        }
        for (; k > 0 && c.surface.certainty > out[k - 1].surface.certainty; k--)
            out[k] = out[k - 1];
        out[k] = c;
        n = std::min(n + 1, kMaxSurfaces);
        i = j + 1;
    }
    return n;
}

/** Which of a cell's surfaces holds the point (dx_m, dy_m) from the cell's centre: the most
 * likely under a Gaussian of each surface's points' footprint (weighted mean and covariance,
 * widened by a tenth of the cell), its prior the surface's share of the cell's certainty (its
 * share of the points, less what contradicting data took away). */
int surfaceHolding(const CellPlane* planes, int count, double dx_m, double dy_m, double cell_m) {
    int best = 0;
    double bestScore = std::numeric_limits<double>::infinity();
    const double widen_m2 = 0.01 * cell_m * cell_m;
    for (int k = 0; k < count; k++) {
        const PlaneMoments& m = planes[k].moments;
        if (!(m.weight > 0) || !(planes[k].points > 0)) continue;
        const double a = m.sxx / m.weight + widen_m2, b = m.sxy / m.weight,
                     c = m.syy / m.weight + widen_m2;
        const double det = a * c - b * b;
        const double ex = dx_m - m.mx_m, ey = dy_m - m.my_m;
        const double d2 = (c * ex * ex - 2 * b * ex * ey + a * ey * ey) / det;
        // The prior is the surface's certainty, not its points: what a bin lost to the
        // visibility constraint (newer data saw through it) counts against it here too.
        const double score = d2 + std::log(det) - 2 * std::log(planes[k].surface.certainty);
        if (score < bestScore) {
            bestScore = score;
            best = k;
        }
    }
    return best;
}

/** A gradient [-] and its covariance; chi2 is the plane fit's residual per degree of freedom
 * (at least 1: the points' own variances are the least the scatter can be). */
struct Gradient {
    double gx = 0, gy = 0;
    double cxx = kUnknownSlope * kUnknownSlope, cxy = 0, cyy = kUnknownSlope * kUnknownSlope;
    double chi2 = 1;
    double variance(double ex, double ey) const {
        return cxx * ex * ex + 2 * cxy * ex * ey + cyy * ey * ey;
    }
};

/** The weighted least-squares gradient of the moments; false if they define no plane (fewer
 * than 4 points, or points on a line). */
bool gradientOf(const PlaneMoments& m, double points, Gradient& g) {
    const double a = m.sxx, b = m.sxy, c = m.syy;
    const double det = a * c - b * b, trace = a + c;
    if (points < 4 || !(det > 1e-3 * trace * trace)) return false;
    const double fitGx = (c * m.sxz - b * m.syz) / det;
    const double fitGy = (a * m.syz - b * m.sxz) / det;
    const double rss = m.szz - fitGx * m.sxz - fitGy * m.syz;
    g.chi2 = std::max(1.0, rss / (points - 3));
    // The fit combined with the prior every gradient has (0 +- kUnknownSlope per axis): points
    // nearly on a line leave the slope across the line undetermined, and the fit alone would
    // extrapolate it to metres at a cell's edge; the prior keeps it near 0 there and changes a
    // well-spread fit by a fraction of its own sigma.
    const double prior = 1.0 / (kUnknownSlope * kUnknownSlope);
    const double ia = a / g.chi2 + prior, ib = b / g.chi2, ic = c / g.chi2 + prior;
    const double idet = ia * ic - ib * ib;
    const double rx = m.sxz / g.chi2, ry = m.syz / g.chi2;
    g.gx = (ic * rx - ib * ry) / idet;
    g.gy = (ia * ry - ib * rx) / idet;
    g.cxx = ic / idet;
    g.cxy = -ib / idet;
    g.cyy = ia / idet;
    return true;
}

/** The plane of one surface of a cell, as far as it does not depend on the query point: its
 * gradient from the cell's and the agreeing neighbours' points, the variance at its centroid and
 * the pose part. */
struct SurfacePlane {
    Gradient g;
    double variance_m2 = 0;      //!< at the centroid, with the relief the plane misses [m^2]
    double poseVariance_m2 = 0;  //!< CellSurface::poseVariance_m2 [m^2]
};

/** The cells heightAt reads, each computed on first use: its surfaces (cellPlanes) and their
 * planes (SurfacePlane). Cell (ix, iy) has the slot (iy mod 4, ix mod columns), columns a power
 * of 2 of at least 4: the 4 x 4 cells a query reads (the 2 x 2 around the point and their
 * neighbours) never share a slot, and queries sorted by row and column find the cells of the
 * queries before them. A slot holds its cell until another cell needs it. */
class CellPlanesCache {
public:
    CellPlanesCache(const BinGrid& grid, const BinUpdateParams& p, int columnsLog2 = 2)
        : m_grid(grid), m_params(p), m_columnMask((1 << std::max(columnsLog2, 2)) - 1) {
        const size_t slots = size_t(4) * size_t(m_columnMask + 1);
        if (slots > kInline) {  // a batch's: on the heap
            m_heapTags.resize(slots);
            m_heapSlots.reset(new Slot[slots]);
            m_tags = m_heapTags.data();
            m_slots = m_heapSlots.get();
        }
    }
    CellPlanesCache(const CellPlanesCache&) = delete;
    CellPlanesCache& operator=(const CellPlanesCache&) = delete;

    /** The surfaces of cell (ix, iy); returns how many. */
    int planesOf(int ix, int iy, const CellPlane*& planes) {
        if (!m_grid.window().contains(ix, iy)) return 0;  // as cellPlanes: no bins there
        const size_t k = slotOf(ix, iy);
        planes = m_slots[k].surfaces;
        return m_tags[k].count;
    }
    /** The plane of surface k of cell (ix, iy), which holds at least k + 1 surfaces. */
    const SurfacePlane& planeOf(int ix, int iy, int k);
    /** Computes the surfaces of the 4 x 4 cells from (ix0, iy0) not held yet, in one loop: the
     * loads of their bins overlap there, as they do not between the planes' arithmetic. */
    void readCells(int ix0, int iy0) {
        for (int iy = iy0; iy < iy0 + 4; iy++)
            for (int ix = ix0; ix < ix0 + 4; ix++)
                if (m_grid.window().contains(ix, iy)) slotOf(ix, iy);
    }
    const BinGrid& grid() const { return m_grid; }

private:
    struct Tag {
        int ix = 0, iy = 0;
        int count = -1;       //!< surfaces; -1: the slot holds no cell yet
        unsigned planes = 0;  //!< bit k: planes[k] computed
    };
    struct Slot {
        Slot() {}  // written before read: a large cache costs only the slots queries use
        union {
            CellPlane surfaces[kMaxSurfaces];
        };
        union {
            SurfacePlane planes[kMaxSurfaces];
        };
    };
    /** The slots of one query (4 x 4), kept in the object: a single query allocates nothing. */
    static constexpr size_t kInline = 16;

    size_t slotOf(int ix, int iy) {
        const size_t k = size_t(iy & 3) * size_t(m_columnMask + 1) + size_t(ix & m_columnMask);
        Tag& t = m_tags[k];
        if (t.count < 0 || t.ix != ix || t.iy != iy)
            t = Tag{ix, iy, cellPlanes(m_grid, ix, iy, m_params, m_slots[k].surfaces), 0};
        return k;
    }

    const BinGrid& m_grid;
    const BinUpdateParams m_params;
    const int m_columnMask;
    Tag m_inlineTags[kInline];
    Slot m_inlineSlots[kInline];
    std::vector<Tag> m_heapTags;
    std::unique_ptr<Slot[]> m_heapSlots;
    Tag* m_tags = m_inlineTags;
    Slot* m_slots = m_inlineSlots;
};

/** The plane of surface `surface` of cell (ix, iy): its gradient from the cell's and the agreeing
 * neighbours' points. `cache` holds the cell and its eight neighbours. */
void surfacePlane(CellPlanesCache& cache, int ix, int iy, int surface, SurfacePlane& out) {
    const CellPlane* planes;
    cache.planesOf(ix, iy, planes);
    const CellPlane& own = planes[surface];
    const double s = cache.grid().cellSize_m();
    const PlaneMoments& m = own.moments;
    const double h = own.surface.height_m, hVar = own.surface.variance_m2;
    Gradient gOwn;
    gradientOf(m, own.points, gOwn);
    // The neighbours on the same surface: a surface of the neighbour whose height at its
    // centroid and the cell's agree within 3 sigma as seen from either plane.
    PlaneMoments window = m;
    double windowPoints = own.points;
    for (int dy = -1; dy <= 1; dy++)
        for (int dx = -1; dx <= 1; dx++) {
            const CellPlane* nb = nullptr;
            const int nbCount = (dx == 0 && dy == 0) ? 0 : cache.planesOf(ix + dx, iy + dy, nb);
            for (int k = 0; k < nbCount; k++) {
                if (!(nb[k].moments.weight > 0)) continue;
                const double ex = dx * s + nb[k].moments.mx_m - m.mx_m;
                const double ey = dy * s + nb[k].moments.my_m - m.my_m;
                const double d = nb[k].surface.height_m - h;
                const double both = hVar + nb[k].surface.variance_m2;
                const double fromOwn = d - gOwn.gx * ex - gOwn.gy * ey;
                if (fromOwn * fromOwn > 9.0 * (both + gOwn.variance(ex, ey))) continue;
                Gradient gNb;
                gradientOf(nb[k].moments, nb[k].points, gNb);
                const double fromNb = d - gNb.gx * ex - gNb.gy * ey;
                if (fromNb * fromNb > 9.0 * (both + gNb.variance(ex, ey))) continue;
                mergePlaneMoments(window, nb[k].moments, dx * s, dy * s);
                windowPoints += nb[k].points;
                break;
            }
        }
    Gradient& g = out.g;
    if (!gradientOf(window, windowPoints, g)) g = gOwn;
    // The points' scatter around the plane beyond their own variances: it widens h's variance,
    // and the truth at the query point departs from the plane by as much (the relief the plane
    // does not follow).
    const double relief_m2 =
        window.weight > 0 ? (g.chi2 - 1) * windowPoints / double(window.weight) : 0.0;
    out.variance_m2 = std::max(hVar, m.weight > 0 ? g.chi2 / m.weight : 0.0) + relief_m2;
    // A pose error moves the surface sideways too, shared by the points like its height part: on
    // a slope g the height at a fixed place changes by g . (horizontal shift).
    out.poseVariance_m2 =
        own.surface.poseVariance_m2 +
        poseVariance_m2(own.poseHorizontalSigmaCode) * (g.gx * g.gx + g.gy * g.gy);
}

const SurfacePlane& CellPlanesCache::planeOf(int ix, int iy, int k) {
    const size_t slot = slotOf(ix, iy);
    if (!(m_tags[slot].planes & (1u << k))) {
        surfacePlane(*this, ix, iy, k, m_slots[slot].planes[k]);  // its neighbours: other slots
        m_tags[slot].planes |= 1u << k;
    }
    return m_slots[slot].planes[k];
}

/** The plane of cell (ix, iy) at (x_m, y_m), which may lie outside the cell: the surface
 * that holds the point, its plane from the cell's and the agreeing neighbours' points. */
bool planeOfCellAt(CellPlanesCache& cache, int ix, int iy, double x_m, double y_m,
                   CellSurface& out) {
    const CellPlane* planes;
    const int count = cache.planesOf(ix, iy, planes);
    if (count == 0) return false;
    const BinGrid& grid = cache.grid();
    const double s = grid.cellSize_m();
    const double qx = x_m - grid.cellCenter_m(ix), qy = y_m - grid.cellCenter_m(iy);
    const int k = count == 1 ? 0 : surfaceHolding(planes, count, qx, qy, s);  // 1: no choice
    const PlaneMoments& m = planes[k].moments;
    const SurfacePlane& plane = cache.planeOf(ix, iy, k);
    // Without points (a map loaded from a file keeps no moments) the centroid is the centre.
    const double ex = qx - m.mx_m, ey = qy - m.my_m;
    out = planes[k].surface;
    out.height_m = planes[k].surface.height_m + plane.g.gx * ex + plane.g.gy * ey;
    out.variance_m2 = plane.variance_m2 + plane.g.variance(ex, ey);
    out.poseVariance_m2 = plane.poseVariance_m2;
    return true;
}

/** heightAt on one grid: the planes of the four cells around the point (whose centres it lies
 * between) evaluated at the point and blended with bilinear weights, a neighbour's only where it
 * agrees with the point's own cell within 3 sigma of the planes (never across a step). One
 * cell's plane carries its few points' noise; the blend averages four such estimates, as
 * bilinear interpolation of cell values does, while each keeps its slope. */
bool planeHeightAt(CellPlanesCache& cache, double x_m, double y_m, bool reliefSigma,
                   CellSurface& out) {
    const BinGrid& grid = cache.grid();
    const int ix = grid.cellIndex(x_m), iy = grid.cellIndex(y_m);
    const double s = grid.cellSize_m();
    const int bx = grid.cellIndex(x_m - 0.5 * s), by = grid.cellIndex(y_m - 0.5 * s);
    const CellPlane* planes;
    if (cache.planesOf(ix, iy, planes) == 0) return false;
    cache.readCells(bx - 1, by - 1);
    planeOfCellAt(cache, ix, iy, x_m, y_m, out);
    const double fx = (x_m - grid.cellCenter_m(bx)) / s, fy = (y_m - grid.cellCenter_m(by)) / s;
    const CellSurface own = out;
    double weightSum = 0, heightSum = 0, varianceSum = 0;
    for (int j = 0; j <= 1; j++)
        for (int i = 0; i <= 1; i++) {
            const double w = (i ? fx : 1 - fx) * (j ? fy : 1 - fy);
            CellSurface c = own;
            if (bx + i != ix || by + j != iy) {
                if (!planeOfCellAt(cache, bx + i, by + j, x_m, y_m, c)) continue;
                const double d = c.height_m - own.height_m;
                if (d * d > 9.0 * (c.variance_m2 + own.variance_m2)) continue;
            }
            weightSum += w;
            heightSum += w * c.height_m;
            // The planes share points (each one's window holds its neighbours'): the weighted
            // mean of their variances, not the variance of a mean of independent estimates.
            varianceSum += w * c.variance_m2;
        }
    if (weightSum > 0) {  // 0 only where the own cell's weight is 0 and no neighbour agrees
        out.height_m = heightSum / weightSum;
        out.variance_m2 = varianceSum / weightSum;
    }
    if (reliefSigma) addOtherBinsSpread(grid, ix, iy, out);
    return true;
}

}  // namespace

void addReliefVariance(const BinGrid& grid, double x_m, double y_m, const BinUpdateParams& p,
                       CellSurface& cell) {
    // Without it sigma is a few mm on 45 degree rock faces where the cell's height is uncertain
    // by a centimetre. The slope from central differences, one-sided at gaps.
    const double s = grid.cellSize_m();
    double slope2 = 0;
    for (const auto& [dx, dy] : {std::pair<double, double>{s, 0.0}, {0.0, s}}) {
        CellSurface lo, hi;
        const bool haveLo = cellSurface(grid, x_m - dx, y_m - dy, p, lo);
        const bool haveHi = cellSurface(grid, x_m + dx, y_m + dy, p, hi);
        double g = 0;
        if (haveLo && haveHi)
            g = (hi.height_m - lo.height_m) / (2 * s);
        else if (haveLo)
            g = (cell.height_m - lo.height_m) / s;
        else if (haveHi)
            g = (hi.height_m - cell.height_m) / s;
        slope2 += g * g;
    }
    cell.variance_m2 += slope2 * s * s / 12.0;
    addOtherBinsSpread(grid, grid.cellIndex(x_m), grid.cellIndex(y_m), cell);
}

bool surfaceAt(const BinGrid& grid, const BinGrid* local, double x_m, double y_m,
               const BinUpdateParams& p, bool reliefSigma, CellSurface& out) {
    CellSurface g, l;
    const bool haveG = cellSurface(grid, x_m, y_m, p, g);
    const bool haveL = local && cellSurface(*local, x_m, y_m, p, l);
    if (reliefSigma) {
        if (haveG) addReliefVariance(grid, x_m, y_m, p, g);
        if (haveL) addReliefVariance(*local, x_m, y_m, p, l);
    }
    return combineGrids(haveG, g, haveL, l, out);
}

namespace {
/** heightAt over the cells of `grid` and, if not null, of the local grid. */
bool heightOnGrids(CellPlanesCache& grid, CellPlanesCache* local, double x_m, double y_m,
                   bool reliefSigma, CellSurface& out) {
    CellSurface g, l;
    const bool haveG = planeHeightAt(grid, x_m, y_m, reliefSigma, g);
    const bool haveL = local && planeHeightAt(*local, x_m, y_m, reliefSigma, l);
    return combineGrids(haveG, g, haveL, l, out);
}

/** The exponent of the power of 2 of slot columns for queries spanning `xSpan_m` in x: the
 * span's cells and the 3 more a query reads beyond them, at most the window's width and 4096
 * (12 MB of slots, touched as used; a wider row computes its cells up to 4 times). */
int columnsLog2(const BinGrid& grid, double xSpan_m) {
    const double spanned = xSpan_m / grid.cellSize_m() + 4.0, window = grid.window().nx;
    const double columns = spanned < window ? spanned : window;  // NaN: the window
    int bits = 2;
    while (bits < 12 && double(1 << bits) < columns) bits++;
    return bits;
}
}  // namespace

bool heightAt(const BinGrid& grid, const BinGrid* local, double x_m, double y_m,
              const BinUpdateParams& p, bool reliefSigma, CellSurface& out) {
    CellPlanesCache g(grid, p);  // one query's 4 x 4 cells, in the object
    if (!local) return heightOnGrids(g, nullptr, x_m, y_m, reliefSigma, out);
    CellPlanesCache l(*local, p);
    return heightOnGrids(g, &l, x_m, y_m, reliefSigma, out);
}

struct HeightAtCache::Impl {
    Impl(const BinGrid& grid, const BinGrid* local, const BinUpdateParams& p, double xSpan_m)
        : global(grid, p, columnsLog2(grid, xSpan_m)) {
        if (local) this->local.emplace(*local, p, columnsLog2(*local, xSpan_m));
    }
    CellPlanesCache global;
    std::optional<CellPlanesCache> local;
};

HeightAtCache::HeightAtCache(const BinGrid& grid, const BinGrid* local, const BinUpdateParams& p,
                             double xSpan_m)
    : m_impl(std::make_unique<Impl>(grid, local, p, xSpan_m)) {}

HeightAtCache::~HeightAtCache() = default;

bool HeightAtCache::heightAt(double x_m, double y_m, bool reliefSigma, CellSurface& out) {
    return heightOnGrids(m_impl->global, m_impl->local ? &*m_impl->local : nullptr, x_m, y_m,
                         reliefSigma, out);
}

}  // namespace multibin
