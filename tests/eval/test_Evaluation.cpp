/* Evaluation against ground truth: eq 17 (PI) on hand-computed cases, truth on the lattice,
 * raw map, report.json. */
#include <gtest/gtest.h>
#include <mrpt/containers/yaml.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "multibin/eval/Evaluation.h"
#include "multibin/io/RasterExport.h"

using namespace multibin::eval;
using multibin::Lattice;

namespace {
CellArray array2x2(float a, float b, float c, float d) {
    CellArray x(2, 2);
    x << a, b, c, d;
    return x;
}
}  // namespace

TEST(Evaluation, PerformanceIndexMatchesHandComputedCase) {
    const CellArray truth = array2x2(0.10f, 0.20f, 0.30f, 0.40f);
    // Method: errors 0.01, -0.02 on two cells, two cells unknown -> MSE = (1e-4 + 4e-4) / 2.
    const CellArray method = array2x2(0.11f, 0.18f, NAN, NAN);
    // Raw: errors 0.03, 0.04, 0, -0.05 -> MSE = (9 + 16 + 0 + 25) e-4 / 4 = 12.5e-4.
    const CellArray raw = array2x2(0.13f, 0.24f, 0.30f, 0.35f);
    const SquaredError em = meanSquaredError(method, truth), er = meanSquaredError(raw, truth);
    EXPECT_EQ(em.cells, 2u);
    EXPECT_EQ(er.cells, 4u);
    EXPECT_NEAR(em.mse_m2, 2.5e-4, 1e-9);
    EXPECT_NEAR(er.mse_m2, 12.5e-4, 1e-9);
    EXPECT_NEAR(performanceIndex(em, er), 0.2, 1e-5);

    std::vector<MethodEstimate> methods{{"raw", raw, {}, "raw", 0, 0},
                                        {"method", method, {}, "raw", 0, 0}};
    const auto scores = scoreMethods(truth, methods);
    EXPECT_NEAR(scores.at("method").pi, 0.2, 1e-5);
    EXPECT_NEAR(scores.at("raw").pi, 1.0, 1e-12);
    // Shared cells: only the first two; raw MSE there = (9 + 16) e-4 / 2.
    EXPECT_NEAR(scores.at("method").piShared, 2.5 / 12.5, 1e-5);
    EXPECT_NEAR(scores.at("method").coverage, 0.5, 1e-12);
    EXPECT_NEAR(scores.at("method").rmse_m, std::sqrt(2.5e-4), 1e-7);
    EXPECT_FALSE(scores.at("method").within3Sigma.has_value());
}

TEST(Evaluation, Within3SigmaCountsCellsInsideTheBand) {
    const CellArray truth = array2x2(0, 0, 0, 0);
    MethodEstimate m{
        "m", array2x2(0.029f, -0.031f, 0.01f, NAN), array2x2(0.01f, 0.01f, 0.01f, 1), "m", 0, 0};
    const auto scores = scoreMethods(truth, {m});
    ASSERT_TRUE(scores.at("m").within3Sigma.has_value());
    EXPECT_NEAR(*scores.at("m").within3Sigma, 2.0 / 3.0, 1e-12);
}

TEST(Evaluation, Within3SigmaOverFilledOnlyCellsLeavesTheMeasuredOnesOut) {
    const CellArray truth = array2x2(0, 0, 0, 0);
    // Cells 0 and 1 measured (in the twin), 2 and 3 filled: of those, cell 2 misses its band.
    MethodEstimate measured{"measured", array2x2(0.029f, -0.031f, NAN, NAN), {}, "measured", 0, 0};
    MethodEstimate filled{"filled",
                          array2x2(0.029f, -0.031f, 0.05f, 0.01f),
                          array2x2(0.01f, 0.01f, 0.01f, 0.01f),
                          "measured",
                          0,
                          0};
    filled.filledFrom = "measured";
    const auto scores = scoreMethods(truth, {measured, filled});
    ASSERT_TRUE(scores.at("filled").within3SigmaFilledOnly.has_value());
    EXPECT_EQ(scores.at("filled").filledOnlyCells, 2u);
    EXPECT_NEAR(*scores.at("filled").within3SigmaFilledOnly, 0.5, 1e-12);
    EXPECT_NEAR(*scores.at("filled").within3Sigma, 0.5, 1e-12);
    EXPECT_FALSE(scores.at("measured").within3SigmaFilledOnly.has_value());
}

