/* Part of the multibin elevation-mapping library. */
#include "multibin/fill/KrigingFill.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "multibin/fill/HarmonicFill.h"
#include "multibin/fill/ModelSelection.h"

namespace multibin::fill {

namespace {

/** Moving-neighbourhood kriging: the gap cells (ci, cj) are cut into tiles of kTile x kTile
 * cells, each kriged from its own `k` training points nearest the tile (distance to the tile's
 * box), under each weighted model's trend shapes and covariance (the amplitudes re-estimated by
 * GLS on the tile's points, as a local universal kriging does). Fills models[q].mean_m /
 * var_m2 for every q with w[q] > 0. */
void krigeByTiles(const std::vector<double>& ci, const std::vector<double>& cj,
                  const std::vector<SurfaceSample>& samples, int k, double prior,
                  std::vector<KrigingModel>& models, const std::vector<double>& w) {
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

/** The rim check: true if the rim-check surface plus harmonic rim residuals predicts the area's
 * two hidden rings of measured cells better (sum of squared errors) than the kriging of `best`
 * from the cells beyond them. */
bool harmonicPredictsRimBetter(const HeightRaster& r, const FillOptions& o, const SupportArea& a,
                               const GaussianSurface& alternative, const KrigingModel& best,
                               double prior) {
    std::vector<KrigingModel> one(1);
    one[0].shapes = best.shapes, one[0].cov = best.cov;
    std::vector<double> ri, rj;
    std::vector<int> both = a.cells;
    for (const auto& s : a.rim) {
        ri.push_back(s.i), rj.push_back(s.j);
        both.push_back(a.rasterIndex(s.i, s.j));
    }
    krigeByTiles(ri, rj, a.beyondRim, o.krigingMaxPoints, prior, one, {1.0});
    const auto hr = harmonicResiduals(r, alternative, both, a);
    double ek = 0, eh = 0;
    for (size_t k = 0; k < a.rim.size(); k++) {
        const auto& v = a.rim[k];
        const double dh = v.h_m - (alternative(v.i, v.j) + hr[a.cells.size() + k]);
        const double dk = v.h_m - one[0].mean_m[k];
        eh += dh * dh, ek += dk * dk;
    }
    return eh < ek;
}

}  // namespace

KrigingPlan planKriging(const FillOptions& o, const SupportArea& a) {
    KrigingPlan plan;
    plan.fitOptions = surfaceFitOptions(o, a);
    // The kriging neighbourhood: the training points nearest the gap (its cost is cubic).
    // Its likelihood (the choice of m) is that of these points.
    plan.near = nearestToGap(a, size_t(o.krigingMaxPoints));
    // One neighbourhood for the whole gap only if it holds the two rings of measured cells
    // around it; otherwise (a long shadow, a sprawling gap) part of the gap would be
    // extrapolated from one side of its rim: krige each tile from its own nearest points.
    plan.moving = o.krigingNeighbourhood == KrigingNeighbourhood::Moving ||
                  (o.krigingNeighbourhood == KrigingNeighbourhood::Auto &&
                   a.rim.size() > plan.near.size());
    // A gap too long or sprawling for one neighbourhood: the rim check against eq 16 by AIC
    // with harmonic rim residuals.
    if (plan.moving && o.movingRimCheck)
        plan.rimCheckSurface = fitGaussianSurface(a.samples, a.side, plan.fitOptions);
    return plan;
}

void fillByKriging(const HeightRaster& r, const FillOptions& o, const SupportArea& a,
                   const KrigingPlan& plan, FillResult& out) {
    const auto& cells = a.cells;
    KrigingModelSet set = searchKrigingModels(o, plan.fitOptions, a, plan.near);
    auto& models = set.models;
    const auto& w = set.weights;
    const KrigingModel& best = models[set.best];
    double meanSigma = 0;
    for (const auto& s : a.samples) meanSigma += s.sigma_m;
    meanSigma /= int(a.samples.size());
    std::vector<double> ci(cells.size()), cj(cells.size());
    for (size_t c = 0; c < cells.size(); c++) ci[c] = a.i(c), cj[c] = a.j(c);

    if (!plan.moving) {
        for (size_t q = 0; q < models.size(); q++)
            if (w[q] > 0) models[q].kriging->predict(ci, cj, models[q].mean_m, models[q].var_m2);
    } else {
        krigeByTiles(ci, cj, a.all, o.krigingMaxPoints, set.amplitudePrior, models, w);
        out.stats.movingNeighbourhoods++;
    }
    out.stats.supportAreas++;
    out.stats.termsChosen.push_back(best.m);
    const double hLo = a.heightLo_m, hHi = a.heightHi_m, slack = a.slack_m(o);
    std::vector<double> harmonic;  // the gap's heights by harmonic residuals, if they won
    if (plan.rimCheckSurface && a.rim.size() >= 4 && a.beyondRim.size() >= 12 &&
        harmonicPredictsRimBetter(r, o, a, *plan.rimCheckSurface, best, set.amplitudePrior)) {
        const GaussianSurface& alternative = *plan.rimCheckSurface;
        const auto hg = harmonicResiduals(r, alternative, cells, a);
        harmonic.resize(cells.size());
        for (size_t c = 0; c < cells.size(); c++)
            harmonic[c] = alternative(ci[c], cj[c]) + hg[c];
        out.stats.rimCheckHarmonic++;
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
        out.source[k] = HeightSource::FilledSurface;
    }
}

}  // namespace multibin::fill
