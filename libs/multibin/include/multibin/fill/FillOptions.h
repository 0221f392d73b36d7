/* Part of the multibin elevation-mapping library. */
#pragma once

#include <string>

#include "multibin/io/OptionsFwd.h"

// Included by the public map header: no other header of the library here but OptionsFwd.h.

namespace multibin::fill {

struct GaussianFitOptions;

/** How the model size m of eq 16 is chosen. */
enum class ModelCriterion {
    AICc,  //!< corrected Akaike criterion (the paper's AIC; default)
    BIC,   //!< Bayesian criterion: a stronger penalty, k ln n instead of about 2 k
    /** Prediction of held-out data: the cells within 2 cells of the gap are hidden, the model is
     * fitted on the rest and m minimises the weighted error of the fill (surface plus rim
     * residuals) on them. Needs the gap, so only fillGaps() applies it; fitGaussianSurface()
     * treats it as AICc. */
    Holdout
};

/** Correlation function of the terrain residuals about the trend (isotropic, distance in cells). */
enum class CovarianceFamily {
    Exponential,  //!< rho(d) = exp(-d / r): rough, continuous surface (Matern nu = 1/2)
    Matern32      //!< rho(d) = (1 + sqrt3 d / r) exp(-sqrt3 d / r): once differentiable
};

/** How a filled cell gets its sigma. */
enum class FillSigmaModel {
    /** Calibrated on held-out cells, one sigma per fill path (default; see doc/gap-filling.md).
     * Median cells: sigma^2 = sigma_nb^2 + (median_sigma_gain * s)^2, s the weighted RMS spread
     * of the window's heights about the median. Kriging cells: sigma = gaussian_sigma_gain *
     * sqrt(v f), v the kriging variance, f >= 1 the kriging's mean standardised squared error
     * on the gap's hidden rim (1 if that is below 1). Harmonic cells (eq 16 plus rim
     * residuals): sigma^2 = rms_res^2 + harmonic_sigma_gain^2 * 2 gamma(d), gamma the
     * semivariogram of the support area's known heights, d the distance to the nearest known
     * cell, plus (rim check) the mean squared error of the harmonic prediction of the hidden
     * rim. All floored at sigma_floor_m. */
    Calibrated,
    /** The paper's rule: the weighted average of the neighbours' sigma (same skeleton as the
     * median); Gaussian cells get the mean sigma of their training points. Too small for the
     * real interpolation error; kept for comparison. */
    Paper
};

/** Kriging neighbourhood of a gap (see FillOptions::krigingNeighbourhood). */
enum class KrigingNeighbourhood { Auto, Moving, Unique };

/** How the residuals of the measured cells about the fitted eq 16 surface are carried into a gap
 * (when FillOptions::residualCorrection is on). */
enum class ResidualModel {
    /** Universal kriging: eq 16 is the trend (amplitudes by generalised least squares), the
     * residuals are interpolated with a covariance fitted to their semivariogram, the kriging
     * variance gives the filled cell's sigma, and m is chosen by AIC on this Gaussian-process
     * likelihood (see doc/gap-filling.md). */
    Kriging,
    /** Harmonic function (Laplace equation) with the rim residuals as Dirichlet data; m chosen
     * by AIC on independent residuals; sigma from the semivariogram of the heights. */
    Harmonic,
    /** As Harmonic, but a biharmonic (thin-plate) function with the two rings of measured cells
     * around the gap as boundary data: continuous slopes across the rim. */
    Biharmonic
};

/** Options of gap filling. Ini keys (all prefixed `fill_` so they can live in the map's
 * insertion-options section) are given in brackets. */
struct FillOptions {
    bool enabled = true;  //!< [fill_enabled] run filling at all

    // --- Weighted median (small gaps) ---
    int medianWindow_cells =
        5;  //!< [fill_median_window_cells] odd side of the window [cells], >= 3
    /** [fill_median_min_known] a gap cell is filled by the median when its window holds at least
     * this many measured cells; a gap with a cell that has fewer goes to the Gaussian surface. */
    int medianMinKnown = 3;

