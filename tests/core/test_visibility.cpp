/* Tests of the visibility constraint: stale heights are removed, consistent ones kept. */
#include <gtest/gtest.h>
#include <mrpt/maps/CMultiBinElevationMap.h>

#include "multibin/VisibilityConstraint.h"
#include "test_scenes.h"

using namespace multibin;

namespace {
PointWithCov pointAt(double x, double y, double z, double sigmaZ_m) {
    PointWithCov p;
    p.point_m = Eigen::Vector3f(float(x), float(y), float(z));
    p.cov_m2 = {1e-6f, 0, 0, 1e-6f, 0, float(sigmaZ_m * sigmaZ_m)};
    return p;
}
}  // namespace

TEST(Visibility, StaleOccluderLessCertainThanTheTargetIsRemoved) {
    BinGrid g(0.1);
    g.reset(0.1, CellWindow{-5, -5, 30, 10});
    BinUpdateParams p;
    VisibilityParams v;
    // A stale 0.35 m reading at x = 1.05 (certainty 1) and a 0 m target at x = 2.05.
    g.beginCycle();
    g.insertPoints({pointAt(1.05, 0.05, 0.35, 0.005)}, p);
    // Sensor at (0, 0, 0.5): the line of sight to (2.05, 0) passes x = 1.05 at about 0.25 m, below
    // the stale 0.35 m: it must go once the target is more certain.
    g.beginCycle();
    g.insertPoints({pointAt(2.05, 0.05, 0.0, 0.005), pointAt(2.05, 0.05, 0.0, 0.005)}, p);
    const VisibilityStats s = applyVisibilityConstraint(g, {0.05, 0.05, 0.5}, v, p);
    EXPECT_EQ(s.raysCast, 1u);
    EXPECT_EQ(s.binsRemoved, 1u);
    EXPECT_EQ(g.winningBin(10, 0), nullptr);
    ASSERT_NE(g.winningBin(20, 0), nullptr);
}

TEST(Visibility, MoreCertainOccluderOnlyLosesCertainty) {
    BinGrid g(0.1);
    g.reset(0.1, CellWindow{-5, -5, 30, 10});
    BinUpdateParams p;
    VisibilityParams v;
    g.beginCycle();
    for (int i = 0; i < 5; i++) g.insertPoints({pointAt(1.05, 0.05, 0.30, 0.005)}, p);
    g.beginCycle();
    g.insertPoints({pointAt(2.05, 0.05, 0.0, 0.005)}, p);
    const VisibilityStats s = applyVisibilityConstraint(g, {0.05, 0.05, 0.5}, v, p);
    EXPECT_EQ(s.binsRemoved, 0u);
    EXPECT_EQ(s.binsWeakened, 1u);
    ASSERT_NE(g.winningBin(10, 0), nullptr);
    EXPECT_FLOAT_EQ(g.winningBin(10, 0)->certainty, 4.f);
}

TEST(Visibility, ConsistentTerrainIsUntouched) {
    BinGrid g(0.1);
    g.reset(0.1, CellWindow{-5, -5, 30, 10});
    BinUpdateParams p;
    VisibilityParams v;
    // A slope rising away from the sensor: every cell is visible, nothing is stale.
    g.beginCycle();
    for (int i = 3; i < 20; i++)
        g.insertPoints({pointAt(0.1 * i + 0.05, 0.05, 0.01 * i, 0.005)}, p);
    g.beginCycle();
    g.insertPoints({pointAt(2.05, 0.05, 0.2, 0.005)}, p);
    // Sensor 0.25 m up: the line of sight runs low over the slope for a while.
    const VisibilityStats s = applyVisibilityConstraint(g, {0.05, 0.05, 0.25}, v, p);
    EXPECT_EQ(s.binsRemoved + s.binsWeakened, 0u);
    EXPECT_GT(s.cellsVisited, 5u);
}

