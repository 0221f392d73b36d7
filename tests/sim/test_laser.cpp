/* Laser of terrain-sim: geometry of the pitched URG-04LX, range noise (chi-square), eq 1
 * intensities and dropouts on dark surfaces, mixed pixels at depth edges. */
#include <gtest/gtest.h>

#include <cmath>

#include "LaserSim.h"
#include "Scenario.h"
#include "sim_fixtures.h"

using namespace terrain_sim;

namespace {
Terrain flatGround() {
    return Terrain::fromSamples(Eigen::MatrixXf::Zero(201, 201), -1.0, -1.0, 0.01);
}
}  // namespace

// The centre beam of a laser 0.26 m up, pitched 45 deg down, meets flat ground 0.26 m ahead.
TEST(LaserSim, PitchedBeamsHitTheGroundAhead) {
    const Terrain t = flatGround();
    const SurfaceTexture tex(t, 1, 0);
    LaserConfig cfg;
    const LaserSim laser(cfg, t, tex, 1);
    std::mt19937_64 rng(1);
    std::vector<BeamTruth> truth;
    const auto scan = laser.scan(mrpt::poses::CPose3D(), syntheticStamp(0), rng, &truth);
    ASSERT_EQ(scan->getScanSize(), 683u);
    EXPECT_TRUE(scan->hasIntensity());
    EXPECT_NEAR(scan->aperture, 240.0 * M_PI / 180.0, 1e-6);
    EXPECT_NEAR(truth[341].trueRange_m, 0.26 * std::sqrt(2.0), 1e-9);
    // Beams pointing above the horizon (|angle| > 90 deg) see nothing.
    EXPECT_FALSE(scan->getScanRangeValidity(0));
    EXPECT_FALSE(scan->getScanRangeValidity(682));
    // Intensity: I = Ires^2 vAGC / 1023, so eq 1 gives back the restored intensity.
    for (int k = 0; k < 683; ++k) {
        if (truth[k].surface < 0) continue;
        const double Ires = std::sqrt(scan->getScanIntensity(k) * 1023.0 / cfg.agc);
        EXPECT_NEAR(Ires, truth[k].restored, 0.05) << k;
    }
}

// Normalised residuals (r - r_true - bias) / sigma_r(r_true) over many scans: their sum of squares
// must follow a chi-square law with N degrees of freedom (99.9 % two-sided, normal approximation),
// and the mean residual must equal the surface bias.
TEST(LaserSim, RangeNoiseMatchesSigmaChiSquare) {
    const Terrain t = flatGround();
    const SurfaceTexture tex(t, 3, 0);
    LaserConfig cfg;
    const LaserSim laser(cfg, t, tex, 3);
    std::mt19937_64 rng(11);
    double chi2 = 0, sumRes = 0, sumSigma2 = 0;
    size_t n = 0;
    std::vector<BeamTruth> truth;
    for (int s = 0; s < 60; ++s) {
        const auto scan = laser.scan(mrpt::poses::CPose3D(0.001 * s, 0, 0, 0.01 * s, 0, 0),
                                     syntheticStamp(0), rng, &truth);
        for (int k = 0; k < 683; ++k) {
            if (!scan->getScanRangeValidity(k) || truth[k].mixed || truth[k].dark) continue;
            const double r = truth[k].trueRange_m;
            const double res = scan->getScanRange(k) - r;
            const double sig = cfg.sigma(r);
            const double z = (res - laser.surfaceBias_m(0)) / sig;
            chi2 += z * z;
            sumRes += res;
            sumSigma2 += sig * sig;
            ++n;
        }
    }
    ASSERT_GT(n, 10000u);
    EXPECT_NEAR(chi2, double(n), 3.29 * std::sqrt(2.0 * n));
    EXPECT_NEAR(sumRes / n, laser.surfaceBias_m(0), 3.29 * std::sqrt(sumSigma2) / n);
    EXPECT_LE(std::abs(laser.surfaceBias_m(0)), cfg.surfaceBiasMax_m);
    EXPECT_GT(std::abs(laser.surfaceBias_m(0)), 1e-5);  // the bias is really there
}

