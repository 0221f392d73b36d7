/* Part of the multibin elevation-mapping library. */
#include "multibin/fill/GapFilling.h"

#include <Eigen/SparseCore>
#include <Eigen/SparseLU>

#include "multibin/fill/Kriging.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

namespace multibin::fill {

namespace {
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
}

// ---------------------------------------------------------------------------------------------
// HeightRaster
// ---------------------------------------------------------------------------------------------
HeightRaster::HeightRaster(int nx_, int ny_, double cellSize)
    : nx(nx_),
      ny(ny_),
      cellSize_m(cellSize),
      height_m(size_t(std::max(nx_, 0)) * size_t(std::max(ny_, 0)), kNaN),
      sigma_m(height_m.size(), kNaN),
      certainty(height_m.size(), 0.0f) {}

bool HeightRaster::isMeasured(size_t k) const {
    return certainty[k] > 0 && std::isfinite(height_m[k]) && std::isfinite(sigma_m[k]) &&
           sigma_m[k] > 0;
}

void HeightRaster::setMeasured(int ix, int iy, float h, float s, float c) {
    const size_t k = index(ix, iy);
    height_m[k] = h;
    sigma_m[k] = s;
    certainty[k] = c > 0 ? c : 1.0f;
}

void HeightRaster::setUnknown(int ix, int iy) {
    const size_t k = index(ix, iy);
    height_m[k] = kNaN;
    sigma_m[k] = kNaN;
    certainty[k] = 0;
}

void HeightRaster::validate() const {
    auto bad = [](const std::string& field, const std::string& what) {
        throw std::invalid_argument("HeightRaster." + field + ": " + what);
    };
    if (nx < 0 || ny < 0) bad("nx/ny", "must be >= 0");
    if (!(cellSize_m > 0) || !std::isfinite(cellSize_m)) bad("cellSize_m", "must be positive [m]");
    const size_t n = size();
    if (height_m.size() != n)
        bad("height_m", "has " + std::to_string(height_m.size()) +
                            " values, expected nx * ny = " + std::to_string(n));
    if (sigma_m.size() != n) bad("sigma_m", "size differs from nx * ny");
    if (certainty.size() != n) bad("certainty", "size differs from nx * ny");
}

// ---------------------------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------------------------
double medianSkeletonWeight(int di, int dj) { return std::sqrt(double(di * di + dj * dj)); }

std::vector<int> labelGaps(const HeightRaster& r, std::vector<int>& sizes) {
    std::vector<int> label(r.size(), -1);
    sizes.clear();
    std::vector<int> stack;
    for (int iy = 0; iy < r.ny; iy++)
        for (int ix = 0; ix < r.nx; ix++) {
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
                const int x = k % r.nx, y = k / r.nx;
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

std::vector<double> semivariogram(const HeightRaster& r, int x0, int y0, int w, int h, int maxLag) {
    const int xa = std::max(x0, 0), ya = std::max(y0, 0);
    const int xb = std::min(x0 + w, r.nx), yb = std::min(y0 + h, r.ny);
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

namespace {

/** Weighted-median filling of single cells; `usable` tells which cells count as data. */
class MedianFiller {
public:
    MedianFiller(const HeightRaster& r, const FillOptions& o) : m_r(r), m_o(o) {
        const int half = o.medianWindow_cells / 2;
        for (int dj = -half; dj <= half; dj++)
            for (int di = -half; di <= half; di++)
                if (di || dj)
                    m_offsets.push_back(
                        {di, dj, dj * std::ptrdiff_t(r.nx) + di, medianSkeletonWeight(di, dj)});
        m_half = half;
    }

    /** Fills cell (ix, iy) of `out` from the cells of `out` flagged in `usable`; false (and the
     * cell untouched) if the window holds fewer than medianMinKnown of them. */
    bool fillCell(int ix, int iy, FillResult& out, const std::vector<char>& usable) {
        m_vals.clear();
        double wSum = 0;
        // Away from the border the whole window is inside: no per-neighbour bounds check.
        const bool interior =
            ix >= m_half && iy >= m_half && ix < m_r.nx - m_half && iy < m_r.ny - m_half;
        const std::ptrdiff_t centre = std::ptrdiff_t(m_r.index(ix, iy));
        for (const auto& o : m_offsets) {
            if (!interior && !m_r.inside(ix + o.di, iy + o.dj)) continue;
            const size_t k = size_t(centre + o.linear);
            if (!usable[k]) continue;
            // Insertion into a sorted list: at most window^2 - 1 values, cheaper than a sort.
            const Sample v{out.height_m[k], out.sigma_m[k], float(o.w)};
            size_t at = m_vals.size();
            m_vals.push_back(v);
            while (at > 0 && m_vals[at - 1].h > v.h) {
                m_vals[at] = m_vals[at - 1];
                at--;
            }
            m_vals[at] = v;
            wSum += o.w;
        }
        if (int(m_vals.size()) < m_o.medianMinKnown) return false;
        double acc = 0, med = m_vals.back().h;
        for (const auto& s : m_vals) {
            acc += s.w;
            if (acc >= 0.5 * wSum) {
                med = s.h;
                break;
            }
        }
        double sigma;
        if (m_o.sigmaModel == FillSigmaModel::Paper) {
            double ws = 0;
            for (const auto& s : m_vals) ws += s.w * s.s;
            sigma = ws / wSum;
        } else {
            // Neighbour noise plus the local spread of heights about the median: a cell on a
            // step edge gets a large sigma, one on a flat plate stays near the sensor noise.
            double var = 0, spread = 0;
            for (const auto& s : m_vals) {
                var += s.w * s.s * s.s;
                spread += s.w * (s.h - med) * (s.h - med);
            }
            var /= wSum;
            spread /= wSum;
            sigma = std::sqrt(var + m_o.medianSigmaGain * m_o.medianSigmaGain * spread);
            sigma = std::max(sigma, m_o.sigmaFloor_m);
        }
        const size_t k = m_r.index(ix, iy);
        out.height_m[k] = float(med);
        out.sigma_m[k] = float(sigma);
        out.source[k] = FillSource::Median;
        return true;
    }

    /** Fills `cells` pass after pass, each pass using the cells filled by earlier passes; returns
     * how many were filled. */
    int fillRepeated(const std::vector<int>& cells, FillResult& out, std::vector<char>& usable) {
        std::vector<int> todo = cells, next, filledNow;
        int filled = 0;
        while (!todo.empty()) {
            next.clear();
            filledNow.clear();
            for (int k : todo) {
                if (fillCell(k % m_r.nx, k / m_r.nx, out, usable))
                    filledNow.push_back(k);
                else
                    next.push_back(k);
            }
            if (filledNow.empty()) break;
            for (int k : filledNow) usable[size_t(k)] = 1;  // data for the next pass only
            filled += int(filledNow.size());
            todo.swap(next);
        }
        return filled;
    }

private:
    struct Offset {
        int di, dj;
        std::ptrdiff_t linear;  // di + dj * nx
        double w;
    };
    int m_half = 2;
    struct Sample {
        float h, s, w;  // height [m], sigma [m], skeleton weight [cells]
    };
    const HeightRaster& m_r;
    const FillOptions& m_o;
    std::vector<Offset> m_offsets;
    std::vector<Sample> m_vals;
};

FillResult initResult(const HeightRaster& r, std::vector<char>& measured) {
    FillResult out;
    out.nx = r.nx;
    out.ny = r.ny;
    out.height_m.assign(r.size(), kNaN);
    out.sigma_m.assign(r.size(), kNaN);
    out.source.assign(r.size(), FillSource::Unfilled);
    measured.assign(r.size(), 0);
    for (size_t k = 0; k < r.size(); k++)
        if (r.isMeasured(k)) {
            measured[k] = 1;
            out.height_m[k] = r.height_m[k];
            out.sigma_m[k] = r.sigma_m[k];
            out.source[k] = FillSource::Measured;
        }
    return out;
}

void countSources(FillResult& out) {
    auto& s = out.stats;
    s.measured = s.median = s.gaussian = s.unfilled = 0;
    for (auto src : out.source) switch (src) {
            case FillSource::Measured:
                s.measured++;
                break;
            case FillSource::Median:
                s.median++;
                break;
            case FillSource::Gaussian:
                s.gaussian++;
                break;
            default:
                s.unfilled++;
        }
}

/** The residual h - g of the measured cells around a gap, carried into the gap as a harmonic
 * function (Laplace equation, Dirichlet data on the rim, solved by over-relaxed Gauss-Seidel):
 * the filled surface then meets every rim cell instead of passing near it. Returns one value
 * per gap cell [m]. */
std::vector<double> harmonicResiduals(const HeightRaster& r, const GaussianSurface& g,
                                      const std::vector<int>& cells, int sx, int sy, int ex,
                                      int ey) {
    const int w = ex - sx, h = ey - sy;
    // 0 = not used, 1 = measured (fixed residual), 2 = gap cell (unknown).
    std::vector<char> kind(size_t(w) * size_t(h), 0);
    std::vector<double> res(kind.size(), 0.0);
    auto at = [&](int ix, int iy) { return size_t(iy - sy) * size_t(w) + size_t(ix - sx); };
    for (int iy = sy; iy < ey; iy++)
        for (int ix = sx; ix < ex; ix++) {
            const size_t k = r.index(ix, iy);
            if (!r.isMeasured(k)) continue;
            kind[at(ix, iy)] = 1;
            res[at(ix, iy)] = r.height_m[k] - g(ix - sx, iy - sy);
        }
    for (int k : cells) {
        // A held-out measured cell starts from 0 like the others: its own residual must not
        // leak into the solution if the iteration stops early.
        kind[at(k % r.nx, k / r.nx)] = 2;
        res[at(k % r.nx, k / r.nx)] = 0;
    }
    constexpr double kOmega = 1.8;         // over-relaxation factor
    constexpr double kTolerance_m = 1e-5;  // well below any sensor noise
    for (int it = 0; it < 2000; it++) {
        double maxStep = 0;
        for (int k : cells) {
            const int ix = k % r.nx, iy = k / r.nx;
            double sum = 0;
            int n = 0;
            const int nb[4][2] = {{ix - 1, iy}, {ix + 1, iy}, {ix, iy - 1}, {ix, iy + 1}};
            for (const auto& p : nb) {
                if (p[0] < sx || p[1] < sy || p[0] >= ex || p[1] >= ey) continue;
                const size_t kk = at(p[0], p[1]);
                if (kind[kk]) sum += res[kk], n++;
            }
            if (!n) continue;
            double& v = res[at(ix, iy)];
            const double step = kOmega * (sum / n - v);
            v += step;
            maxStep = std::max(maxStep, std::abs(step));
        }
        if (maxStep < kTolerance_m) break;
    }
    std::vector<double> out(cells.size());
    for (size_t c = 0; c < cells.size(); c++) out[c] = res[at(cells[c] % r.nx, cells[c] / r.nx)];
    return out;
}

/** The residual h - g of the measured cells around a gap, carried into the gap as a biharmonic
 * function (thin-plate equation: the 13-point stencil of the squared Laplacian set to zero at
 * every gap cell, the two rings of measured cells around it as boundary data), solved directly
 * (sparse LU). A gap cell whose stencil reaches a cell that is neither measured nor in the gap
 * (raster edge, another gap) takes the harmonic equation over its measured or gap neighbours.
 * Returns one value per gap cell [m]. */
std::vector<double> biharmonicResiduals(const HeightRaster& r, const GaussianSurface& g,
                                        const std::vector<int>& cells, int sx, int sy) {
    std::vector<int> unknown(r.size(), -1);
    for (size_t c = 0; c < cells.size(); c++) unknown[size_t(cells[c])] = int(c);
    auto known = [&](int ix, int iy) { return r.inside(ix, iy) && r.isMeasured(r.index(ix, iy)); };
    auto residual = [&](int ix, int iy) {
        return r.height_m[r.index(ix, iy)] - g(ix - sx, iy - sy);
    };
    struct Tap {
        int di, dj;
        double w;
    };
    static const Tap bi[] = {{0, 0, 20}, {1, 0, -8}, {-1, 0, -8}, {0, 1, -8},  {0, -1, -8},
                             {1, 1, 2},  {1, -1, 2}, {-1, 1, 2},  {-1, -1, 2}, {2, 0, 1},
                             {-2, 0, 1}, {0, 2, 1},  {0, -2, 1}};
    static const Tap lap[] = {{0, 0, 4}, {1, 0, -1}, {-1, 0, -1}, {0, 1, -1}, {0, -1, -1}};
    const int n = int(cells.size());
    std::vector<Eigen::Triplet<double>> trip;
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n);
    for (int c = 0; c < n; c++) {
        const int ix = cells[size_t(c)] % r.nx, iy = cells[size_t(c)] / r.nx;
        bool full = true;
        for (const auto& t : bi) {
            const int x = ix + t.di, y = iy + t.dj;
            if (!(r.inside(x, y) && (unknown[r.index(x, y)] >= 0 || known(x, y)))) full = false;
        }
        if (full) {
            for (const auto& t : bi) {
                const int x = ix + t.di, y = iy + t.dj;
                const int u = unknown[r.index(x, y)];
                if (u >= 0)
                    trip.emplace_back(c, u, t.w);
                else
                    rhs[c] -= t.w * residual(x, y);
            }
        } else {
            double diag = 0;
            for (const auto& t : lap) {
                if (!t.di && !t.dj) continue;
                const int x = ix + t.di, y = iy + t.dj;
                if (!r.inside(x, y)) continue;
                const int u = unknown[r.index(x, y)];
                if (u >= 0)
                    trip.emplace_back(c, u, -1.0), diag += 1;
                else if (known(x, y))
                    rhs[c] += residual(x, y), diag += 1;
            }
            trip.emplace_back(c, c, std::max(diag, 1.0));
        }
    }
    Eigen::SparseMatrix<double> A(n, n);
    A.setFromTriplets(trip.begin(), trip.end());
    Eigen::SparseLU<Eigen::SparseMatrix<double>> lu(A);
    std::vector<double> out(size_t(n), 0.0);
    if (lu.info() != Eigen::Success) return out;
    const Eigen::VectorXd x = lu.solve(rhs);
    for (int c = 0; c < n; c++) out[size_t(c)] = x[c];
    return out;
}

/** The training points nearest a gap: `cand` sorted by distance to the gap, cut to `count`.
 * Where the cut falls inside a ring (more points at the cut-off distance than places left),
 * the places go to points evenly spread by angle about the gap's centre (ci, cj), so the kept
 * points still surround the gap: the raster order would keep one side of a long rim only. */
template <class Cand>
void keepNearestToGap(std::vector<Cand>& cand, size_t count, double ci, double cj) {
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

/** Moving-neighbourhood kriging: the gap cells are cut into tiles of kTile x kTile cells, each
 * kriged from its own `k` training points nearest the tile (distance to the tile's box), under
 * each weighted model's trend shapes and covariance (the amplitudes re-estimated by GLS on the
 * tile's points, as a local universal kriging does). Fills models[q].mean_m / var_m2. */
template <class Model>
void krigeByTiles(const std::vector<double>& ci, const std::vector<double>& cj,
                  const std::vector<SurfaceSample>& samples, int k, double prior,
                  std::vector<Model>& models, const std::vector<double>& w) {
    // 8 x 8 cells: 64 predictions per factorisation, and a tile's far cells stay within a few
    // cells of the points nearest its box.
    constexpr int kTile = 8;
    for (size_t q = 0; q < models.size(); q++)
        if (w[q] > 0)
            models[q].mean_m.assign(ci.size(), 0.0), models[q].var_m2.assign(ci.size(), 0.0);
    std::vector<std::pair<long long, size_t>> byTile(ci.size());
    for (size_t c = 0; c < ci.size(); c++) {
        const long long ti = (long long)std::floor(ci[c] / kTile),
                        tj = (long long)std::floor(cj[c] / kTile);
        byTile[c] = {tj * 1000003LL + ti, c};
    }
    std::sort(byTile.begin(), byTile.end());
    std::vector<std::pair<double, size_t>> dist(samples.size());
    std::vector<SurfaceSample> local;
    std::vector<double> ti, tj, mean, var;
    for (size_t a = 0; a < byTile.size();) {
        size_t b = a;
        while (b < byTile.size() && byTile[b].first == byTile[a].first) b++;
        double i0 = ci[byTile[a].second], i1 = i0, j0 = cj[byTile[a].second], j1 = j0;
        ti.clear(), tj.clear();
        for (size_t t = a; t < b; t++) {
            const size_t c = byTile[t].second;
            i0 = std::min(i0, ci[c]), i1 = std::max(i1, ci[c]);
            j0 = std::min(j0, cj[c]), j1 = std::max(j1, cj[c]);
            ti.push_back(ci[c]), tj.push_back(cj[c]);
        }
        for (size_t s = 0; s < samples.size(); s++) {
            const double di = std::max({i0 - samples[s].i, samples[s].i - i1, 0.0});
            const double dj = std::max({j0 - samples[s].j, samples[s].j - j1, 0.0});
            dist[s] = {di * di + dj * dj, s};
        }
        const size_t n = std::min(samples.size(), size_t(k));
        if (n == 0) throw std::runtime_error("krigeByTiles: no samples");
        std::nth_element(dist.begin(), dist.begin() + std::ptrdiff_t(n - 1), dist.end());
        local.clear();
        for (size_t s = 0; s < n; s++) local.push_back(samples[dist[s].second]);
        for (size_t q = 0; q < models.size(); q++) {
            if (!(w[q] > 0)) continue;
            const UniversalKriging uk(local, models[q].shapes, models[q].cov, prior);
            uk.predict(ti, tj, mean, var);
            for (size_t t = a; t < b; t++) {
                models[q].mean_m[byTile[t].second] = mean[t - a];
                models[q].var_m2[byTile[t].second] = var[t - a];
            }
        }
        a = b;
    }
}

/** The kriging path of fillWithGaussianSurface (ResidualModel::Kriging): eq 16 fitted for
 * m = 0, 1, ... as usual (seeded swarm, iid Mahalanobis fitness), each fit then taken as the
 * trend of a universal kriging whose residual covariance is fitted to the semivariogram of its
 * residuals; m grows while the criterion (AICc or BIC) on the kriging likelihood improves. The
 * gap gets the kriged heights of the best m, or their Akaike-weighted mean (modelAveraging),
 * and sigma from the kriging variance (plus, when averaging, the models' spread). */
void fillByKriging(const HeightRaster& r, const FillOptions& o,
                   const GaussianFitOptions& fitOptions, const std::vector<int>& cells,
                   const std::vector<SurfaceSample>& samples,
                   const std::vector<SurfaceSample>& near, const std::vector<SurfaceSample>* moving,
                   const std::vector<SurfaceSample>& rim,
                   const std::vector<SurfaceSample>& beyondRim, const GaussianSurface* alternative,
                   int side, int sx, int sy, FillResult& out) {
    const int n = int(samples.size());
    const double prior = amplitudePriorPrecision(samples);
    double sensorVar = 0, hLo = samples[0].h_m, hHi = hLo, meanSigma = 0;
    for (const auto& s : samples) {
        sensorVar += s.sigma_m * s.sigma_m;
        meanSigma += s.sigma_m;
        hLo = std::min(hLo, s.h_m), hHi = std::max(hHi, s.h_m);
    }
    sensorVar /= n;
    meanSigma /= n;
    std::vector<double> ci(cells.size()), cj(cells.size());
    for (size_t c = 0; c < cells.size(); c++)
        ci[c] = cells[c] % r.nx - sx, cj[c] = cells[c] / r.nx - sy;

    struct Model {
        double criterion;
        int m;
        GaussianSurface shapes;  // the swarm's fit; the kriging re-estimates its amplitudes
        Covariance cov;
        std::unique_ptr<UniversalKriging> kriging;
        std::vector<double> mean_m, var_m2;
    };
    std::vector<Model> models;
    std::vector<double> grid(size_t(side) * size_t(side));
    const int maxLag = std::max(1, side / 2);
    auto covarianceOf = [&](const GaussianSurface& g) {
        std::fill(grid.begin(), grid.end(), std::numeric_limits<double>::quiet_NaN());
        for (const auto& s : samples)
            grid[size_t(s.j) * size_t(side) + size_t(s.i)] = s.h_m - g(s.i, s.j);
        std::vector<double> pairs;
        const auto gamma = gridSemivariogram(grid, side, side, maxLag, &pairs);
        return fitCovariance(gamma, pairs, sensorVar, o.krigingCovariance, side);
    };
    auto criterion = [&](const UniversalKriging& uk, const GaussianSurface& g) {
        const int k = g.parameters() + 3;  // eq 16's, plus sill, range and nugget
        const int nk = int(near.size());   // the likelihood is that of the neighbourhood
        const double penalty = o.criterion == ModelCriterion::BIC
                                   ? k * std::log(double(nk))
                                   : (nk > k + 1 ? 2.0 * k + 2.0 * k * (k + 1.0) / (nk - k - 1.0)
                                                 : std::numeric_limits<double>::infinity());
        return uk.minusTwoLogLikelihood() + penalty;
    };
    auto evaluate = [&](const GaussianSurface& g, const Covariance& cov) {
        auto uk = std::make_unique<UniversalKriging>(near, g, cov, prior);
        const double c = criterion(*uk, g);
        models.push_back(Model{c, int(g.terms.size()), g, cov, std::move(uk), {}, {}});
    };
    GaussianSurface prev = fitGaussianSurfaceFixed(samples, side, 0, fitOptions);
    size_t best = 0;
    evaluate(prev, covarianceOf(prev));
    for (int m = 1; m <= o.maxTerms && n > 2 + 5 * m + 3; m++) {
        const GaussianSurface g = fitGaussianSurfaceFixed(samples, side, m, fitOptions, &prev);
        evaluate(g, covarianceOf(g));
        // Forward selection as in the paper's search: stop at the first m that does not improve
        // the criterion. Each m is a whole model, trend plus its own covariance. Measured on the
        // seed-1 / seed-2 placements (doc/gap-filling.md; kriging on all training points, centres
        // anywhere): searching every m up to maxTerms gave
        // 17.8 / 18.3 mm instead of 16.5 / 17.1 mm (and twice the time); judging m against m - 1
        // under the covariance of m's residuals (a nested test) counts known Gaussians better but
        // gave 17.4 / 18.5 mm.
        if (!(models.back().criterion < models[best].criterion)) break;
        best = models.size() - 1;
        prev = g;
    }
    std::vector<double> w(models.size(), 0.0);
    if (o.modelAveraging) {
        // Akaike weights; a model more than 20 below the best (weight < 5e-5) is not predicted.
        double sw = 0;
        for (size_t q = 0; q < models.size(); q++) {
            const double d = models[q].criterion - models[best].criterion;
            sw += w[q] = d < 20 ? std::exp(-0.5 * d) : 0.0;
        }
        for (auto& v : w) v /= sw;
    } else {
        w[best] = 1;
    }
    if (!moving) {
        for (size_t q = 0; q < models.size(); q++)
            if (w[q] > 0) models[q].kriging->predict(ci, cj, models[q].mean_m, models[q].var_m2);
    } else {
        krigeByTiles(ci, cj, *moving, o.krigingMaxPoints, prior, models, w);
        out.stats.movingNeighbourhoods++;
    }
    out.stats.supportAreas++;
    out.stats.termsChosen.push_back(models[best].m);
    const double slack = o.extrapolationMargin * (hHi - hLo);
    std::vector<double> harmonic;  // the gap's heights by harmonic residuals, if they won
    if (alternative && rim.size() >= 4 && beyondRim.size() >= 12) {
        // Rim check: hide the two rings of measured cells around the gap and predict them as the
        // gap would be filled, by this kriging (best m, moving neighbourhoods from the cells
        // beyond the rings) and by the alternative (eq 16 by AIC on independent residuals plus
        // harmonic rim residuals); the gap takes the method that predicted its rim better.
        struct One {
            GaussianSurface shapes;
            Covariance cov;
            std::vector<double> mean_m, var_m2;
        };
        std::vector<One> one{{models[best].shapes, models[best].cov, {}, {}}};
        std::vector<double> ri, rj;
        std::vector<int> both = cells;
        for (const auto& s : rim) {
            ri.push_back(s.i), rj.push_back(s.j);
            both.push_back(int(r.index(sx + s.i, sy + s.j)));
        }
        krigeByTiles(ri, rj, beyondRim, o.krigingMaxPoints, prior, one, {1.0});
        const int ex = std::min(sx + side, r.nx), ey = std::min(sy + side, r.ny);
        const auto hr = harmonicResiduals(r, *alternative, both, sx, sy, ex, ey);
        double ek = 0, eh = 0;
        for (size_t k = 0; k < rim.size(); k++) {
            const double dh =
                rim[k].h_m - ((*alternative)(rim[k].i, rim[k].j) + hr[cells.size() + k]);
            const double dk = rim[k].h_m - one[0].mean_m[k];
            eh += dh * dh, ek += dk * dk;
        }
        if (eh < ek) {
            const auto hg = harmonicResiduals(r, *alternative, cells, sx, sy, ex, ey);
            harmonic.resize(cells.size());
            for (size_t c = 0; c < cells.size(); c++)
                harmonic[c] = (*alternative)(ci[c], cj[c]) + hg[c];
            out.stats.rimCheckHarmonic++;
        }
    }
    for (size_t c = 0; c < cells.size(); c++) {
        double mean = 0, var = 0;
        for (size_t q = 0; q < models.size(); q++)
            if (w[q] > 0) mean += w[q] * models[q].mean_m[c];
        for (size_t q = 0; q < models.size(); q++) {
            if (!(w[q] > 0)) continue;
            const double d = models[q].mean_m[c] - mean;
            var += w[q] * (models[q].var_m2[c] + d * d);
        }
        double sigma = meanSigma;
        if (o.sigmaModel == FillSigmaModel::Calibrated)
            sigma = std::max(o.gaussianSigmaGain * std::sqrt(var), o.sigmaFloor_m);
        const size_t k = size_t(cells[c]);
        if (!harmonic.empty()) mean = harmonic[c];
        out.height_m[k] = float(std::clamp(mean, hLo - slack, hHi + slack));
        out.sigma_m[k] = float(sigma);
        out.source[k] = FillSource::Gaussian;
    }
}

/** Fits eq 16 on the square support area around one gap and fills its cells; false if the area
 * holds too little data (the caller then falls back to the repeated median). */
bool fillWithGaussianSurface(const HeightRaster& r, const FillOptions& o,
                             const std::vector<int>& cells, FillResult& out) {
    int x0 = r.nx, x1 = -1, y0 = r.ny, y1 = -1;
    for (int k : cells) {
        const int x = k % r.nx, y = k / r.nx;
        x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
    }
    const int side = std::max(x1 - x0 + 1, y1 - y0 + 1) + 2 * o.supportMargin_cells;
    // Centre the square on the gap, then slide it inside the raster where it fits.
    auto place = [&](int lo, int hi, int n) {
        int start = (lo + hi + 1) / 2 - side / 2;
        start = std::min(start, n - side);
        return std::max(start, 0);
    };
    const int sx = place(x0, x1, r.nx), sy = place(y0, y1, r.ny);
    const int ex = std::min(sx + side, r.nx), ey = std::min(sy + side, r.ny);

    // Training points: measured cells of the area, the ones nearest the gap first if capped.
    // Distance to the gap itself (multi-source breadth-first search, 8-neighbour steps), not to
    // its bounding box: for a long or L-shaped gap the box says little.
    const int bw = ex - sx, bh = ey - sy;
    std::vector<int> gapDist(size_t(bw) * size_t(bh), -1);
    std::vector<int> queue;
    queue.reserve(gapDist.size());
    for (int k : cells) {
        const size_t b = size_t(k / r.nx - sy) * size_t(bw) + size_t(k % r.nx - sx);
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
    struct Cand {
        SurfaceSample s;
        int gapDist;
    };
    std::vector<Cand> cand;
    for (int iy = sy; iy < ey; iy++)
        for (int ix = sx; ix < ex; ix++) {
            const size_t k = r.index(ix, iy);
            if (!r.isMeasured(k)) continue;
            cand.push_back({SurfaceSample{ix - sx, iy - sy, r.height_m[k], r.sigma_m[k]},
                            gapDist[size_t(iy - sy) * size_t(bw) + size_t(ix - sx)]});
        }
    std::vector<SurfaceSample> all;  // every measured cell of the area: the moving neighbourhoods
    std::vector<SurfaceSample> rim, beyondRim;  // within 2 cells of the gap, and the others
    for (const auto& c : cand) {
        all.push_back(c.s);
        (c.gapDist <= 2 ? rim : beyondRim).push_back(c.s);
    }
    const size_t rimCells = rim.size();
    const double gi = 0.5 * (x0 + x1) - sx, gj = 0.5 * (y0 + y1) - sy;  // gap centre
    keepNearestToGap(cand, size_t(o.maxTrainingPoints), gi, gj);
    // Fewer than this and even m = 1 cannot be judged by the criterion.
    if (cand.size() < 12) return false;
    std::vector<SurfaceSample> samples;
    samples.reserve(cand.size());
    for (const auto& c : cand) samples.push_back(c.s);

    GaussianFitOptions fitOptions = o.gaussianFitOptions();
    if (o.termsOutsideGap) {
        // Centres on the rim cells or beyond: the gap's bounding box widened by half a cell.
        fitOptions.excludeI0 = x0 - sx - 0.5, fitOptions.excludeI1 = x1 - sx + 0.5;
        fitOptions.excludeJ0 = y0 - sy - 0.5, fitOptions.excludeJ1 = y1 - sy + 0.5;
    }
    if (o.residualCorrection && o.residualModel == ResidualModel::Kriging &&
        o.criterion != ModelCriterion::Holdout) {
        // The kriging neighbourhood: the training points nearest the gap (its cost is cubic).
        // Its likelihood (the choice of m) is that of these points.
        std::vector<Cand> nearCand = cand;
        keepNearestToGap(nearCand, size_t(o.krigingMaxPoints), gi, gj);
        std::vector<SurfaceSample> near;
        for (const auto& c : nearCand) near.push_back(c.s);
        // One neighbourhood for the whole gap only if it holds the two rings of measured cells
        // around it; otherwise (a long shadow, a sprawling gap) part of the gap would be
        // extrapolated from one side of its rim: krige each tile from its own nearest points.
        const bool moving =
            o.krigingNeighbourhood == KrigingNeighbourhood::Moving ||
            (o.krigingNeighbourhood == KrigingNeighbourhood::Auto && rimCells > near.size());
        // A gap too long or sprawling for one neighbourhood: the rim check against eq 16 by
        // AIC with harmonic rim residuals (see fillByKriging).
        GaussianSurface alternative;
        if (moving && o.movingRimCheck) alternative = fitGaussianSurface(samples, side, fitOptions);
        try {
            fillByKriging(r, o, fitOptions, cells, samples, near, moving ? &all : nullptr, rim,
                          beyondRim, moving && o.movingRimCheck ? &alternative : nullptr, side, sx,
                          sy, out);
            return true;
        } catch (const std::runtime_error&) {
            // K not positive definite (not seen; K has every sample's sensor variance on its
            // diagonal): fill this gap by the harmonic path below instead of failing the map.
        }
    }
    GaussianSurface g;
    if (o.criterion == ModelCriterion::Holdout) {
        // Hide the two rings of measured cells nearest the gap, fit on the rest, fill the
        // hidden cells as the gap would be filled, and keep the m that predicts them best.
        std::vector<SurfaceSample> fitSet, heldOut;
        std::vector<int> hidden = cells;
        for (const auto& c : cand)
            if (c.gapDist <= 2) {
                heldOut.push_back(c.s);
                hidden.push_back(int(r.index(sx + c.s.i, sy + c.s.j)));
            } else {
                fitSet.push_back(c.s);
            }
        if (fitSet.size() >= 12 && heldOut.size() >= 4) {
            auto heldOutError = [&](const GaussianSurface& s) {
                const auto res = o.residualCorrection
                                     ? harmonicResiduals(r, s, hidden, sx, sy, ex, ey)
                                     : std::vector<double>(hidden.size(), 0.0);
                double e = 0;
                for (size_t h = 0; h < heldOut.size(); h++) {
                    const auto& v = heldOut[h];
                    const double d = v.h_m - (s(v.i, v.j) + res[cells.size() + h]);
                    e += d * d / (v.sigma_m * v.sigma_m);
                }
                return e;
            };
            GaussianSurface prev = fitGaussianSurfaceFixed(fitSet, side, 0, fitOptions);
            double bestErr = heldOutError(prev);
            int bestM = 0;
            GaussianSurface bestFit = prev;
            for (int m = 1; m <= o.maxTerms && int(fitSet.size()) > 2 + 5 * m; m++) {
                GaussianSurface trial = fitGaussianSurfaceFixed(fitSet, side, m, fitOptions, &prev);
                const double err = heldOutError(trial);
                if (!(err < bestErr)) break;
                bestErr = err, bestM = m, bestFit = trial, prev = trial;
            }
            // Refit on every training point with the chosen size, starting from the held-out
            // fit's terms (m - 1 of them seed the swarm; the LM polish does the rest).
            GaussianSurface seed = bestFit;
            if (bestM > 0) seed.terms.pop_back();
            g = fitGaussianSurfaceFixed(samples, side, bestM, fitOptions,
                                        bestM > 0 ? &seed : nullptr);
        } else {
            g = fitGaussianSurface(samples, side, fitOptions);  // too little data: AICc
        }
    } else {
        g = fitGaussianSurface(samples, side, fitOptions);
    }
    // The surface never leaves the heights of its data by more than extrapolationMargin times
    // their range: far from the rim the model extrapolates, and the data say little there.
    double hLo = samples[0].h_m, hHi = hLo;
    for (const auto& s : samples) hLo = std::min(hLo, s.h_m), hHi = std::max(hHi, s.h_m);
    const double slack = o.extrapolationMargin * (hHi - hLo);
    out.stats.supportAreas++;
    out.stats.termsChosen.push_back(int(g.terms.size()));

    // Distance of each gap cell to the nearest training point [cells].
    std::vector<double> dist(cells.size(), std::numeric_limits<double>::infinity());
    double maxDist = 1;
    for (size_t c = 0; c < cells.size(); c++) {
        const int i = cells[c] % r.nx - sx, j = cells[c] / r.nx - sy;
        int best = std::numeric_limits<int>::max();
        for (const auto& s : samples)
            best = std::min(best, (s.i - i) * (s.i - i) + (s.j - j) * (s.j - j));
        dist[c] = std::sqrt(double(best));
        maxDist = std::max(maxDist, dist[c]);
    }
    const int maxLag = std::min(int(std::ceil(maxDist)) + 1, std::max(side - 1, 1));
    std::vector<double> gamma;
    double meanSigma = 0;
    if (o.sigmaModel == FillSigmaModel::Calibrated)
        gamma = semivariogram(r, sx, sy, side, side, maxLag);
    else {
        for (const auto& s : samples) meanSigma += s.sigma_m;
        meanSigma /= double(samples.size());
    }
    const std::vector<double> resid = !o.residualCorrection ? std::vector<double>(cells.size(), 0.0)
                                      : o.residualModel == ResidualModel::Biharmonic
                                          ? biharmonicResiduals(r, g, cells, sx, sy)
                                          : harmonicResiduals(r, g, cells, sx, sy, ex, ey);
    for (size_t c = 0; c < cells.size(); c++) {
        const int ix = cells[c] % r.nx, iy = cells[c] / r.nx;
        const double h = std::clamp(g(ix - sx, iy - sy) + resid[c], hLo - slack, hHi + slack);
        double sigma = meanSigma;
        if (o.sigmaModel == FillSigmaModel::Calibrated) {
            // Interpolated semivariogram at the distance to the data (flat beyond maxLag).
            const double d = std::min(dist[c], double(maxLag));
            const int l = std::min(int(d), maxLag - 1);
            const double t = d - l;
            const double gam = (1 - t) * gamma[size_t(l)] + t * gamma[size_t(l) + 1];
            sigma = std::sqrt(g.rmsResidual_m * g.rmsResidual_m +
                              o.gaussianSigmaGain * o.gaussianSigmaGain * 2.0 * gam);
            sigma = std::max(sigma, o.sigmaFloor_m);
        }
        const size_t k = size_t(cells[c]);
        out.height_m[k] = float(h);
        out.sigma_m[k] = float(sigma);
        out.source[k] = FillSource::Gaussian;
    }
    return true;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Public entry points
// ---------------------------------------------------------------------------------------------
FillResult weightedMedianFill(const HeightRaster& r, const FillOptions& o, bool repeat) {
    r.validate();
    o.validate();
    std::vector<char> usable;
    FillResult out = initResult(r, usable);
    MedianFiller median(r, o);
    std::vector<int> gaps;
    for (size_t k = 0; k < r.size(); k++)
        if (!usable[k]) gaps.push_back(int(k));
    if (repeat)
        median.fillRepeated(gaps, out, usable);
    else
        for (int k : gaps) median.fillCell(k % r.nx, k / r.nx, out, usable);
    countSources(out);
    return out;
}

FillResult fillGaps(const HeightRaster& r, const FillOptions& o) {
    r.validate();
    o.validate();
    std::vector<char> measured;
    FillResult out = initResult(r, measured);
    std::vector<int> sizes;
    const std::vector<int> label = labelGaps(r, sizes);
    out.stats.gapComponents = int(sizes.size());
    if (!o.enabled || sizes.empty()) {
        countSources(out);
        return out;
    }

    // Measured cells per window, from a summed-area table: O(1) per cell.
    const int half = o.medianWindow_cells / 2;
    std::vector<int> sat(size_t(r.nx + 1) * size_t(r.ny + 1), 0);
    auto S = [&](int x, int y) -> int& { return sat[size_t(y) * size_t(r.nx + 1) + size_t(x)]; };
    for (int iy = 0; iy < r.ny; iy++)
        for (int ix = 0; ix < r.nx; ix++)
            S(ix + 1, iy + 1) =
                measured[r.index(ix, iy)] + S(ix, iy + 1) + S(ix + 1, iy) - S(ix, iy);
    auto knownInWindow = [&](int ix, int iy) {
        const int xa = std::max(ix - half, 0), xb = std::min(ix + half + 1, r.nx);
        const int ya = std::max(iy - half, 0), yb = std::min(iy + half + 1, r.ny);
        return S(xb, yb) - S(xa, yb) - S(xb, ya) + S(xa, ya);
    };

    std::vector<std::vector<int>> cells(sizes.size());
    std::vector<char> medianReach(sizes.size(), 1);
    for (size_t id = 0; id < sizes.size(); id++)
        if (sizes[id] <= o.maxGapCells) cells[id].reserve(size_t(sizes[id]));
    for (size_t k = 0; k < r.size(); k++) {
        const int id = label[k];
        if (id < 0 || sizes[size_t(id)] > o.maxGapCells) continue;
        cells[size_t(id)].push_back(int(k));
        if (knownInWindow(int(k) % r.nx, int(k) / r.nx) < o.medianMinKnown)
            medianReach[size_t(id)] = 0;
    }

    MedianFiller median(r, o);
    std::vector<char> usable = measured;  // the median of a small gap uses measured cells only
    for (size_t id = 0; id < sizes.size(); id++) {
        if (cells[id].empty()) continue;  // too large: stays Unfilled
        if (medianReach[id]) {
            for (int k : cells[id]) median.fillCell(k % r.nx, k / r.nx, out, usable);
            continue;
        }
        if (o.gaussianEnabled && fillWithGaussianSurface(r, o, cells[id], out)) continue;
        // Fallback: rim-inwards median; its intermediate cells must not leak into other gaps.
        std::vector<char> local = measured;
        median.fillRepeated(cells[id], out, local);
    }
    countSources(out);
    return out;
}

}  // namespace multibin::fill