TEST(Evaluation, UnknownBaselineIsRefused) {
    const CellArray truth = array2x2(0, 0, 0, 0);
    EXPECT_THROW(scoreMethods(truth, {{"m", truth, {}, "nope", 0, 0}}), std::invalid_argument);
}

TEST(Evaluation, GroundTruthCellIsTheMeanOfItsSamples) {
    // 4 x 4 samples of 1 cm starting at the cell centre (0.005, 0.005): 2 x 2 samples per 2 cm
    // cell; heights = column index in mm.
    multibin::EsriAsciiGrid gt;
    gt.cellsize_m = 0.01;
    gt.xllcenter_m = 0.005;
    gt.yllcenter_m = 0.005;
    gt.heights_m.resize(4, 4);
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++) gt.heights_m(r, c) = 0.001f * float(c);
    Lattice L;
    const CellArray truth = groundTruthOnLattice(gt, 0.02, L);
    EXPECT_EQ(L.window.ix0, 0);
    EXPECT_EQ(L.window.iy0, 0);
    ASSERT_EQ(L.window.nx, 2);
    ASSERT_EQ(L.window.ny, 2);
    EXPECT_NEAR(truth(0, 0), 0.0005, 1e-7);  // mean of columns 0 and 1
    EXPECT_NEAR(truth(1, 1), 0.0025, 1e-7);  // mean of columns 2 and 3

    RawPointGrid raw(L);
    raw.addPoint(0.01, 0.01, 0.1);
    raw.addPoint(0.015, 0.019, 0.2);
    raw.addPoint(0.03, 0.03, 0.5);
    raw.addPoint(5.0, 0.0, 9.0);  // outside: ignored
    const CellArray h = raw.heights_m();
    EXPECT_NEAR(h(0, 0), 0.15, 1e-6);
    EXPECT_NEAR(h(1, 1), 0.5, 1e-6);
    EXPECT_TRUE(std::isnan(h(0, 1)));
}

TEST(Evaluation, ReportJsonHasTheDocumentedFields) {
    const CellArray truth = array2x2(0.1f, 0.2f, 0.3f, 0.4f);
    std::vector<MethodEstimate> methods{
        {"raw_all", array2x2(0.12f, 0.2f, 0.3f, 0.4f), {}, "raw_all", 0.5, 0},
        {"multibin", array2x2(0.11f, 0.2f, 0.3f, NAN), array2x2(0.01f, 0.01f, 0.01f, 0), "raw_all",
         1.5, 0.25}};
    const auto scores = scoreMethods(truth, methods);
    Lattice L;
    L.cellSize_m = 0.02;
    L.window.nx = L.window.ny = 2;
    const std::string json = reportJson(scores, {"raw_all", "multibin"}, L);
    const auto doc = mrpt::containers::yaml::FromText(json);
    const auto& mb = doc["methods"]["multibin"];
    EXPECT_NEAR(mb["rmse_m"].as<double>(), std::sqrt(1e-4 / 3), 1e-6);
    EXPECT_NEAR(mb["pi"].as<double>(), (1e-4 / 3) / (4e-4 / 4), 1e-4);
    EXPECT_NEAR(mb["coverage"].as<double>(), 0.75, 1e-12);
    EXPECT_NEAR(mb["within_3sigma"].as<double>(), 1.0, 1e-12);
    EXPECT_NEAR(mb["insert_s"].as<double>(), 1.5, 1e-12);
    EXPECT_NEAR(mb["fill_s"].as<double>(), 0.25, 1e-12);
    EXPECT_TRUE(doc["methods"]["raw_all"]["within_3sigma"].isNullNode());
    EXPECT_NEAR(doc["cell_size_m"].as<double>(), 0.02, 1e-12);
    EXPECT_EQ(doc["area_m"].asSequence().size(), 4u);
}

