/* Terrain of terrain-sim: tiling, bilinear heights, exact ray casting, ground truth. */
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "Terrain.h"
#include "sim_fixtures.h"

using terrain_sim::Terrain;

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
}

// A tilted plane is reproduced exactly by bilinear patches, so every hit must match the
// analytic ray-plane intersection, whatever the number of cells and blocks the ray crosses.
TEST(TerrainRayCast, PlaneExactHit) {
    const double a = 0.1, b = 0.2, c = -0.1, cell = 0.01, x0 = -0.3, y0 = -0.2;
    Eigen::MatrixXf h(81, 101);
    for (int r = 0; r < h.rows(); ++r)
        for (int k = 0; k < h.cols(); ++k) h(r, k) = a + b * (x0 + k * cell) + c * (y0 + r * cell);
    // float samples: compare against the plane through the stored values' tilt, from float data
    const Terrain t = Terrain::fromSamples(h, x0, y0, cell);
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> ux(-0.25, 0.65), uy(-0.15, 0.55), ua(-M_PI, M_PI),
        ue(0.05, 1.5);
    int tested = 0;
    for (int i = 0; i < 2000; ++i) {
        const Eigen::Vector3d o(ux(rng), uy(rng), 0.5);
        const double az = ua(rng), el = ue(rng);
        const Eigen::Vector3d d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az),
                                -std::sin(el));
        // Analytic: o.z + s d.z = a + b (o.x + s d.x) + c (o.y + s d.y)
        const double s = (a + b * o.x() + c * o.y() - o.z()) / (d.z() - b * d.x() - c * d.y());
        const Eigen::Vector3d p = o + s * d;
        if (p.x() < x0 + 0.01 || p.x() > x0 + 0.99 || p.y() < y0 + 0.01 || p.y() > y0 + 0.79)
            continue;  // beyond the lattice the ground is z = 0, not this plane
        const double got = t.castRay(o, d, 10.0);
        ASSERT_NEAR(got, s, 2e-6) << "ray " << i;  // float samples: ~1e-7 m height error
        ++tested;
    }
    EXPECT_GT(tested, 500);
}

// A step of 0.05 m between samples x = 0.10 and x = 0.11 (one cell of bilinear ramp).
TEST(TerrainRayCast, StepExactHit) {
    const double cell = 0.01, x0 = -0.3, y0 = -0.2, hs = 0.05;
    Eigen::MatrixXf h = Eigen::MatrixXf::Zero(41, 81);
    for (int k = 0; k < h.cols(); ++k)
        if (x0 + k * cell > 0.1 + 1e-9) h.col(k).setConstant(hs);
    const Terrain t = Terrain::fromSamples(h, x0, y0, cell);
    // Vertical rays on both levels.
    EXPECT_NEAR(t.castRay({0.05, 0.0, 0.3}, {0, 0, -1}, 1.0), 0.3, 1e-12);
    EXPECT_NEAR(t.castRay({0.2, 0.0, 0.3}, {0, 0, -1}, 1.0), 0.3 - hs, 1e-7);
    // Horizontal ray at z = 0.02 hits the ramp where 5 (x - 0.1) = 0.02.
    EXPECT_NEAR(t.castRay({-0.2, 0.0, 0.02}, {1, 0, 0}, 1.0), 0.104 + 0.2, 1e-7);
    // Descending onto the top face from +x.
    {
        const Eigen::Vector3d d = Eigen::Vector3d(-1, 0, -0.5).normalized();
        EXPECT_NEAR(t.castRay({0.3, 0.0, 0.1}, d, 1.0), 0.1 * std::sqrt(1.25), 1e-7);
    }
    // Descending from -x: passes over the low floor and hits the ramp face at
    // 0.1 - 0.3 (x + 0.2) = 5 (x - 0.1)  ->  x = 0.54 / 5.3.
    {
        const Eigen::Vector3d d = Eigen::Vector3d(1, 0, -0.3).normalized();
        const double x = 0.54 / 5.3;
        EXPECT_NEAR(t.castRay({-0.2, 0.0, 0.1}, d, 1.0), (x + 0.2) * std::sqrt(1.09), 1e-7);
    }
    // Out of range, and pointing up: no hit.
    EXPECT_EQ(t.castRay({0.05, 0.0, 0.3}, {0, 0, -1}, 0.2), kInf);
    EXPECT_EQ(t.castRay({0.05, 0.0, 0.3}, {0, 0, 1}, 5.0), kInf);
    // Beyond the lattice the ground is the plane z = 0.
    const Eigen::Vector3d d = Eigen::Vector3d(-1, 0, -1).normalized();
    EXPECT_NEAR(t.castRay({-0.5, 0.0, 0.2}, d, 1.0), 0.2 * std::sqrt(2.0), 1e-12);
}

