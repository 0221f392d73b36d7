/* Tests of BinAccumulator, the one home of a bin's update: the sequential form is the per-point
 * rule of BinUpdate.h bit for bit, the information form agrees with it up to rounding, and a merge
 * of two bins is the bin of all their points. */
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "multibin/grid/BinAccumulator.h"

using namespace multibin;

namespace {

struct TestPoint {
    float x_m, y_m;
    double z_m, variance_m2;
    uint8_t heightCode, horizontalCode;
};

std::vector<TestPoint> somePoints(int count, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> xy(-0.05f, 0.05f);
    std::normal_distribution<double> z(0.42, 0.01);
    std::uniform_real_distribution<double> sigma(0.002, 0.02);
    std::vector<TestPoint> points;
    for (int k = 0; k < count; k++) {
        const double s = sigma(rng);
        points.push_back({xy(rng), xy(rng), z(rng), s * s, poseSigmaCode(float(1e-4 * (k + 1))),
                          poseSigmaCode(float(4e-4 * (k + 2)))});
    }
    return points;
}

constexpr double kCellX_m = 0.05, kCellY_m = -0.15;

/** Each point through its own sequential update, as the laser path does. */
BinEstimate sequentially(BinEstimate bin, const std::vector<TestPoint>& points,
                         const BinUpdateParams& params) {
    for (const TestPoint& p : points) {
        BinAccumulator<HeightFusion::kSequential> update;
        update.open(bin, kCellX_m, kCellY_m);
        update.addPoint(p.x_m, p.y_m, p.z_m, p.variance_m2, 1.0 / p.variance_m2, params);
        update.lowerPoseCodes(p.heightCode, p.horizontalCode);
        update.close(bin, params, isExactWholeFloat(params.certaintyIncrement));
    }
    return bin;
}

}  // namespace

TEST(BinAccumulator, SequentialIsThePerPointRule) {
    const BinUpdateParams params;
    const std::vector<TestPoint> points = somePoints(50, 1);
    BinEstimate expected;
    for (const TestPoint& p : points) {
        addMeasurement(expected, p.z_m, p.variance_m2, params);
        addPlanePoint(expected.plane, float(p.x_m - kCellX_m), float(p.y_m - kCellY_m),
                      float(p.z_m), float(1.0 / p.variance_m2));
        lowerPoseSigmaCodes(expected, p.heightCode, p.horizontalCode);
    }
    const BinEstimate got = sequentially(BinEstimate{}, points, params);
    static_assert(sizeof(BinEstimate) == 60, "no padding: memcmp compares every field");
    EXPECT_EQ(std::memcmp(&got, &expected, sizeof got), 0);  // every field, bit for bit
}

TEST(BinAccumulator, InformationFormAgreesWithSequential) {
    BinUpdateParams params;
    params.certaintyIncrement = 0.75f;
    const std::vector<TestPoint> points = somePoints(40, 2);
    BinEstimate start;  // a bin that already holds points
    start = sequentially(start, somePoints(5, 3), params);
    const BinEstimate seq = sequentially(start, points, params);

    BinEstimate run = start;
    BinAccumulator<HeightFusion::kInformation> update;
    update.open(run, kCellX_m, kCellY_m);
    update.lowerPoseCodes(points[0].heightCode, points[0].horizontalCode);
    double maxHeight_m = -INFINITY;
    for (const TestPoint& p : points) {
        update.addPoint(p.x_m, p.y_m, p.z_m, p.variance_m2, 1.0 / p.variance_m2, params);
        maxHeight_m = std::max(maxHeight_m, p.z_m);
    }
    update.close(run, params, isExactWholeFloat(params.certaintyIncrement));
    EXPECT_EQ(update.points(), points.size());
    EXPECT_EQ(update.maxHeight_m(), maxHeight_m);
    EXPECT_NEAR(run.height_m, seq.height_m, 1e-6);
    EXPECT_NEAR(run.variance_m2, seq.variance_m2, 1e-6 * seq.variance_m2);
    EXPECT_EQ(run.certainty, seq.certainty);  // addCertainty: the sequence's sum, bit for bit
    EXPECT_EQ(run.pointCount, seq.pointCount);
    EXPECT_EQ(run.plane.sxz, seq.plane.sxz);  // the same centred updates in the same order
}

TEST(BinAccumulator, FrozenBinKeepsItsHeight) {
    const BinUpdateParams params;
    BinEstimate exact;
    exact.height_m = 1.25f;
    exact.variance_m2 = 0;  // an exact height
    exact.pointCount = 3;
    BinAccumulator<HeightFusion::kInformation> update;
    update.open(exact, 0, 0);
    update.addPoint(0, 0, 1.3, 1e-4, 1e4, params);
    update.close(exact, params, true);
    EXPECT_EQ(exact.height_m, 1.25f);
    EXPECT_EQ(exact.variance_m2, 0.0f);
    EXPECT_EQ(exact.pointCount, 4u);
}

TEST(BinAccumulator, MergeIsTheBinOfAllPoints) {
    const BinUpdateParams params;
    const std::vector<TestPoint> all = somePoints(60, 4);
    const std::vector<TestPoint> first(all.begin(), all.begin() + 30),
        second(all.begin() + 30, all.end());
    const BinEstimate together = sequentially(BinEstimate{}, all, params);
    BinEstimate merged = sequentially(BinEstimate{}, first, params);
    const BinEstimate other = sequentially(BinEstimate{}, second, params);
    BinAccumulator<HeightFusion::kSequential> update;
    update.open(merged, kCellX_m, kCellY_m);
    update.merge(other);
    update.close(merged, params, true);
    EXPECT_NEAR(merged.height_m, together.height_m, 1e-5);
    EXPECT_NEAR(merged.variance_m2, together.variance_m2, 1e-5 * together.variance_m2);
    EXPECT_EQ(merged.certainty, together.certainty);
    EXPECT_EQ(merged.pointCount, together.pointCount);
    EXPECT_EQ(merged.poseHeightSigmaCode, together.poseHeightSigmaCode);
    EXPECT_NEAR(merged.plane.sxx, together.plane.sxx, 1e-4 * together.plane.sxx);
}
