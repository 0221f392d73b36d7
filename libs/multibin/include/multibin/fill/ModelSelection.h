/* Part of the multibin elevation-mapping library. */
#pragma once

#include <memory>
#include <vector>

#include "multibin/fill/FillOptions.h"
#include "multibin/fill/GaussianSurface.h"
#include "multibin/fill/HeightRaster.h"
#include "multibin/fill/Kriging.h"
#include "multibin/fill/SupportArea.h"

namespace multibin::fill {

/** The eq 16 fit settings for the support area of a gap: options.gaussianFitOptions(), with the
 * terms' centres kept out of the gap's bounding box widened by half a cell when
 * options.termsOutsideGap (on the rim cells or beyond). */
GaussianFitOptions surfaceFitOptions(const FillOptions& options, const SupportArea& area);

/** The model size of the surface path (independent residuals): ModelCriterion::Holdout hides
 * the two rings of measured cells nearest the gap, fits m = 0, 1, ... on the rest and keeps the
 * m whose fill (surface plus rim residuals) predicts them best, then refits that m on every
 * training point; AICc and BIC are fitGaussianSurface()'s search. */
GaussianSurface selectSurfaceModel(const HeightRaster& raster, const FillOptions& options,
                                   const SupportArea& area, const GaussianFitOptions& fitOptions);

/** One model of the kriging path: eq 16 with m terms as the trend, the covariance fitted to its
 * residuals, its criterion on the kriging likelihood, and (once predicted) its fill. */
struct KrigingModel {
    double criterion = 0;    //!< AICc or BIC of the kriging likelihood (lower is better)
    int m = 0;               //!< number of Gaussian terms
    GaussianSurface shapes;  //!< the swarm's fit; the kriging re-estimates its amplitudes
    Covariance cov;          //!< fitted to the semivariogram of its residuals
    std::unique_ptr<UniversalKriging> kriging;  //!< on the neighbourhood nearest the gap
    std::vector<double> mean_m, var_m2;         //!< kriged height and variance per gap cell
};

/** The models visited by the kriging path's search and their weights. */
struct KrigingModelSet {
    std::vector<KrigingModel> models;  //!< m = 0, 1, ... in search order
    size_t best = 0;                   //!< index of the lowest criterion
    std::vector<double> weights;       //!< Akaike weights (or 1 for the best), sum 1
    double amplitudePrior = 0;         //!< see amplitudePriorPrecision
};

/** The kriging path's model search (ResidualModel::Kriging): eq 16 fitted for m = 0, 1, ... on
 * the area's training points (seeded swarm, iid Mahalanobis fitness), each fit taken as the
 * trend of a universal kriging on `near` whose residual covariance is fitted to the
 * semivariogram of its residuals; m grows while the criterion (AICc or BIC) on the kriging
 * likelihood improves. Weights: Akaike weights exp(-dAIC/2) when options.modelAveraging (a
 * model more than 20 above the best gets 0), else 1 for the best. Throws std::runtime_error if
 * a kriging matrix is not positive definite. */
KrigingModelSet searchKrigingModels(const FillOptions& options,
                                    const GaussianFitOptions& fitOptions, const SupportArea& area,
                                    const std::vector<SurfaceSample>& near);

}  // namespace multibin::fill
