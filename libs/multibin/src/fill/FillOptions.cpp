/* Part of the multibin elevation-mapping library. */
#include "multibin/fill/FillOptions.h"

#include <mrpt/config/CConfigFileBase.h>

#include <cmath>
#include <stdexcept>
#include <type_traits>
#include <utility>
#include <vector>

#include "multibin/fill/GaussianSurface.h"
#include "multibin/io/OptionKeys.h"

namespace multibin::fill {

namespace {
const OptionNames<ResidualModel> kResidualModels{{"kriging", ResidualModel::Kriging},
                                                 {"harmonic", ResidualModel::Harmonic},
                                                 {"biharmonic", ResidualModel::Biharmonic}};
const OptionNames<CovarianceFamily> kCovarianceFamilies{
    {"exponential", CovarianceFamily::Exponential}, {"matern32", CovarianceFamily::Matern32}};
const OptionNames<KrigingNeighbourhood> kNeighbourhoods{{"auto", KrigingNeighbourhood::Auto},
                                                        {"moving", KrigingNeighbourhood::Moving},
                                                        {"unique", KrigingNeighbourhood::Unique}};
const OptionNames<ModelCriterion> kCriteria{{"aic", ModelCriterion::AICc},
                                            {"bic", ModelCriterion::BIC},
                                            {"holdout", ModelCriterion::Holdout}};
const OptionNames<FillSigmaModel> kSigmaModels{{"calibrated", FillSigmaModel::Calibrated},
                                               {"paper", FillSigmaModel::Paper}};

/** The `fill_*` keys of `o` (a FillOptions or a const one), for the options protocol
 * (multibin/io/OptionKeys.h): read, written and checked from this one list. */
template <class Options, class Visit>
void visitKeys(Options& o, Visit&& visit) {
    visit("fill_enabled", o.enabled);
    visit({"fill_median_window_cells", "fill_median_window"}, o.medianWindow_cells,
          oddBetween(3, 15, "cells"));
    visit("fill_median_min_known", o.medianMinKnown, atLeast(1));
    visit("fill_gaussian", o.gaussianEnabled);
    visit("fill_max_gap_cells", o.maxGapCells, atLeast(1, "cells"));
    visit({"fill_support_margin_cells", "fill_support_margin"}, o.supportMargin_cells,
          between(1, 100, "cells"));
    visit("fill_max_training_points", o.maxTrainingPoints, atLeast(10));
    visit("fill_residual_correction", o.residualCorrection);
    visit("fill_residual_model", o.residualModel, kResidualModels);
    visit("fill_kriging_covariance", o.krigingCovariance, kCovarianceFamilies);
    visit("fill_terms_outside_gap", o.termsOutsideGap);
    visit("fill_kriging_max_points", o.krigingMaxPoints, between(20, 5000));
    visit("fill_moving_rim_check", o.movingRimCheck);
    visit("fill_shadow_occluders", o.shadowOccluders.enabled);
    visit("fill_shadow_step_sigmas", o.shadowOccluders.stepSigmas, atLeast(0));
    visit("fill_shadow_reach_cells", o.shadowOccluders.reach_cells, between(0, 100, "cells"));
    visit("fill_clearance", o.clearance.enabled);
    visit("fill_clearance_margin_m", o.clearance.margin_m, atLeast(0, "m"));
    visit("fill_kriging_neighbourhood", o.krigingNeighbourhood, kNeighbourhoods);
    visit("fill_model_averaging", o.modelAveraging);
    visit("fill_extrapolation_margin", o.extrapolationMargin, atLeast(0));
    visit("fill_model_criterion", o.criterion, kCriteria);
    visit("fill_max_terms", o.maxTerms, between(0, 20));
    visit({"fill_min_width_cells", "fill_min_width"}, o.minWidth_cells, atLeast(0.3, "cells"));
    visit("fill_pso_particles", o.swarmParticles, between(1, 1000));
    visit("fill_pso_iterations", o.swarmIterations, between(0, 100000));
    visit("fill_pso_seed", o.swarmSeed);
    visit("fill_sigma_model", o.sigmaModel, kSigmaModels);
    visit("fill_median_sigma_gain", o.medianSigmaGain, atLeast(0));
    visit("fill_gaussian_sigma_gain", o.gaussianSigmaGain, atLeast(0));
    visit("fill_harmonic_sigma_gain", o.harmonicSigmaGain, atLeast(0));
    visit({"fill_sigma_floor_m", "fill_sigma_floor"}, o.sigmaFloor_m, atLeast(0, "m"));
}

/** visitKeys as one callable, for readOptionKeys() and loadOptionKeys(). */
const auto kKeys = [](auto& o, auto&& visit) { visitKeys(o, visit); };
}  // namespace

GaussianFitOptions FillOptions::gaussianFitOptions() const {
    GaussianFitOptions g;
    g.criterion = criterion;
    g.maxTerms = maxTerms;
    g.minWidth_cells = minWidth_cells;
    g.swarm.particles = swarmParticles;
    g.swarm.iterations = swarmIterations;
    g.swarm.seed = swarmSeed;
    return g;
}

void FillOptions::read(StrictConfigSection& s) { readOptionKeys(s, *this, kKeys); }
void FillOptions::loadFromConfigFile(const mrpt::config::CConfigFileBase& source,
                                     const std::string& section) {
    loadOptionKeys(source, section, *this, kKeys);
}

void FillOptions::write(mrpt::config::CConfigFileBase& c, const std::string& section) const {
    visitKeys(*this, OptionWriter{c, section});
}

void FillOptions::validate() const {
    const OptionChecker check("gap-filling option");
    visitKeys(*this, check);
    if (medianMinKnown > medianWindow_cells * medianWindow_cells - 1)
        check.fail("fill_median_min_known", "must be from 1 to window^2 - 1");
}

}  // namespace multibin::fill
