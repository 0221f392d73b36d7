/* Part of the multibin elevation-mapping library. */
#include "multibin/fill/ModelSelection.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "multibin/fill/HarmonicFill.h"

namespace multibin::fill {

GaussianFitOptions surfaceFitOptions(const FillOptions& o, const SupportArea& a) {
    GaussianFitOptions fitOptions = o.gaussianFitOptions();
    if (o.termsOutsideGap) {
        // Centres on the rim cells or beyond: the gap's bounding box widened by half a cell.
        fitOptions.excludeI0 = a.x0 - a.sx - 0.5, fitOptions.excludeI1 = a.x1 - a.sx + 0.5;
        fitOptions.excludeJ0 = a.y0 - a.sy - 0.5, fitOptions.excludeJ1 = a.y1 - a.sy + 0.5;
    }
    return fitOptions;
}

GaussianSurface selectSurfaceModel(const HeightRaster& r, const FillOptions& o,
                                   const SupportArea& a, const GaussianFitOptions& fitOptions) {
    const auto& samples = a.samples;
    const int side = a.side;
    if (o.criterion != ModelCriterion::Holdout)
        return fitGaussianSurface(samples, side, fitOptions);
    // Hide the two rings of measured cells nearest the gap, fit on the rest, fill the hidden
    // cells as the gap would be filled, and keep the m that predicts them best.
    std::vector<SurfaceSample> fitSet, heldOut;
    std::vector<int> hidden = a.cells;
    for (const auto& c : a.training)
        if (c.gapDist <= 2) {
            heldOut.push_back(c.s);
            hidden.push_back(a.rasterIndex(c.s.i, c.s.j));
        } else {
            fitSet.push_back(c.s);
        }
    if (fitSet.size() < 12 || heldOut.size() < 4)
        return fitGaussianSurface(samples, side, fitOptions);  // too little data: AICc
    auto heldOutError = [&](const GaussianSurface& s) {
        const auto res = o.residualCorrection ? harmonicResiduals(r, s, hidden, a)
                                              : std::vector<double>(hidden.size(), 0.0);
        double e = 0;
        for (size_t h = 0; h < heldOut.size(); h++) {
            const auto& v = heldOut[h];
            const double d = v.h_m - (s(v.i, v.j) + res[a.cells.size() + h]);
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
    // Refit on every training point with the chosen size, starting from the held-out fit's
    // terms (m - 1 of them seed the swarm; the LM polish does the rest).
    GaussianSurface seed = bestFit;
    if (bestM > 0) seed.terms.pop_back();
    return fitGaussianSurfaceFixed(samples, side, bestM, fitOptions, bestM > 0 ? &seed : nullptr);
}

KrigingModelSet searchKrigingModels(const FillOptions& o, const GaussianFitOptions& fitOptions,
                                    const SupportArea& a, const std::vector<SurfaceSample>& near) {
    const auto& samples = a.samples;
    const int side = a.side;
    const int n = int(samples.size());
    KrigingModelSet set;
    set.amplitudePrior = amplitudePriorPrecision(samples);
    double sensorVar = 0;
    for (const auto& s : samples) sensorVar += s.sigma_m * s.sigma_m;
    sensorVar /= n;

    auto& models = set.models;
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
        auto uk = std::make_unique<UniversalKriging>(near, g, cov, set.amplitudePrior);
        const double c = criterion(*uk, g);
        models.push_back(KrigingModel{c, int(g.terms.size()), g, cov, std::move(uk), {}, {}});
    };
    GaussianSurface prev = fitGaussianSurfaceFixed(samples, side, 0, fitOptions);
    size_t& best = set.best;
    evaluate(prev, covarianceOf(prev));
    for (int m = 1; m <= o.maxTerms && n > 2 + 5 * m + 3; m++) {
        const GaussianSurface g = fitGaussianSurfaceFixed(samples, side, m, fitOptions, &prev);
        evaluate(g, covarianceOf(g));
        // Forward selection as in the paper's search: stop at the first m that does not improve
        // the criterion (searching every m, or judging m against m - 1 under a common covariance,
        // did worse: doc/gap-filling.md, "How the settings were chosen").
        if (!(models.back().criterion < models[best].criterion)) break;
        best = models.size() - 1;
        prev = g;
    }
    auto& w = set.weights;
    w.assign(models.size(), 0.0);
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
    return set;
}

}  // namespace multibin::fill
