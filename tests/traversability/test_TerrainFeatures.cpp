/* Traversability features and probabilities on known surfaces (multibin/traversability/). */
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>

#include "multibin/traversability/TerrainFeatures.h"

using namespace multibin;
using namespace multibin::traversability;

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;

/** The features of z = f(x, y) over a disc of radius r, sampled on a 0.5 mm lattice. */
DiscFeatures fineDisc(const std::function<double(double, double)>& f, double r_m) {
    DiscAccumulator acc;
    const double d = 0.0005;
    for (double y = -r_m; y <= r_m; y += d)
        for (double x = -r_m; x <= r_m; x += d)
            if (x * x + y * y <= r_m * r_m) acc.add(x, y, f(x, y));
    DiscFeatures out;
    EXPECT_TRUE(acc.features(out));
    return out;
}

/** Samples of z = f(x, y) [m] on a lattice of nx x ny cells of `cell_m`, k per cell side, each
 * with `sigma_m`; the cell's error drawn once per cell if `rng` is given. */
SurfaceSamples samplesOf(const std::function<double(double, double)>& f, int nx, int ny,
                         double cell_m, double sigma_m, std::mt19937* rng = nullptr, int k = 2) {
    SurfaceSamples s(Lattice{cell_m, CellWindow{0, 0, nx, ny}}, k);
    std::normal_distribution<double> n01;
    for (int row = 0; row < ny; row++)
        for (int col = 0; col < nx; col++) {
            const double e = rng ? sigma_m * n01(*rng) : 0.0;
            for (int r = 0; r < k; r++)
                for (int c = 0; c < k; c++) {
                    const double x = (col + (c + 0.5) / k) * cell_m,
                                 y = (row + (r + 0.5) / k) * cell_m;
                    const size_t i = s.sampleIndex(col * k + c, row * k + r);
                    s.height_m[i] = float(f(x, y) + e);
                    s.sigma_m[i] = float(sigma_m);
                }
        }
    return s;
}

double normalCdf(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }
}  // namespace

// ---------------------------------------------------------------------------------------------
// The feature definitions, against closed forms
// ---------------------------------------------------------------------------------------------
TEST(DiscFeatures, APlaneHasNoStepSlopeOrRoughness) {
    const DiscFeatures f = fineDisc([](double, double) { return 0.3; }, 0.05);
    EXPECT_NEAR(f.step_m, 0, 1e-9);
    EXPECT_NEAR(f.slope_deg, 0, 1e-6);
    EXPECT_NEAR(f.roughness_m, 0, 1e-9);
}

TEST(DiscFeatures, ATiltedPlaneHasItsAngleAndTheStepAcrossTheDisc) {
    const double a = 20 * kDeg, r = 0.05;
    // Tilted about an oblique axis: the angle is that of the gradient's norm.
    const DiscFeatures f =
        fineDisc([&](double x, double y) { return std::tan(a) * (0.6 * x + 0.8 * y) + 1.0; }, r);
    EXPECT_NEAR(f.slope_deg, 20.0, 1e-6);
    EXPECT_NEAR(f.step_m, 2 * r * std::tan(a), 2 * 0.0005 * std::tan(a));
    EXPECT_NEAR(f.roughness_m, 0, 1e-7);
}

TEST(DiscFeatures, ABoxStepThroughTheCentre) {
    // Half the disc at H: the least-squares slope is 8 H / (3 pi r), the residual RMS
    // H sqrt(1/4 - 16 / (9 pi^2)) (uniform disc: var x = r^2 / 4, E[x; x > 0] = 2 r / (3 pi)).
    const double H = 0.1, r = 0.05;
    const DiscFeatures f = fineDisc([&](double x, double) { return x > 0 ? H : 0.0; }, r);
    EXPECT_NEAR(f.step_m, H, 1e-12);
    EXPECT_NEAR(std::tan(f.slope_deg * kDeg), 8 * H / (3 * kPi * r), 0.01 * 8 * H / (3 * kPi * r));
    const double rms = H * std::sqrt(0.25 - 16 / (9 * kPi * kPi));
    EXPECT_NEAR(f.roughness_m, rms, 0.01 * rms);
}

