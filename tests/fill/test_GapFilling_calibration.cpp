/* Calibration of the sigma of filled cells on the shared LittleDog boards: gaps placed where
 * the calibration (compare_fill calibrate, seed 1) never looked (seed 2), >= 95 % of filled
 * cells must hold the true height within 3 sigma. Figures: doc/gap-filling.md. */
#include <gtest/gtest.h>

#include "FillTestData.h"
#include "multibin/fill/GapFilling.h"

using multibin::HeightSource;
using namespace multibin::fill;
using namespace multibin::filltest;

namespace {
const std::vector<Board>& boards() { return boardsAt15mm(MULTIBIN_REFERENCE_DATA_DIR); }

struct Coverage {
    int n = 0, in3 = 0, in1 = 0;
    double frac3() const { return double(in3) / n; }
    double frac1() const { return double(in1) / n; }
};

void add(const FillResult& f, const GapCase& c, HeightSource kind, Coverage& cov) {
    for (int iy = 0; iy < f.ny(); iy++)
        for (int ix = 0; ix < f.nx(); ix++) {
            const size_t k = f.index(ix, iy);
            if (f.source[k] != kind) continue;
            const double z =
                std::abs(f.height_m[k] - caseTruth(boards(), c, ix, iy)) / f.sigma_m[k];
            cov.n++, cov.in3 += z <= 3, cov.in1 += z <= 1;
        }
}
}  // namespace

TEST(FillCalibration, BoardsResampleToFifteenMillimetreCells) {
    ASSERT_EQ(boards().size(), 6u);
    for (const auto& b : boards()) {
        EXPECT_GE(b.n, kCropOffset + kCropSide) << b.name;  // 0.61-0.66 m board / 15 mm
        for (double h : b.truth_m) EXPECT_TRUE(std::isfinite(h));
    }
    // Cell (0, 0) of board B is the mean of the samples whose centres lie below 15 mm in x and
    // y: (c + 0.5) * 1.191406 mm < 15 mm for c = 0..12, a 13 x 13 block.
    const auto g =
        multibin::EsriAsciiGrid::load(MULTIBIN_REFERENCE_DATA_DIR "/terrain/littledog/B.asc");
    EXPECT_NEAR(boards()[0].at(0, 0), g.heights_m.block(0, 0, 13, 13).cast<double>().mean(), 1e-9);
    EXPECT_EQ(boards()[0].n, int(513 * g.cellsize_m / 0.015));
}

TEST(FillCalibration, GaussianFilledCellsWithinThreeSigma) {
    Coverage paper, calibrated;
    FillOptions paperOpt;
    paperOpt.sigmaModel = FillSigmaModel::Paper;
    for (int size : {6, 10, 14, 18}) {
        Coverage perSize;
        for (const auto& c : makeGapCases(int(boards().size()), {size}, 2, 4, 2)) {
            const auto r = caseRaster(boards(), c);
            const auto f = fillGaps(r, FillOptions{});
            add(f, c, HeightSource::FilledSurface, perSize);
            add(f, c, HeightSource::FilledSurface, calibrated);
            add(fillGaps(r, paperOpt), c, HeightSource::FilledSurface, paper);
        }
        ASSERT_EQ(perSize.n, 6 * 2 * size * size);  // every hidden cell filled by eq 16
        EXPECT_GE(perSize.frac3(), 0.95) << "gap side " << size;
    }
    EXPECT_GE(calibrated.frac3(), 0.95);
    EXPECT_GE(calibrated.frac1(), 0.60);  // not simply inflated: about a normal 1-sigma share
    EXPECT_LT(paper.frac3(), 0.8);        // the paper's neighbour-average sigma is far too small
}

TEST(FillCalibration, MedianFilledCellsWithinThreeSigma) {
    Coverage cov;
    std::mt19937 rng(2);
    for (size_t b = 0; b < boards().size(); b++)
        for (int size : {1, 2, 3}) {
            GapCase c;
            c.board = int(b);
            c.noiseSeed = unsigned(rng());
            auto r = caseRaster(boards(), c);  // size 0: nothing hidden yet
            std::uniform_int_distribution<int> pos(0, kCropSide - size);
            for (int h = 0; h < 25; h++) hideBox(r, pos(rng), pos(rng), size, size);
            add(fillGaps(r, FillOptions{}), c, HeightSource::FilledMedian, cov);
        }
    ASSERT_GT(cov.n, 500);
    EXPECT_GE(cov.frac3(), 0.95);
    EXPECT_GE(cov.frac1(), 0.60);
}