TEST(Terrain, TilesCycleBoardsWithFlatGroundAround) {
    const auto A = sim_test::flatBoard(11, 0.01, 0.1), B = sim_test::flatBoard(11, 0.01, 0.2);
    const Terrain t = Terrain::fromBoards({A, B}, 3, 1, 0.05);
    EXPECT_NEAR(t.tileSide_m(), 0.1, 1e-12);
    EXPECT_NEAR(t.height(0.05, 0.0), 0.1, 1e-6);  // tile 0 = A
    EXPECT_NEAR(t.height(0.15, 0.0), 0.2, 1e-6);  // tile 1 = B
    EXPECT_NEAR(t.height(0.25, 0.0), 0.1, 1e-6);  // tile 2 = A again
    EXPECT_EQ(t.height(-0.03, 0.0), 0.0);         // stored flat margin
    EXPECT_EQ(t.height(2.0, 1.0), 0.0);           // analytic ground
    EXPECT_EQ(t.surfaceId(0.05, 0.0), 1);
    EXPECT_EQ(t.surfaceId(0.25, 0.02), 3);
    EXPECT_EQ(t.surfaceId(0.35, 0.0), 0);
    EXPECT_NEAR(t.meanTileHeight_m(), (2 * 0.1 * 10 + 0.2 * 10 + 0.1) / 31.0, 1e-6);
}

TEST(Terrain, BilinearHeightBetweenSamples) {
    Eigen::MatrixXf h(2, 2);
    h << 0.0f, 0.1f,  // row 0 (y = 0): x = 0, x = 1
        0.2f, 0.7f;   // row 1 (y = 1)
    const Terrain t = Terrain::fromSamples(h, 0, 0, 1.0);
    EXPECT_NEAR(t.height(0.5, 0.5), 0.25, 1e-7);
    EXPECT_NEAR(t.height(0.25, 0.0), 0.025, 1e-7);
    EXPECT_NEAR(t.height(1.0, 1.0), 0.7, 1e-7);
}

TEST(Terrain, GroundTruthIsTheMeanOfTheSamplesInsideEachCell) {
    // Samples every 0.01 m from x = y = 0; heights x + 10 y. A 0.05 m cell [0, 0.05)^2 holds the
    // samples 0 .. 4 in each direction: mean x = 0.02, mean y = 0.02 -> 0.02 + 0.2.
    Eigen::MatrixXf h(21, 21);
    for (int r = 0; r < 21; ++r)
        for (int k = 0; k < 21; ++k) h(r, k) = static_cast<float>(0.01 * k + 0.1 * r);
    const Terrain t = Terrain::fromSamples(h, 0, 0, 0.01);
    const auto g = t.groundTruth(0.05);
    ASSERT_EQ(g.cols(), 4);
    ASSERT_EQ(g.rows(), 4);
    EXPECT_NEAR(g.xllcenter_m, 0.025, 1e-12);
    EXPECT_NEAR(g.heights_m(0, 0), 0.02 + 0.2, 1e-6);
    EXPECT_NEAR(g.heights_m(1, 2), 0.12 + 0.7, 1e-6);  // x in [0.10, 0.15), y in [0.05, 0.10)
}