TEST(DiscFeatures, ASineSurface) {
    // z = A sin(k (x0 + x)) over a disc of radius r: the least-squares slope is
    // 8 A cos(k x0) J2(k r) / (k r^2) (E[x sin kx] = 2 J2(k r) / k over the disc); with x0 = 0 the
    // surface is odd, so the RMS residual is that of A sin(k x) about the line b x: E[z^2] = A^2 (1
    // - J1(2 k r) / (k r)) / 2, minus b^2 r^2 / 4.
    const double A = 0.02, lambda = 0.08, k = 2 * kPi / lambda, r = 0.05;
    const DiscFeatures f = fineDisc([&](double x, double) { return A * std::sin(k * x); }, r);
    const double b = 8 * A * std::cyl_bessel_j(2.0, k * r) / (k * r * r);
    EXPECT_NEAR(std::tan(f.slope_deg * kDeg), std::abs(b), 0.01 * std::abs(b));
    const double ez2 = A * A * 0.5 * (1 - std::cyl_bessel_j(1.0, 2 * k * r) / (k * r));
    const double rms = std::sqrt(ez2 - b * b * r * r / 4);
    EXPECT_NEAR(f.roughness_m, rms, 0.01 * rms);
    EXPECT_NEAR(f.step_m, 2 * A, 1e-4);  // the disc spans more than a period
}

// ---------------------------------------------------------------------------------------------
// The layers: features of the samples, their sigmas and probabilities
// ---------------------------------------------------------------------------------------------
TEST(TraversabilityLayers, TiltedPlaneSlopeSigmaIsThePropagatedOne) {
    // Each cell's samples share one error of sigma s (one plane per cell), cells independent:
    // the least-squares gradient along x is sum_i a_i h_i with a_i = x_i / sum x^2 over the
    // disc's samples (a symmetric disc), so var(g_x) = s^2 sum_cells (sum_{i in cell} a_i)^2.
    const double cell = 0.02, s = 0.003, angle = 30 * kDeg;
    TraversabilityOptions o;
    o.monte_carlo_draws = 2000;
    const SurfaceSamples samples =
        samplesOf([&](double x, double) { return std::tan(angle) * x; }, 11, 11, cell, s);
    TraversabilityLayers t;
    computeLayers(samples, o, t);
    const size_t c = t.lattice.index(5, 5);
    EXPECT_NEAR(t.slope_deg[c], 30.0, 1e-3);
    EXPECT_NEAR(t.roughness_m[c], 0.0, 1e-6);
    // The propagation by hand.
    const int k = samples.perCell;
    double sxx = 0;
    std::map<std::pair<int, int>, double> perCell;
    for (int sr = 0; sr < samples.sy(); sr++)
        for (int sc = 0; sc < samples.sx(); sc++) {
            const double dx = ((sc + 0.5) / k - 5.5) * cell, dy = ((sr + 0.5) / k - 5.5) * cell;
            if (dx * dx + dy * dy > o.radius_m * o.radius_m) continue;
            sxx += dx * dx;
            perCell[{sc / k, sr / k}] += dx;
        }
    double varG = 0;
    for (const auto& [cellIndex, sumX] : perCell) varG += (s * sumX / sxx) * (s * sumX / sxx);
    const double g = std::tan(angle);
    const double sigmaDeg = std::sqrt(varG) / (1 + g * g) / kDeg;
    EXPECT_NEAR(t.slopeSigma_deg[c], sigmaDeg, 0.05 * sigmaDeg);
    // P(slope > 35 deg): the slope is Gaussian to first order.
    EXPECT_NEAR(t.untraversable[c], 1 - normalCdf((35.0 - 30.0) / sigmaDeg), 0.02);
}

TEST(TraversabilityLayers, TheProbabilityOfAMonteCarloOfTheMapsOwnErrors) {
    // A slope near the limit: P from the layer against the frequency over independent draws of
    // the same error model (4000, another generator), features by DiscAccumulator.
    const double cell = 0.02, s = 0.004, angle = 34.5 * kDeg;
    TraversabilityOptions o;
    o.monte_carlo_draws = 1024;
    const auto plane = [&](double x, double y) { return std::tan(angle) * (0.8 * x - 0.6 * y); };
    TraversabilityLayers t;
    computeLayers(samplesOf(plane, 11, 11, cell, s), o, t);
    const size_t c = t.lattice.index(5, 5);
    std::mt19937 rng(5);
    int exceed = 0;
    const int trials = 4000;
    for (int n = 0; n < trials; n++) {
        const SurfaceSamples noisy = samplesOf(plane, 11, 11, cell, s, &rng);
        DiscAccumulator acc;
        for (int sr = 0; sr < noisy.sy(); sr++)
            for (int sc = 0; sc < noisy.sx(); sc++) {
                const double dx = ((sc + 0.5) / 2 - 5.5) * cell, dy = ((sr + 0.5) / 2 - 5.5) * cell;
                if (dx * dx + dy * dy <= o.radius_m * o.radius_m)
                    acc.add(dx, dy, noisy.height_m[noisy.sampleIndex(sc, sr)]);
            }
        DiscFeatures f;
        ASSERT_TRUE(acc.features(f));
        exceed += f.step_m > o.max_step_m || f.slope_deg > o.max_slope_deg ||
                  f.roughness_m > o.max_roughness_m;
    }
    const double p = double(exceed) / trials;
    EXPECT_GT(p, 0.1);
    EXPECT_LT(p, 0.9);
    EXPECT_NEAR(t.untraversable[c], p, 0.04);
}

