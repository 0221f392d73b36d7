/* Part of the multibin elevation-mapping library.
 * CMultiBinElevationMap: the traversability layers (multibin/traversability/,
 * doc/traversability.md) and what MRPT's planners read of them (an occupancy grid, obstacle
 * points), and the foothold query.
 *
 * The layers are computed when asked for, and only where the map changed since they were last
 * computed: every cell keeps a digest of its bins and its fill; a changed cell changes the
 * sub-cell surface of the cells around it (their planes read their neighbours) and so the layers
 * of every cell whose discs reach them. */
#include <mrpt/maps/COccupancyGridMap2D.h>
#include <mrpt/maps/CSimplePointsMap.h>

#include <cmath>
#include <cstring>

#include "CMultiBinElevationMap_impl.h"
#include "multibin/grid/BinUpdate.h"
#include "multibin/grid/CellSurface.h"
#include "multibin/io/EsriAsciiGrid.h"

using namespace mrpt::maps;
using multibin::traversability::SurfaceSamples;
using multibin::traversability::TraversabilityLayers;
using multibin::traversability::TraversabilityOptions;

namespace {

/** Cells around a changed one whose sub-cell surface it enters (each point's plane blends the
 * four cells around it, and a cell's plane reads its 8 neighbours). */
constexpr int kSurfaceReach_cells = 2;

uint64_t mix(uint64_t h, uint64_t v) {
    h ^= v + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
    return h;
}
uint64_t bitsOf(float v) {
    uint32_t u;
    std::memcpy(&u, &v, sizeof u);
    return u;
}

/** A digest of what the layers read of cell (ix, iy): its bins (heights, variances, certainty,
 * counts) and its filled height. */
uint64_t cellDigest(const multibin::BinGrid& grid, int ix, int iy, float filled_m) {
    uint64_t h = bitsOf(filled_m);
    grid.forEachBin(ix, iy, [&](const multibin::Bin& b) {
        h = mix(h, bitsOf(b.height_m) << 32 | bitsOf(b.variance_m2));
        h = mix(h, bitsOf(b.certainty) << 32 | uint64_t(b.pointCount));
        h = mix(h, uint64_t(uint16_t(b.index)) | bitsOf(b.plane.weight) << 16);
    });
    return h;
}

/** The variance of a surface's points about their weighted least-squares plane beyond what their
 * noise explains [m^2]: each point's weighted squared residual w e^2 is 1 on average for noise
 * alone, so the excess of the weighted residual sum over points - 3, per unit of weight, is the
 * relief inside the cell that its plane does not follow. 0 with fewer than 4 points. */
double reliefVariance_m2(const multibin::PlaneMoments& m, double points) {
    const double a = m.sxx, b = m.sxy, c = m.syy, det = a * c - b * b;
    if (points < 4 || !(m.weight > 0)) return 0;
    double rss = m.szz;
    if (det > 1e-3 * (a + c) * (a + c))
        rss -= ((c * m.sxz - b * m.syz) * m.sxz + (a * m.syz - b * m.sxz) * m.syz) / det;
    return std::max(0.0, rss - (points - 3)) / m.weight;
}

/** The surface samples of cell (col, row) of `s` (absolute cell (ix, iy)): the sub-cell surface
 * at k x k points without the pose part (a common offset no feature sees), else the filled
 * height; and the cell's certain bins beside its surface. */
void sampleCell(const multibin::BinGrid& grid, const multibin::BinGrid* local,
                const multibin::BinUpdateParams& params, double binShare, float filled_m,
                float filledSigma_m, int col, int row, SurfaceSamples& s) {
    const int k = s.perCell;
    const int ix = s.lattice.window.ix0 + col, iy = s.lattice.window.iy0 + row;
    const double cell_m = s.lattice.cellSize_m;
    multibin::CellSurface surface;
    const bool measured = multibin::cellSurface(grid, ix, iy, params, surface);
    const size_t c = s.lattice.index(col, row);
    s.binLow_m[c] = s.binLowSigma_m[c] = s.binHigh_m[c] = s.binHighSigma_m[c] = NAN;
    if (!measured) {
        s.setCell(col, row, filled_m, filledSigma_m);  // NaN where not filled either
        return;
    }
    for (int r = 0; r < k; r++)
        for (int q = 0; q < k; q++) {
            multibin::CellSurface p;
            const double x = (ix + (q + 0.5) / k) * cell_m, y = (iy + (r + 0.5) / k) * cell_m;
            const size_t i = s.sampleIndex(col * k + q, row * k + r);
            const bool ok = multibin::heightAt(grid, local, x, y, params, false, p);
            s.height_m[i] = ok ? float(p.height_m) : NAN;
            s.sigma_m[i] = ok ? float(std::sqrt(p.variance_m2)) : NAN;
        }
    multibin::PlaneMoments merged;
    double points = 0;
    const double minCertainty = binShare * surface.certainty;
    grid.forEachBin(ix, iy, [&](const multibin::Bin& b) {
        const bool inSurface = b.index >= surface.firstBin && b.index <= surface.lastBin;
        if (inSurface) multibin::mergePlaneMoments(merged, b.plane), points += b.pointCount;
        if (!(b.certainty > 0) || inSurface || b.certainty < minCertainty) return;
        const float sigma =
            float(std::sqrt(std::max(double(b.variance_m2), params.varianceFloor_m2)));
        if (!(b.height_m >= s.binLow_m[c])) s.binLow_m[c] = b.height_m, s.binLowSigma_m[c] = sigma;
        if (!(b.height_m <= s.binHigh_m[c]))
            s.binHigh_m[c] = b.height_m, s.binHighSigma_m[c] = sigma;
    });
    s.relief_m2[c] = float(reliefVariance_m2(merged, points));
}

}  // namespace