TEST(Evaluation, AreaScoresCountOnlyTheCellsOfTheSubArea) {
    const CellArray truth = array2x2(0, 0, 0, 0);
    Lattice L;
    L.cellSize_m = 1;
    L.window.nx = L.window.ny = 2;
    Lattice crop = L;
    crop.window.ix0 = 1;  // the right column: cells (r, 1)
    crop.window.nx = 1;
    const std::vector<MethodEstimate> methods{
        {"m", array2x2(0.5f, 0.1f, 0.5f, 0.2f), {}, "m", 0, 0}};
    const AreaScores a = scoreArea("crop", truth, methods, L, crop);
    EXPECT_EQ(a.errors.at("m").cells, 2u);
    EXPECT_NEAR(a.errors.at("m").mse_m2, (0.01 + 0.04) / 2, 1e-7);
    EXPECT_EQ(a.area_m, (std::vector<double>{1, 2, 0, 2}));
}

// Cells of 0.1 m, lattice cells ix -5..14 (x in [-0.5, 1.5)), iy 0..9. An area whose edges fall
// just past cell centres keeps exactly the cells whose centres lie inside it.
TEST(Evaluation, SubLatticeKeepsTheCellsWhoseCentresLieInTheArea) {
    Lattice L;
    L.cellSize_m = 0.1;
    L.window.ix0 = -5;
    L.window.nx = 20;
    L.window.iy0 = 0;
    L.window.ny = 10;
    const Lattice s = subLattice(L, {0.0, 0.34, 0.24, 2.0});
    EXPECT_EQ(s.window.ix0, 0);  // centre 0.05 is the first >= 0.0
    EXPECT_EQ(s.window.nx, 3);   // centres 0.05, 0.15, 0.25 (0.35 > 0.34)
    EXPECT_EQ(s.window.iy0, 2);  // centre 0.25 is the first >= 0.24
    EXPECT_EQ(s.window.ny, 8);   // up to the lattice's last row (iy 9), the area goes beyond it
    EXPECT_DOUBLE_EQ(s.cellSize_m, 0.1);
    EXPECT_THROW(subLattice(L, {2.0, 3.0, 0.0, 1.0}), std::invalid_argument);  // outside
    EXPECT_THROW(subLattice(L, {1.0, 0.0, 0.0, 1.0}), std::invalid_argument);  // xmin > xmax
    EXPECT_THROW(subLattice(L, {0.0, 1.0}), std::invalid_argument);            // two numbers
}

// MRPT's GMRF map is built on a crop only: it must not narrow the cells the whole-area methods
// share, and its own shared PI compares it with its baseline inside its crop.
TEST(Evaluation, ACropOnlyMethodDoesNotNarrowTheSharedCells) {
    const CellArray truth = array2x2(0.10f, 0.20f, 0.30f, 0.40f);
    const CellArray raw = array2x2(0.13f, 0.24f, 0.31f, 0.35f);  // errors .03 .04 .01 -.05
    const CellArray full = array2x2(0.11f, 0.18f, 0.30f, NAN);   // errors .01 -.02 0
    const CellArray crop = array2x2(NAN, NAN, 0.32f, 0.41f);     // errors .02 .01
    MethodEstimate cropOnly{"crop", crop, {}, "raw", 0, 0};
    cropOnly.coversWholeArea = false;
    const auto scores = scoreMethods(
        truth, {{"raw", raw, {}, "raw", 0, 0}, {"full", full, {}, "raw", 0, 0}, cropOnly});
    // Shared by raw and full: cells 0, 1, 2 -> (1 + 4 + 0) / (9 + 16 + 1).
    EXPECT_NEAR(scores.at("full").piShared, 5.0 / 26.0, 1e-5);
    // The crop inside the shared cells: cell 2 only -> 4 / 1.
    EXPECT_NEAR(scores.at("crop").piShared, 4.0, 1e-4);
    // Its PI: over its crop (cells 2, 3) against the raw map over the same cells,
    // (4 + 1) / 2 over (1 + 25) / 2; the whole-area PI of `full` is unchanged, (5 / 3) / (51 / 4).
    EXPECT_NEAR(scores.at("crop").pi, 5.0 / 26.0, 1e-5);
    EXPECT_NEAR(scores.at("full").pi, (5.0 / 3.0) / (51.0 / 4.0), 1e-5);
}
