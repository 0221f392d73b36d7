/* The fill options (FillOptions.h): ini round trip and strict errors. */
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFileMemory.h>

#include <stdexcept>
#include <string>

#include "multibin/fill/FillOptions.h"
#include "multibin/io/StrictConfigSection.h"

using namespace multibin::fill;

TEST(FillOptions, IniRoundTripAndStrictErrors) {
    FillOptions a;
    a.enabled = false;
    a.medianWindow_cells = 7;
    a.maxGapCells = 1234;
    a.sigmaModel = FillSigmaModel::Paper;
    a.gaussianSigmaGain = 1.25;
    a.swarmSeed = 42;
    a.residualCorrection = false;
    a.criterion = ModelCriterion::Holdout;
    a.residualModel = ResidualModel::Harmonic;
    a.krigingCovariance = CovarianceFamily::Exponential;
    a.termsOutsideGap = false;
    a.krigingMaxPoints = 321;
    a.krigingNeighbourhood = KrigingNeighbourhood::Moving;
    a.movingRimCheck = false;
    a.modelAveraging = false;
    mrpt::config::CConfigFileMemory ini;
    a.write(ini, "insertOpts");
    FillOptions b;
    b.loadFromConfigFile(ini, "insertOpts");
    EXPECT_EQ(b.enabled, false);
    EXPECT_EQ(b.medianWindow_cells, 7);
    EXPECT_EQ(b.maxGapCells, 1234);
    EXPECT_EQ(b.sigmaModel, FillSigmaModel::Paper);
    EXPECT_DOUBLE_EQ(b.gaussianSigmaGain, 1.25);
    EXPECT_EQ(b.swarmSeed, 42u);
    EXPECT_FALSE(b.residualCorrection);
    EXPECT_EQ(b.criterion, ModelCriterion::Holdout);
    EXPECT_EQ(b.residualModel, ResidualModel::Harmonic);
    EXPECT_EQ(b.krigingCovariance, CovarianceFamily::Exponential);
    EXPECT_FALSE(b.termsOutsideGap);
    EXPECT_EQ(b.krigingMaxPoints, 321);
    EXPECT_EQ(b.krigingNeighbourhood, KrigingNeighbourhood::Moving);
    EXPECT_FALSE(b.movingRimCheck);
    EXPECT_FALSE(b.modelAveraging);

    // Keys shared with the map's own section: the caller's strict reader owns finish().
    mrpt::config::CConfigFileMemory shared;
    shared.write("s", "fill_median_window_cells", 3);
    shared.write("s", "certainty_increment", 1.0);
    multibin::StrictConfigSection sec(shared, "s");
    FillOptions c;
    c.read(sec);
    EXPECT_EQ(c.medianWindow_cells, 3);
    EXPECT_THROW(sec.finish(), std::invalid_argument);  // certainty_increment was not read here

    auto expectError = [](const std::string& key, const std::string& value) {
        mrpt::config::CConfigFileMemory m;
        m.write("s", key, value);
        FillOptions o;
        try {
            o.loadFromConfigFile(m, "s");
            ADD_FAILURE() << key << " = " << value << " accepted";
        } catch (const std::invalid_argument& e) {
            EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
        }
    };
    expectError("fill_median_window_cells", "4");
    expectError("fill_median_window_cells", "five");
    expectError("fill_sigma_model", "bayes");
    expectError("fill_model_criterion", "cv");
    expectError("fill_max_gap_cells", "0");
    expectError("fill_residual_model", "spline");
    expectError("fill_kriging_covariance", "gaussian");
    expectError("fill_kriging_max_points", "5");
    expectError("fill_kriging_neighbourhood", "global");
    expectError("fill_medain_window", "5");  // typo: unknown key
}