    // --- Gaussian surface (large gaps, eq 16) ---
    bool gaussianEnabled = true;  //!< [fill_gaussian] false: large gaps by repeated median
    /** [fill_max_gap_cells] gaps (4-connected never-observed cells) larger than this stay
     * Unfilled: beyond the sensors' reach there is nothing to interpolate from [cells]. */
    int maxGapCells = 2500;
    int supportMargin_cells =
        4;  //!< [fill_support_margin_cells] margin of the square support [cells]
    /** [fill_max_training_points] measured cells used per support area at most: beyond it, the
     * ones nearest the gap are kept (bounds the fitting time) [-]. */
    int maxTrainingPoints = 600;
    /** [fill_residual_correction] beyond the paper: add to the fitted surface the residuals of
     * the rim cells, carried into the gap as a harmonic function, so the fill meets the rim. */
    bool residualCorrection = true;
    /** [fill_residual_model] kriging|harmonic|biharmonic: see ResidualModel. */
    ResidualModel residualModel = ResidualModel::Kriging;
    /** [fill_kriging_covariance] exponential|matern32: correlation family of the kriging. */
    CovarianceFamily krigingCovariance = CovarianceFamily::Matern32;
    /** [fill_terms_outside_gap] the centres of the Gaussian terms stay out of the gap's bounding
     * box (on its rim cells or beyond): a term then peaks where data constrain it instead of
     * bulging into the gap. */
    bool termsOutsideGap = true;
    /** [fill_kriging_max_points] the kriging (and its likelihood) uses at most this many
     * training points, the nearest to the gap: its cost grows as the cube [-]. */
    int krigingMaxPoints = 200;
    /** [fill_kriging_neighbourhood] auto|moving|unique: where each gap cell is kriged from.
     * unique: the krigingMaxPoints training points nearest the gap, one factorisation for the
     * whole gap; moving: each tile of 8 x 8 gap cells from its own krigingMaxPoints nearest
     * training points (the trend's amplitudes re-estimated there); auto: unique when those
     * points hold the two whole rings of measured cells around the gap, else moving (a long or
     * sprawling gap, whose rim does not fit in one neighbourhood). */
    KrigingNeighbourhood krigingNeighbourhood = KrigingNeighbourhood::Auto;
    /** [fill_moving_rim_check] a gap kriged in moving neighbourhoods is also filled, on its two
     * hidden rings of measured cells, by eq 16 (m by AIC on independent residuals) plus harmonic
     * rim residuals; if that predicts the hidden rings better than the kriging does, the gap is
     * filled that way (the kriging sigma kept). A step hidden in a long shadow is what the
     * smooth kriging carries too far. */
    bool movingRimCheck = true;
    /** A filled cell lies no higher than its clearance (the lowest line of sight that passed
     * over it without a return there, kept by the map's visibility stage) plus margin_m: a cell
     * the laser never hit lies below the rays over it (BoundedByClearance.h). */
    struct Clearance {
        /** [fill_clearance] off by default: the lines walked for it cost about 17 % of a laser
         * scan's insertion (doc/gap-filling.md). */
        bool enabled = false;
        /** [fill_clearance_margin_m] what a filled cell may lie above its clearance [m]: the
         * ray's own error near its end point and the cell's relief under a line crossing it. */
        double margin_m = 0.0;
    } clearance;
    /** A gap whose rim holds the top of a step that hides it (a shadow behind a raised edge,
     * see ShadowOccluders.h) is filled without the step's top: from the hidden side only. */
    struct ShadowOccluders {
        bool enabled = true;  //!< [fill_shadow_occluders]
        /** [fill_shadow_step_sigmas] a rim cell is an occluder when it stands above the cells
         * across the gap by more than this many standard deviations of what their sigmas and the
         * visible slopes explain [-]. */
        double stepSigmas = 3.0;
        /** [fill_shadow_reach_cells] an occluder's top is hidden from the fill up to this many
         * cells from its rim cell [cells]. */
        int reach_cells = 4;
    } shadowOccluders;
    /** [fill_model_averaging] kriging only: average the fills of the m visited by the search
     * with Akaike weights exp(-dAIC/2) (and add their spread to the variance) instead of
     * keeping the single best m. */
    bool modelAveraging = true;
    /** [fill_extrapolation_margin] Gaussian-filled heights are kept within the training heights'
     * range widened by this fraction of it on each side [-]. 0.25 cut overshoot into rock-board
     * gaps (doc/gap-filling.md) but also flattens a hidden hill top higher than that. */
    double extrapolationMargin = 0.25;
    /** [fill_model_criterion] aic (the paper's, as AICc), bic or holdout: how m is chosen
     * (see ModelCriterion). */
    ModelCriterion criterion = ModelCriterion::AICc;
    int maxTerms = 4;             //!< [fill_max_terms] largest m tried by AIC [-]
    double minWidth_cells = 1.0;  //!< [fill_min_width_cells] narrowest Gaussian sigma [cells]
    int swarmParticles = 20;      //!< [fill_pso_particles]
    int swarmIterations = 25;     //!< [fill_pso_iterations]
    unsigned swarmSeed = 1;       //!< [fill_pso_seed]

    // --- Sigma of filled cells ---
    FillSigmaModel sigmaModel =
        FillSigmaModel::Calibrated;  //!< [fill_sigma_model] calibrated|paper
    double medianSigmaGain = 0.77;   //!< [fill_median_sigma_gain] calibrated gain [-]
    /** [fill_gaussian_sigma_gain] calibrated gain of the kriging sigma [-] */
    double gaussianSigmaGain = 1.16;
    /** [fill_harmonic_sigma_gain] calibrated gain of the harmonic (surface path) sigma [-] */
    double harmonicSigmaGain = 0.76;
    double sigmaFloor_m = 0.002;  //!< [fill_sigma_floor_m] smallest sigma of a filled cell [m]

    /** The Gaussian-fit settings these options imply. */
    GaussianFitOptions gaussianFitOptions() const;

    /** Reads the `fill_*` keys through a strict reader of the section they live in (the caller
     * owns the reader and calls finish()); absent keys keep their value. Then validate(). */
    void read(StrictConfigSection& section);
    /** Reads a section holding only `fill_*` keys (unknown keys are an error). */
    void loadFromConfigFile(const mrpt::config::CConfigFileBase& source,
                            const std::string& section);
    /** Writes every `fill_*` key to `section`. */
    void write(mrpt::config::CConfigFileBase& target, const std::string& section) const;
    /** Throws std::invalid_argument naming the ini key of the first bad value. */
    void validate() const;
};

}  // namespace multibin::fill
