/* Part of the multibin elevation-mapping library. */
#pragma once

#include <vector>

#include "multibin/fill/FillOptions.h"
#include "multibin/fill/ParticleSwarm.h"

namespace multibin::fill {

/** One known height inside a support area: the training data of eq 16. */
struct SurfaceSample {
    int i = 0;              //!< column inside the support area, 0 .. side-1 [cells]
    int j = 0;              //!< row inside the support area, 0 .. side-1 [cells]
    double h_m = 0;         //!< measured height [m]
    double sigma_m = 0.01;  //!< its 1-sigma [m] (weight 1/sigma^2 in the fitness)
};

/** One term of eq 16: c * exp(lambda1 (i - a1)^2 + lambda2 (j - a2)^2), i, j in cells. */
struct GaussianTerm {
    double c_m = 0;      //!< amplitude [m]
    double lambda1 = 0;  //!< [1/cell^2], < 0
    double a1 = 0;       //!< centre column [cells]
    double lambda2 = 0;  //!< [1/cell^2], < 0
    double a2 = 0;       //!< centre row [cells]
};

/** The fitted surface of eq 16 on one square support area.
 *
 * The q = 0 term of eq 16 is taken with lambda1,0 = lambda2,0 = 0, i.e. a constant `c0_m`, so
 * `terms.size()` is the model size m (m = 0: a plane at the weighted mean height). */
struct GaussianSurface {
    double c0_m = 0;                  //!< the q = 0 (constant) term [m]
    std::vector<GaussianTerm> terms;  //!< q = 1..m
    int samples = 0;                  //!< training points n
    double chi2 = 0;  //!< squared Mahalanobis distance to the samples, sum ((h - f)/sigma)^2 [-]
    double aicc = 0;  //!< corrected Akaike criterion of this fit [-] (lower is better)
    double bic = 0;   //!< Bayesian (Schwarz) criterion of this fit [-] (lower is better)
    double rmsResidual_m = 0;  //!< weighted RMS of (h - f) over the samples [m]

    /** Height of the surface at (i, j) [m], in support-area cells (fractional allowed). */
    double operator()(double i, double j) const;
    /** Parameters of the model: m + 1 amplitudes and 4 m shape parameters. */
    int parameters() const { return 1 + 5 * int(terms.size()); }
};

/** How eq 16 is fitted. */
struct GaussianFitOptions {
    ModelCriterion criterion = ModelCriterion::AICc;  //!< how m is chosen
    int maxTerms = 4;                                 //!< largest m tried by the AIC search [-]
    double minWidth_cells = 1.0;  //!< narrowest Gaussian, as a standard deviation [cells]
    /** Widest Gaussian, as a multiple of the support-area side [-] (wide terms act as slopes). */
    double maxWidthFactor = 2.0;
    ParticleSwarmOptions swarm;  //!< PSO settings for each m
    /** Centres of the terms are kept out of this box [cells] (i0, i1, j0, j1 in support-area
     * cells; a centre inside is moved to the nearest side): a term must peak where data are,
     * not inside a gap where nothing constrains its height. Empty (i0 > i1): no restriction. */
    double excludeI0 = 1, excludeI1 = 0, excludeJ0 = 1, excludeJ1 = 0;
    /** Levenberg-Marquardt iterations that refine the swarm's best centres and widths (0: the
     * swarm's answer as is) [-]. */
    int polishIterations = 20;
};

/** Corrected Akaike criterion of a weighted least-squares fit with an unknown common scale of
 * the weights: n ln(chi2 / n) + 2 k + 2 k (k + 1) / (n - k - 1). Infinite if n <= k + 1. */
double correctedAic(double chi2, int n, int k);

/** Bayesian criterion of a weighted least-squares fit with an unknown common scale of the
 * weights: n ln(chi2 / n) + k ln n. */
double bayesianCriterion(double chi2, int n, int k);

/** Precision 1 / sigma_c^2 [1/m^2] of the weak Gaussian prior on the amplitudes c_q (q >= 1):
 * sigma_c = the samples' height range (at least 3 times their largest sigma). It does nothing to
 * a term the data support and keeps a term sitting in the gap, where no sample constrains it,
 * from taking an arbitrary amplitude. */
double amplitudePriorPrecision(const std::vector<SurfaceSample>& samples);

/** Fits eq 16 with exactly m Gaussians to samples on a side x side support area: amplitudes by
 * weighted linear least squares (Gram matrix, Eigen LDLT), centres and widths by particle
 * swarm minimising chi2, then refined by Levenberg-Marquardt from the swarm's best. `seed` (may be
 * empty) is a fit with m - 1 terms: the swarm then starts from it plus one term at the largest
 * residual. Throws std::invalid_argument on empty samples, side < 2, a sample outside the area, m <
 * 0 or a non-positive sigma. */
GaussianSurface fitGaussianSurfaceFixed(const std::vector<SurfaceSample>& samples, int side, int m,
                                        const GaussianFitOptions& options,
                                        const GaussianSurface* seed = nullptr);

/** Fits eq 16 choosing m = 0, 1, ... maxTerms by options.criterion: m grows while the criterion
 * improves (each fit seeded by the previous one) and the best fit is returned. */
GaussianSurface fitGaussianSurface(const std::vector<SurfaceSample>& samples, int side,
                                   const GaussianFitOptions& options);

}  // namespace multibin::fill