TEST(Visibility, UpdatedCellBinAboveTheNewMeasurementsLosesCertainty) {
    BinGrid g(0.1);
    g.reset(0.1, CellWindow{-5, -5, 30, 10});
    BinUpdateParams p;
    VisibilityParams v;
    g.beginCycle();
    g.insertPoints({pointAt(1.05, 0.05, 0.30, 0.005), pointAt(1.05, 0.05, 0.30, 0.005)}, p);
    for (int cycle = 0; cycle < 2; cycle++) {
        g.beginCycle();
        g.insertPoints({pointAt(1.05, 0.05, 0.0, 0.005)}, p);
        applyVisibilityConstraint(g, {0.05, 0.05, 0.5}, v, p);
    }
    // The 0.3 m bin lost 1 per contradicting point and vanished after two; the ground bin wins.
    size_t bins = 0;
    g.forEachBin(10, 0, [&](const Bin&) { bins++; });
    EXPECT_EQ(bins, 1u);
    EXPECT_NEAR(g.winningBin(10, 0)->height_m, 0.0, 1e-6);
}

namespace {
struct BoxTerrain {
    bool boxPresent = true;
    double operator()(double x, double y) const {
        const double ground = 0.01 * std::sin(3 * x) * std::cos(2 * y);
        const bool inBox = x > 0.60 && x < 0.75 && y > -0.10 && y < 0.10;
        return boxPresent && inBox ? 0.12 : ground;
    }
};

/** Drives the pitched laser from x = -0.3 to 0.9 in 10 mm steps. */
void drive(mrpt::maps::CMultiBinElevationMap& map, const BoxTerrain& terrain) {
    mrpt::poses::CPose3DPDFGaussian pose;
    pose.cov.setIdentity();
    pose.cov *= 1e-8;
    for (double x = -0.3; x <= 0.9; x += 0.01) {
        pose.mean = mrpt::poses::CPose3D(x, 0, 0, 0, 0, 0);
        map.insertObservation(
            *test_scenes::pitchedScanOver(terrain, pose.mean, 0.26, mrpt::DEG2RAD(45.0)), pose);
    }
}
}  // namespace

TEST(Visibility, MovedObjectIsForgottenAndItsSurroundingsKept) {
    mrpt::maps::CMultiBinElevationMap::TCreationOptions c;
    c.resolution_m = 0.015;
    BoxTerrain terrain;
    for (const bool constraint : {true, false}) {
        mrpt::maps::CMultiBinElevationMap map(c);
        map.insertionOptions.visibility.enabled = constraint;
        terrain.boxPresent = true;
        drive(map, terrain);
        double h, s;
        ASSERT_TRUE(map.getHeight(0.70, 0.0, h, s));
        EXPECT_NEAR(h, 0.12, 0.01) << "the box is mapped in the first pass";
        terrain.boxPresent = false;
        drive(map, terrain);
        // Inside the old footprint and around it: height within 2 sigma of the true ground.
        size_t cells = 0, within2Sigma = 0, around = 0, aroundOk = 0;
        for (double x = 0.55; x < 0.80; x += 0.015)
            for (double y = -0.15; y < 0.15; y += 0.015) {
                if (!map.getHeight(x, y, h, s)) continue;
                const double truth = terrain(x, y);
                // Cells wholly inside the box's footprint. The cells its faces cross also
                // fused face points into their ground bin; see doc/visibility.md.
                const bool onFaces = (x > 0.585 && x < 0.615) || (x > 0.735 && x < 0.765) ||
                                     std::abs(std::abs(y) - 0.10) < 0.015;
                const bool inFootprint = x > 0.615 && x < 0.735 && std::abs(y) < 0.085;
                if (onFaces) continue;
                const bool ok = std::abs(h - truth) <= 2 * s + 0.003;  // + within-cell relief
                if (inFootprint) {
                    cells++;
                    within2Sigma += ok;
                } else {
                    around++;
                    aroundOk += ok;
                }
            }
        if (constraint) {
            EXPECT_GT(cells, 50u);
            EXPECT_EQ(within2Sigma, cells) << "footprint cells back on the ground";
            EXPECT_GE(double(aroundOk), 0.95 * double(around)) << "surroundings unharmed";
            EXPECT_GT(map.visibilityStats().binsRemoved + map.visibilityStats().binsWeakened, 0u);
        } else {
            // Without the constraint the box lingers: this is what the constraint fixes.
            EXPECT_LT(within2Sigma, cells);
        }
        std::cout << (constraint ? "with" : "without") << " visibility constraint: " << within2Sigma
                  << " / " << cells << " footprint cells within 2 sigma, " << aroundOk << " / "
                  << around << " around\n";
    }
}