TraversabilityLayers CMultiBinElevationMap::traversabilityLayers() const {
    prepareForReading();
    const multibin::MapLock::Shared lock(m_impl->lock);
    updateTraversability();
    const std::lock_guard<std::mutex> cacheLock(m_impl->traversability.mutex);
    return m_impl->traversability.layers;
}

void CMultiBinElevationMap::updateTraversability() const {
    prepareForReading();
    const multibin::MapLock::Shared lock(m_impl->lock);
    multibin::TraversabilityCache& cache = m_impl->traversability;
    const std::lock_guard<std::mutex> cacheLock(cache.mutex);
    const TraversabilityOptions& o = traversabilityOptions;
    o.validate();
    const multibin::BinGrid& grid = m_impl->grid;
    const multibin::Lattice lattice = grid.lattice();
    if (lattice.cellCount() > kMaxWholeWindowCells)
        throw std::runtime_error(
            "CMultiBinElevationMap: the traversability layers cover the whole window as one "
            "raster; this map's window of " +
            std::to_string(lattice.nx()) + " x " + std::to_string(lattice.ny()) +
            " cells is beyond the " + std::to_string(kMaxWholeWindowCells) + " cells allowed");
    const bool full = !cache.valid || cache.samples.lattice.cellSize_m != lattice.cellSize_m ||
                      cache.samples.perCell != o.samples_per_cell ||
                      cache.options.text() != o.text() || isDualGrid();
    if (!full && !(cache.samples.lattice == lattice)) {
        // The window moved or grew: what it kept is kept; the new cells' digest (0) differs
        // from any real one, so they and the cells whose discs reach them are computed below.
        SurfaceSamples samples(lattice, o.samples_per_cell);
        samples.copyFrom(cache.samples);
        TraversabilityLayers layers(lattice);
        layers.copyFrom(cache.layers);
        std::vector<uint64_t> signature(lattice.cellCount(), 0);
        const multibin::CellWindow& old = cache.samples.lattice.window;
        for (int row = 0; row < lattice.ny(); row++)
            for (int col = 0; col < lattice.nx(); col++) {
                const int ix = lattice.window.ix0 + col, iy = lattice.window.iy0 + row;
                if (old.contains(ix, iy))
                    signature[lattice.index(col, row)] =
                        cache.signature[cache.samples.lattice.index(ix - old.ix0, iy - old.iy0)];
            }
        cache.samples = std::move(samples);
        cache.layers = std::move(layers);
        cache.signature = std::move(signature);
    }
    if (full) {
        cache.samples = SurfaceSamples(lattice, o.samples_per_cell);
        cache.signature.assign(lattice.cellCount(), 0);
        cache.layers = TraversabilityLayers(lattice);
        cache.options = o;
    }
    // Which cells changed: their digest.
    const multibin::fill::FilledCells& fill = m_impl->filled;
    const multibin::CellWindow& fw = m_impl->fillWindow;
    std::vector<uint8_t> changed(lattice.cellCount(), full ? 1 : 0);
    std::vector<float> filled(lattice.cellCount(), NAN), filledSigma(lattice.cellCount(), NAN);
    bool any = full;
    for (int row = 0; row < lattice.ny(); row++)
        for (int col = 0; col < lattice.nx(); col++) {
            const int ix = lattice.window.ix0 + col, iy = lattice.window.iy0 + row;
            const size_t c = lattice.index(col, row);
            if (fw.contains(ix, iy))
                if (const multibin::fill::FilledCell* f = fill.find(ix, iy))
                    filled[c] = f->height_m, filledSigma[c] = f->sigma_m;
            const uint64_t d = cellDigest(grid, ix, iy, filled[c]);
            if (d != cache.signature[c] || full) changed[c] = 1, any = true;
            cache.signature[c] = d;
        }
    if (any) {
        const std::vector<uint8_t> resample =
            full ? changed
                 : multibin::traversability::dilateMask(changed, lattice.nx(), lattice.ny(),
                                                        kSurfaceReach_cells);
        const multibin::BinUpdateParams params = binUpdateParams();
        const multibin::BinGrid* local = isDualGrid() ? &m_impl->local : nullptr;
        for (int row = 0; row < lattice.ny(); row++)
            for (int col = 0; col < lattice.nx(); col++) {
                const size_t c = lattice.index(col, row);
                if (resample[c])
                    sampleCell(grid, local, params, o.bin_min_certainty_share, filled[c],
                               filledSigma[c], col, row, cache.samples);
            }
        const int reach_cells = int(std::ceil(o.reach_m() / lattice.cellSize_m)) + 1;
        multibin::traversability::computeLayers(
            cache.samples, o, cache.layers,
            full ? std::vector<uint8_t>{}
                 : multibin::traversability::dilateMask(resample, lattice.nx(), lattice.ny(),
                                                        reach_cells));
    }
    cache.valid = true;
}

