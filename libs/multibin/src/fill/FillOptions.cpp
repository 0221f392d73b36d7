/* Part of the multibin elevation-mapping library. */
#include "multibin/fill/FillOptions.h"

#include <mrpt/config/CConfigFileBase.h>

#include <cmath>
#include <stdexcept>
#include <type_traits>
#include <utility>
#include <vector>

#include "multibin/fill/GaussianSurface.h"
#include "multibin/io/StrictConfigSection.h"

namespace multibin::fill {

namespace {
// One table per choice key: the names read and the names written.
template <class T>
using Names = std::vector<std::pair<std::string, T>>;

const Names<ResidualModel> kResidualModels{{"kriging", ResidualModel::Kriging},
                                           {"harmonic", ResidualModel::Harmonic},
                                           {"biharmonic", ResidualModel::Biharmonic}};
const Names<CovarianceFamily> kCovarianceFamilies{{"exponential", CovarianceFamily::Exponential},
                                                  {"matern32", CovarianceFamily::Matern32}};
const Names<KrigingNeighbourhood> kNeighbourhoods{{"auto", KrigingNeighbourhood::Auto},
                                                  {"moving", KrigingNeighbourhood::Moving},
                                                  {"unique", KrigingNeighbourhood::Unique}};
const Names<ModelCriterion> kCriteria{{"aic", ModelCriterion::AICc},
                                      {"bic", ModelCriterion::BIC},
                                      {"holdout", ModelCriterion::Holdout}};
const Names<FillSigmaModel> kSigmaModels{{"calibrated", FillSigmaModel::Calibrated},
                                         {"paper", FillSigmaModel::Paper}};

template <class T>
std::string nameOf(const Names<T>& names, T value) {
    for (const auto& [name, v] : names)
        if (v == value) return name;
    return names.front().first;
}

/** Calls visit(key, member) for every plain key and visit(key, member, names) for every choice
 * key of `o` (a FillOptions or a const one): the one list of keys that read and write share. */
template <class Options, class Visit>
void visitKeys(Options& o, Visit&& visit) {
    visit("fill_enabled", o.enabled);
    visit("fill_median_window", o.medianWindow_cells);
    visit("fill_median_min_known", o.medianMinKnown);
    visit("fill_gaussian", o.gaussianEnabled);
    visit("fill_max_gap_cells", o.maxGapCells);
    visit("fill_support_margin", o.supportMargin_cells);
    visit("fill_max_training_points", o.maxTrainingPoints);
    visit("fill_residual_correction", o.residualCorrection);
    visit("fill_residual_model", o.residualModel, kResidualModels);
    visit("fill_kriging_covariance", o.krigingCovariance, kCovarianceFamilies);
    visit("fill_terms_outside_gap", o.termsOutsideGap);
    visit("fill_kriging_max_points", o.krigingMaxPoints);
    visit("fill_moving_rim_check", o.movingRimCheck);
    visit("fill_kriging_neighbourhood", o.krigingNeighbourhood, kNeighbourhoods);
    visit("fill_model_averaging", o.modelAveraging);
    visit("fill_extrapolation_margin", o.extrapolationMargin);
    visit("fill_model_criterion", o.criterion, kCriteria);
    visit("fill_max_terms", o.maxTerms);
    visit("fill_min_width", o.minWidth_cells);
    visit("fill_pso_particles", o.swarmParticles);
    visit("fill_pso_iterations", o.swarmIterations);
    visit("fill_pso_seed", o.swarmSeed);
    visit("fill_sigma_model", o.sigmaModel, kSigmaModels);
    visit("fill_median_sigma_gain", o.medianSigmaGain);
    visit("fill_gaussian_sigma_gain", o.gaussianSigmaGain);
    visit("fill_harmonic_sigma_gain", o.harmonicSigmaGain);
    visit("fill_sigma_floor", o.sigmaFloor_m);
}

struct KeyReader {
    StrictConfigSection& s;
    template <class T>
    void operator()(const char* key, T& value) const {
        s.read(key, value);
    }
    template <class T>
    void operator()(const char* key, T& value, const Names<T>& names) const {
        s.readChoice(key, value, names);
    }
};

struct KeyWriter {
    mrpt::config::CConfigFileBase& c;
    const std::string& section;
    template <class T>
    void operator()(const char* key, const T& value) const {
        if constexpr (std::is_same_v<T, unsigned>)
            c.write(section, key, int(value));
        else
            c.write(section, key, value);
    }
    template <class T>
    void operator()(const char* key, const T& value, const Names<T>& names) const {
        c.write(section, key, nameOf(names, value));
    }
};
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
    visitKeys(*this, KeyReader{s});
    validate();
}

void FillOptions::loadFromConfigFile(const mrpt::config::CConfigFileBase& source,
                                     const std::string& section) {
    StrictConfigSection s(source, section);
    read(s);
    s.finish();
}

void FillOptions::write(mrpt::config::CConfigFileBase& c, const std::string& section) const {
    visitKeys(*this, KeyWriter{c, section});
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
    if (!(harmonicSigmaGain >= 0) || !std::isfinite(harmonicSigmaGain))
        bad("fill_harmonic_sigma_gain", "must be >= 0");
    if (!(sigmaFloor_m >= 0) || !std::isfinite(sigmaFloor_m))
        bad("fill_sigma_floor", "must be >= 0 [m]");
}

}  // namespace multibin::fill