TEST(TraversabilityLayers, CalibratedOnNoisyPlanesAroundTheSlopeLimit) {
    // Truth: planes whose angle is uniform in 25..45 deg (the limit 35), seen with the stated
    // noise (one error per cell). Among cells given probability p, a share p is in truth steeper
    // than the limit: expected calibration error over deciles.
    const double cell = 0.02, s = 0.006;
    TraversabilityOptions o;
    o.max_step_m = 1.0;  // the slope alone decides
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> angleDeg(25, 45), dir(0, 2 * kPi);
    std::vector<uint8_t> mask(9 * 9, 0);
    mask[4 * 9 + 4] = 1;
    std::array<double, 10> sumP{}, sumTruth{}, count{};
    const int trials = 1500;
    for (int n = 0; n < trials; n++) {
        const double a = angleDeg(rng) * kDeg, d = dir(rng);
        const SurfaceSamples samples = samplesOf(
            [&](double x, double y) { return std::tan(a) * (std::cos(d) * x + std::sin(d) * y); },
            9, 9, cell, s, &rng);
        TraversabilityLayers t;
        computeLayers(samples, o, t, mask);
        const double p = t.untraversable[4 * 9 + 4];
        ASSERT_TRUE(std::isfinite(p));
        const int bin = std::min(9, int(p * 10));
        sumP[bin] += p, sumTruth[bin] += a > 35 * kDeg, count[bin]++;
    }
    double ece = 0;
    for (int b = 0; b < 10; b++)
        if (count[b] > 0) ece += std::abs(sumP[b] - sumTruth[b]) / trials;
    EXPECT_LT(ece, 0.03);
    // Not all 0 or 1: the noise makes some cells uncertain.
    EXPECT_GT(count[1] + count[2] + count[3] + count[4] + count[5] + count[6] + count[7] + count[8],
              50);
}

TEST(TraversabilityLayers, ABoxStepIsUntraversableNearItsEdgeOnly) {
    const double cell = 0.02;
    TraversabilityOptions o;
    o.max_slope_deg = 89, o.max_roughness_m = 1;  // the step alone decides
    for (const double H : {0.12, 0.05}) {
        const SurfaceSamples samples =
            samplesOf([&](double x, double) { return x > 0.2 ? H : 0.0; }, 20, 5, cell, 0.002);
        TraversabilityLayers t;
        computeLayers(samples, o, t);
        for (int col = 0; col < 20; col++) {
            const size_t c = t.lattice.index(col, 2);
            const double dist = std::abs((col + 0.5) * cell - 0.2);  // centre to the edge
            if (dist < o.radius_m - 0.01) {
                EXPECT_NEAR(t.step_m[c], H, 0.001) << col;
                EXPECT_NEAR(t.untraversable[c], H > o.max_step_m ? 1.0 : 0.0, 0.02) << col;
            } else if (dist > o.radius_m + 0.01) {
                EXPECT_NEAR(t.step_m[c], 0, 0.001) << col;
                EXPECT_NEAR(t.untraversable[c], 0.0, 0.02) << col;
            }
        }
    }
}

TEST(TraversabilityLayers, AStepInsideACellFromItsBins) {
    // The cell's surface is the low ground; a second certain bin 0.1 m above it (the top of a
    // step the cell's one height flattens) makes the discs that hold the cell a step.
    const double cell = 0.02;
    TraversabilityOptions o;
    SurfaceSamples samples = samplesOf([](double, double) { return 0.0; }, 11, 11, cell, 0.002);
    samples.binHigh_m[samples.lattice.index(5, 5)] = 0.1f;
    samples.binHighSigma_m[samples.lattice.index(5, 5)] = 0.002f;
    TraversabilityLayers t;
    computeLayers(samples, o, t);
    EXPECT_NEAR(t.step_m[t.lattice.index(5, 5)], 0.1, 1e-6);
    EXPECT_GT(t.untraversable[t.lattice.index(6, 5)], 0.98);
    EXPECT_LT(t.untraversable[t.lattice.index(9, 5)], 0.02);  // 8 cm away: outside the disc
    o.use_bins = false;
    computeLayers(samples, o, t);
    EXPECT_LT(t.untraversable[t.lattice.index(5, 5)], 0.02);
}

