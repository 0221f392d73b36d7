/* Part of the multibin elevation-mapping library. */
#include "multibin/fill/HarmonicFill.h"

#include <Eigen/SparseCore>
#include <Eigen/SparseLU>

#include <algorithm>
#include <cmath>
#include <limits>

namespace multibin::fill {

std::vector<double> harmonicResiduals(const HeightRaster& r, const GaussianSurface& g,
                                      const std::vector<int>& cells, const SupportArea& a) {
    const int sx = a.sx, sy = a.sy, ex = a.ex, ey = a.ey;
    const int w = ex - sx, h = ey - sy, nx = r.nx();
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
        kind[at(k % nx, k / nx)] = 2;
        res[at(k % nx, k / nx)] = 0;
    }
    constexpr double kOmega = 1.8;         // over-relaxation factor
    constexpr double kTolerance_m = 1e-5;  // well below any sensor noise
    for (int it = 0; it < 2000; it++) {
        double maxStep = 0;
        for (int k : cells) {
            const int ix = k % nx, iy = k / nx;
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
    for (size_t c = 0; c < cells.size(); c++) out[c] = res[at(cells[c] % nx, cells[c] / nx)];
    return out;
}

std::vector<double> biharmonicResiduals(const HeightRaster& r, const GaussianSurface& g,
                                        const std::vector<int>& cells, const SupportArea& a) {
    const int sx = a.sx, sy = a.sy, nx = r.nx();
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
        const int ix = cells[size_t(c)] % nx, iy = cells[size_t(c)] / nx;
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

void fillByHarmonic(const HeightRaster& r, const FillOptions& o, const SupportArea& a,
                    const GaussianSurface& g, FillResult& out) {
    const auto& cells = a.cells;
    const auto& samples = a.samples;
    const int side = a.side, sx = a.sx, sy = a.sy;
    // The surface never leaves the heights of its data by more than extrapolationMargin times
    // their range: far from the rim the model extrapolates, and the data say little there.
    const double hLo = a.heightLo_m, hHi = a.heightHi_m, slack = a.slack_m(o);
    out.stats.supportAreas++;
    out.stats.termsChosen.push_back(int(g.terms.size()));

    // Distance of each gap cell to the nearest training point [cells].
    std::vector<double> dist(cells.size(), std::numeric_limits<double>::infinity());
    double maxDist = 1;
    for (size_t c = 0; c < cells.size(); c++) {
        const int i = a.i(c), j = a.j(c);
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
                                          ? biharmonicResiduals(r, g, cells, a)
                                          : harmonicResiduals(r, g, cells, a);
    for (size_t c = 0; c < cells.size(); c++) {
        const double h = std::clamp(g(a.i(c), a.j(c)) + resid[c], hLo - slack, hHi + slack);
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
        out.source[k] = HeightSource::FilledSurface;
    }
}

}  // namespace multibin::fill