multibin::EsriAsciiGrid CMultiBinElevationMap::traversabilityRaster(
    TraversabilityLayer layer) const {
    prepareForReading();
    const multibin::MapLock::Shared lock(m_impl->lock);
    const TraversabilityLayers t = traversabilityLayers();
    multibin::EsriAsciiGrid g = multibin::EsriAsciiGrid::onLattice(t.lattice);
    g.xllcenter_m += m_impl->origin_m.x();  // the raster is in the pose frame
    g.yllcenter_m += m_impl->origin_m.y();
    const std::vector<float>& v = layer == TraversabilityLayer::Untraversable ? t.untraversable
                                  : layer == TraversabilityLayer::Step        ? t.step_m
                                  : layer == TraversabilityLayer::Slope       ? t.slope_deg
                                  : layer == TraversabilityLayer::Roughness   ? t.roughness_m
                                                                              : t.foothold;
    for (int r = 0; r < t.lattice.ny(); r++)
        for (int c = 0; c < t.lattice.nx(); c++) g.heights_m(r, c) = v[t.lattice.index(c, r)];
    return g;
}

void CMultiBinElevationMap::getAsOccupancyGrid(mrpt::maps::COccupancyGridMap2D& out) const {
    prepareForReading();
    const multibin::MapLock::Shared lock(m_impl->lock);
    const TraversabilityLayers t = traversabilityLayers();
    const std::vector<double> a = t.lattice.area_m();
    const double cell_m = t.lattice.cellSize_m;
    const Eigen::Vector2d& o = m_impl->origin_m;
    // Half a cell inside the area: MRPT rounds the limits to whole cells.
    out.setSize(float(o.x() + a[0]), float(o.x() + a[1]), float(o.y() + a[2]), float(o.y() + a[3]),
                float(cell_m), 0.5f);
    for (int r = 0; r < t.lattice.ny(); r++)
        for (int c = 0; c < t.lattice.nx(); c++) {
            const size_t k = t.lattice.index(c, r);
            if (!t.known(k)) continue;
            const int cx = out.x2idx(o.x() + t.lattice.cellCenterX_m(c));
            const int cy = out.y2idx(o.y() + t.lattice.cellCenterY_m(r));
            // MRPT's cells hold the probability of being free.
            if (cx >= 0 && cy >= 0 && cx < int(out.getSizeX()) && cy < int(out.getSizeY()))
                out.setCell(cx, cy, 1.0f - t.untraversable[k]);
        }
}

void CMultiBinElevationMap::getUntraversablePoints(mrpt::maps::CSimplePointsMap& points,
                                                   double minProbability) const {
    prepareForReading();
    const multibin::MapLock::Shared lock(m_impl->lock);
    const TraversabilityLayers t = traversabilityLayers();
    const Eigen::Vector2d& o = m_impl->origin_m;
    points.clear();
    for (int r = 0; r < t.lattice.ny(); r++)
        for (int c = 0; c < t.lattice.nx(); c++) {
            const size_t k = t.lattice.index(c, r);
            if (!t.known(k) || !(t.untraversable[k] >= minProbability)) continue;
            const double x = o.x() + t.lattice.cellCenterX_m(c);
            const double y = o.y() + t.lattice.cellCenterY_m(r);
            double z, sigma;
            if (getElevation(x, y, z, sigma) == HeightSource::Unknown) z = 0;
            points.insertPoint(float(x), float(y), float(z));
        }
}

CMultiBinElevationMap::TFoothold CMultiBinElevationMap::bestFoothold(double x_m, double y_m,
                                                                     double searchRadius_m) const {
    prepareForReading();
    const multibin::MapLock::Shared lock(m_impl->lock);
    const TraversabilityLayers t = traversabilityLayers();
    const Eigen::Vector2d& o = m_impl->origin_m;
    TFoothold best;
    double bestD2 = 0;
    for (int r = 0; r < t.lattice.ny(); r++)
        for (int c = 0; c < t.lattice.nx(); c++) {
            const size_t k = t.lattice.index(c, r);
            if (!t.known(k)) continue;
            const double x = o.x() + t.lattice.cellCenterX_m(c);
            const double y = o.y() + t.lattice.cellCenterY_m(r);
            const double d2 = (x - x_m) * (x - x_m) + (y - y_m) * (y - y_m);
            if (d2 > searchRadius_m * searchRadius_m) continue;
            const double p = t.foothold[k];
            if (best.found && (p < best.probability || (p == best.probability && d2 >= bestD2)))
                continue;
            double z, sigma;
            if (getElevation(x, y, z, sigma) == HeightSource::Unknown) continue;
            best = {true, x, y, z, p};
            bestD2 = d2;
        }
    return best;
}
