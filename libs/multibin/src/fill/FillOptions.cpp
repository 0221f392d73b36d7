/* Part of the multibin elevation-mapping library. */
#include "multibin/fill/FillOptions.h"

#include <mrpt/config/CConfigFileBase.h>

#include <cmath>
#include <stdexcept>

#include "multibin/io/StrictConfigSection.h"

namespace multibin::fill {

namespace {
const char* criterionName(ModelCriterion c) {
    return c == ModelCriterion::BIC ? "bic" : c == ModelCriterion::Holdout ? "holdout" : "aic";
}

const char* sigmaModelName(FillSigmaModel m) {
    return m == FillSigmaModel::Paper ? "paper" : "calibrated";
}
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

void FillOptions::read(StrictConfigSection& s) {
    s.read("fill_enabled", enabled);
    s.read("fill_median_window", medianWindow_cells);
    s.read("fill_median_min_known", medianMinKnown);
    s.read("fill_gaussian", gaussianEnabled);
    s.read("fill_max_gap_cells", maxGapCells);
    s.read("fill_support_margin", supportMargin_cells);
    s.read("fill_max_training_points", maxTrainingPoints);
    s.read("fill_residual_correction", residualCorrection);
    s.readChoice<ResidualModel>("fill_residual_model", residualModel,
                                {{"kriging", ResidualModel::Kriging},
                                 {"harmonic", ResidualModel::Harmonic},
                                 {"biharmonic", ResidualModel::Biharmonic}});
    s.readChoice<CovarianceFamily>(
        "fill_kriging_covariance", krigingCovariance,
        {{"exponential", CovarianceFamily::Exponential}, {"matern32", CovarianceFamily::Matern32}});
    s.read("fill_terms_outside_gap", termsOutsideGap);
    s.read("fill_kriging_max_points", krigingMaxPoints);
    s.read("fill_moving_rim_check", movingRimCheck);
    s.readChoice<KrigingNeighbourhood>("fill_kriging_neighbourhood", krigingNeighbourhood,
                                       {{"auto", KrigingNeighbourhood::Auto},
                                        {"moving", KrigingNeighbourhood::Moving},
                                        {"unique", KrigingNeighbourhood::Unique}});
    s.read("fill_model_averaging", modelAveraging);
    s.read("fill_extrapolation_margin", extrapolationMargin);
    s.readChoice<ModelCriterion>("fill_model_criterion", criterion,
                                 {{"aic", ModelCriterion::AICc},
                                  {"bic", ModelCriterion::BIC},
                                  {"holdout", ModelCriterion::Holdout}});
    s.read("fill_max_terms", maxTerms);
    s.read("fill_min_width", minWidth_cells);
    s.read("fill_pso_particles", swarmParticles);
    s.read("fill_pso_iterations", swarmIterations);
    s.read("fill_pso_seed", swarmSeed);
    s.readChoice<FillSigmaModel>(
        "fill_sigma_model", sigmaModel,
        {{"calibrated", FillSigmaModel::Calibrated}, {"paper", FillSigmaModel::Paper}});
    s.read("fill_median_sigma_gain", medianSigmaGain);
    s.read("fill_gaussian_sigma_gain", gaussianSigmaGain);
    s.read("fill_sigma_floor", sigmaFloor_m);
    validate();
}

void FillOptions::loadFromConfigFile(const mrpt::config::CConfigFileBase& source,
                                     const std::string& section) {
    StrictConfigSection s(source, section);
    read(s);
    s.finish();
}

void FillOptions::saveToConfigFile(mrpt::config::CConfigFileBase& c,
                                   const std::string& section) const {
    c.write(section, "fill_enabled", enabled);
    c.write(section, "fill_median_window", medianWindow_cells);
    c.write(section, "fill_median_min_known", medianMinKnown);
    c.write(section, "fill_gaussian", gaussianEnabled);
    c.write(section, "fill_max_gap_cells", maxGapCells);
    c.write(section, "fill_support_margin", supportMargin_cells);
    c.write(section, "fill_max_training_points", maxTrainingPoints);
    c.write(section, "fill_residual_correction", residualCorrection);
    c.write(section, "fill_residual_model",
            std::string(residualModel == ResidualModel::Harmonic     ? "harmonic"
                        : residualModel == ResidualModel::Biharmonic ? "biharmonic"
                                                                     : "kriging"));
    c.write(
        section, "fill_kriging_covariance",
        std::string(krigingCovariance == CovarianceFamily::Matern32 ? "matern32" : "exponential"));
    c.write(section, "fill_terms_outside_gap", termsOutsideGap);
    c.write(section, "fill_kriging_max_points", krigingMaxPoints);
    c.write(section, "fill_moving_rim_check", movingRimCheck);
    c.write(section, "fill_kriging_neighbourhood",
            std::string(krigingNeighbourhood == KrigingNeighbourhood::Moving   ? "moving"
                        : krigingNeighbourhood == KrigingNeighbourhood::Unique ? "unique"
                                                                               : "auto"));
    c.write(section, "fill_model_averaging", modelAveraging);
    c.write(section, "fill_extrapolation_margin", extrapolationMargin);
    c.write(section, "fill_model_criterion", std::string(criterionName(criterion)));
    c.write(section, "fill_max_terms", maxTerms);
    c.write(section, "fill_min_width", minWidth_cells);
    c.write(section, "fill_pso_particles", swarmParticles);
    c.write(section, "fill_pso_iterations", swarmIterations);
    c.write(section, "fill_pso_seed", int(swarmSeed));
    c.write(section, "fill_sigma_model", std::string(sigmaModelName(sigmaModel)));
    c.write(section, "fill_median_sigma_gain", medianSigmaGain);
    c.write(section, "fill_gaussian_sigma_gain", gaussianSigmaGain);
    c.write(section, "fill_sigma_floor", sigmaFloor_m);
}

void FillOptions::validate() const {
    auto bad = [](const std::string& key, const std::string& what) {
        throw std::invalid_argument("gap-filling option '" + key + "': " + what);
    };
    if (medianWindow_cells < 3 || medianWindow_cells % 2 == 0 || medianWindow_cells > 15)
        bad("fill_median_window", "must be an odd number of cells from 3 to 15");
    if (medianMinKnown < 1 || medianMinKnown > medianWindow_cells * medianWindow_cells - 1)
        bad("fill_median_min_known", "must be from 1 to window^2 - 1");
    if (maxGapCells < 1) bad("fill_max_gap_cells", "must be >= 1 [cells]");
    if (supportMargin_cells < 1 || supportMargin_cells > 100)
        bad("fill_support_margin", "must be from 1 to 100 [cells]");
    if (maxTrainingPoints < 10) bad("fill_max_training_points", "must be >= 10");
    if (krigingMaxPoints < 20 || krigingMaxPoints > 5000)
        bad("fill_kriging_max_points", "must be from 20 to 5000");
    if (maxTerms < 0 || maxTerms > 20) bad("fill_max_terms", "must be from 0 to 20");
    if (!(extrapolationMargin >= 0) || !std::isfinite(extrapolationMargin))
        bad("fill_extrapolation_margin", "must be >= 0");
    if (!(minWidth_cells >= 0.3) || !std::isfinite(minWidth_cells))
        bad("fill_min_width", "must be >= 0.3 [cells]");
    if (swarmParticles < 1 || swarmParticles > 1000) bad("fill_pso_particles", "must be 1..1000");
    if (swarmIterations < 0 || swarmIterations > 100000)
        bad("fill_pso_iterations", "must be 0..100000");
    if (!(medianSigmaGain >= 0) || !std::isfinite(medianSigmaGain))
        bad("fill_median_sigma_gain", "must be >= 0");
    if (!(gaussianSigmaGain >= 0) || !std::isfinite(gaussianSigmaGain))
        bad("fill_gaussian_sigma_gain", "must be >= 0");
    if (!(sigmaFloor_m >= 0) || !std::isfinite(sigmaFloor_m))
        bad("fill_sigma_floor", "must be >= 0 [m]");
}

}  // namespace multibin::fill