// Dark paint: no return where Ires < 60, an unreliable return where 60 <= Ires < 100.
TEST(LaserSim, DarkSurfacesDropOutAndRestoredIntensityIsLow) {
    const auto board = sim_test::flatBoard(61, 0.01, 0.0);
    const Terrain t = Terrain::fromBoards({board}, 3, 2, 0.3);
    const SurfaceTexture tex(t, 7, 40);
    LaserConfig cfg;
    const LaserSim laser(cfg, t, tex, 7);
    std::mt19937_64 rng(2);
    std::vector<BeamTruth> truth;
    size_t dropouts = 0, darkHits = 0, brightHits = 0;
    for (int s = 0; s < 100; ++s) {
        const mrpt::poses::CPose3D robot(0.015 * s, 0, 0, 0, 0, 0);
        const auto scan = laser.scan(robot, syntheticStamp(0), rng, &truth);
        const mrpt::poses::CPose3D sensor = robot + cfg.pose;
        for (int k = 0; k < 683; ++k) {
            if (truth[k].surface < 0) continue;
            const Eigen::Vector3d d = sensor.getRotationMatrix().asEigen() * laser.beamDirection(k);
            const Eigen::Vector3d p =
                Eigen::Vector3d(sensor.x(), sensor.y(), sensor.z()) + truth[k].trueRange_m * d;
            const bool onPaint = tex.isDark(p.x(), p.y());
            if (onPaint) {
                ++darkHits;
                EXPECT_LT(truth[k].restored, cfg.darkRestored) << k;
                EXPECT_TRUE(truth[k].dropout) << k;  // albedo 0.03: Ires <= 31
                EXPECT_FALSE(scan->getScanRangeValidity(k)) << k;
            } else if (truth[k].trueRange_m < 0.9) {  // grazing far beams may be dim
                ++brightHits;
                EXPECT_GE(truth[k].restored, cfg.darkRestored * 0.99) << k;
            }
            dropouts += truth[k].dropout;
        }
    }
    EXPECT_GT(darkHits, 100u);
    EXPECT_GT(brightHits, 1000u);
    EXPECT_EQ(dropouts, darkHits);
}

namespace {
/** Scans across a 0.1 m box on the floor; checks that every mixed beam lies between the foreground
 * and the background (within 10 % of the jump from either, 2 cm of noise) at a jump over
 * cfg.mixedJump_m, and returns how many there were. */
size_t mixedPixelsAcrossABox(const LaserConfig& cfg) {
    const Terrain t = sim_test::boxOnFloor();
    const SurfaceTexture tex(t, 1, 0);
    const LaserSim laser(cfg, t, tex, 1);
    std::mt19937_64 rng(4);
    std::vector<BeamTruth> truth;
    size_t mixed = 0;
    for (int s = 0; s < 40; ++s) {
        const auto scan = laser.scan(mrpt::poses::CPose3D(-0.2 + 0.01 * s, 0, 0, 0, 0, 0),
                                     syntheticStamp(0), rng, &truth);
        for (int k = 1; k + 1 < 683; ++k) {
            if (!truth[k].mixed) continue;
            ++mixed;
            const double lo = std::min(
                {truth[k - 1].trueRange_m, truth[k].trueRange_m, truth[k + 1].trueRange_m});
            const double hi = std::max(
                {truth[k - 1].trueRange_m, truth[k].trueRange_m, truth[k + 1].trueRange_m});
            const double r = scan->getScanRange(k);
            EXPECT_GT(r, lo + 0.1 * (hi - lo) - 0.02) << k;
            EXPECT_LT(r, hi - 0.1 * (hi - lo) + 0.02) << k;
            EXPECT_GT(hi - lo, cfg.mixedJump_m);
        }
    }
    return mixed;
}
}  // namespace

// A box 0.1 m high occludes the floor behind it: where a scan line jumps from the box top to the
// floor, some far beams return a range strictly between the two surfaces.
TEST(LaserSim, MixedPixelsLieBetweenForegroundAndBackground) {
    EXPECT_GT(mixedPixelsAcrossABox(LaserConfig()), 5u);
}

// The independent setting (--laser-mixed 1,0.015: every depth edge over 15 mm): mixed beams of
// the same shape, twice as many as with a 0.5 chance at the same edges.
TEST(SensorErrors, LaserMixedPixelAtEveryEdge) {
    LaserConfig cfg;
    cfg.mixedJump_m = 0.015;
    cfg.mixedProbability = 1.0;
    const size_t all = mixedPixelsAcrossABox(cfg);
    cfg.mixedProbability = 0.5;
    const size_t half = mixedPixelsAcrossABox(cfg);
    ASSERT_GT(all, 20u);
    EXPECT_NEAR(double(half) / all, 0.5, 0.15) << half << " of " << all;
}