TEST(TraversabilityLayers, UnknownIsAStateOfItsOwn) {
    const double cell = 0.02;
    TraversabilityOptions o;
    SurfaceSamples samples = samplesOf([](double, double) { return 0.0; }, 11, 11, cell, 0.002);
    samples.setCell(5, 5, NAN, NAN);  // never seen, not filled
    for (int col = 0; col < 11; col++)
        for (int row = 0; row < 11; row++)
            if (col <= 1 || row <= 1) samples.setCell(col, row, NAN, NAN);
    TraversabilityLayers t;
    computeLayers(samples, o, t);
    EXPECT_FALSE(t.known(t.lattice.index(5, 5)));  // the cell itself unknown
    EXPECT_FALSE(t.known(t.lattice.index(2, 2)));  // its disc mostly unknown
    EXPECT_TRUE(t.known(t.lattice.index(6, 6)));
    EXPECT_TRUE(std::isnan(t.step_m[t.lattice.index(5, 5)]));
    EXPECT_NEAR(t.untraversable[t.lattice.index(6, 6)], 0.0, 1e-6);
}

TEST(TraversabilityLayers, FootholdOnFlatGroundAndBesideAStep) {
    const double cell = 0.02;
    TraversabilityOptions o;  // foot 0.02 m, flat within 0.01 m, clearance 0.02 m
    const SurfaceSamples samples =
        samplesOf([&](double x, double) { return x > 0.2 ? 0.1 : 0.0; }, 20, 5, cell, 0.001);
    TraversabilityLayers t;
    computeLayers(samples, o, t);
    EXPECT_GT(t.foothold[t.lattice.index(2, 2)], 0.98);   // 0.15 m from the edge
    EXPECT_LT(t.foothold[t.lattice.index(9, 2)], 0.02);   // 1 cm from the edge
    EXPECT_GT(t.foothold[t.lattice.index(15, 2)], 0.98);  // on top, far from the edge
}

TEST(TraversabilityLayers, ZeroDrawsThresholdTheFeatures) {
    TraversabilityOptions o;
    o.monte_carlo_draws = 0;
    const SurfaceSamples samples =
        samplesOf([&](double x, double) { return std::tan(36 * kDeg) * x; }, 11, 11, 0.02, 0.01);
    TraversabilityLayers t;
    computeLayers(samples, o, t);
    EXPECT_EQ(t.untraversable[t.lattice.index(5, 5)], 1.0f);
    EXPECT_EQ(t.slopeSigma_deg[t.lattice.index(5, 5)], 0.0f);
}

// The step's calibration reads the map's roughness and slope too: on a 20 deg plane with 1 cm
// waves, the calibrated step is bias + gain step + step_roughness_gain roughness + step_slope_gain
// slope of the uncalibrated features, and decides the class (here the roughness term alone takes
// it across 0.08 m).
TEST(TraversabilityLayers, TheStepCalibrationReadsRoughnessAndSlope) {
    TraversabilityOptions o;
    o.monte_carlo_draws = 0;
    const auto surface = [](double x, double y) {
        return std::tan(20 * kDeg) * x + 0.01 * std::sin(2 * kPi * x / 0.03) * std::cos(y / 0.02);
    };
    const SurfaceSamples samples = samplesOf(surface, 11, 11, 0.02, 0.002);
    TraversabilityLayers raw, cal;
    computeLayers(samples, o, raw);
    o.step = {0.02, 0.1, 0};
    o.step_roughness_gain = 10;
    o.step_slope_gain = 0.0005;
    computeLayers(samples, o, cal);
    const size_t k = raw.lattice.index(5, 5);
    const double expected =
        0.02 + 0.1 * raw.step_m[k] + 10 * raw.roughness_m[k] + 0.0005 * raw.slope_deg[k];
    EXPECT_NEAR(cal.step_m[k], expected, 1e-6);
    EXPECT_EQ(cal.slope_deg[k], raw.slope_deg[k]);
    EXPECT_EQ(cal.roughness_m[k], raw.roughness_m[k]);
    // The roughness term takes the step across the limit, and the class with it.
    ASSERT_GT(expected, o.max_step_m);
    EXPECT_EQ(cal.untraversable[k], 1.f);
    o.step_roughness_gain = 0;
    computeLayers(samples, o, cal);
    EXPECT_NEAR(cal.step_m[k], expected - 10 * raw.roughness_m[k], 1e-6);
    ASSERT_LT(cal.step_m[k], o.max_step_m);
    EXPECT_EQ(cal.untraversable[k], 0.f);
}

TEST(TraversabilityLayers, DilateMaskGrowsASquare) {
    std::vector<uint8_t> m(7 * 5, 0);
    m[2 * 7 + 3] = 1;
    const std::vector<uint8_t> d = dilateMask(m, 7, 5, 1);
    int n = 0;
    for (int r = 0; r < 5; r++)
        for (int c = 0; c < 7; c++) {
            const bool in = std::abs(c - 3) <= 1 && std::abs(r - 2) <= 1;
            EXPECT_EQ(d[size_t(r) * 7 + size_t(c)], in ? 1 : 0) << c << "," << r;
            n += d[size_t(r) * 7 + size_t(c)];
        }
    EXPECT_EQ(n, 9);
}
