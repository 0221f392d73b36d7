/* Universal kriging (Kriging.h): the grid semivariogram by hand, the covariance fit, the
 * variance against Monte Carlo, exact data and the trend far away. */
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "fill_test_util.h"
#include "multibin/fill/Kriging.h"

using namespace multibin::fill;
using namespace fill_test;

TEST(Kriging, GridSemivariogramByHand) {
    const double nan = std::nan("");
    // Row 0: 0 1 3; row 1: 2 nan 2. Lag 1: (0,1) (1,3) (2,2 has a gap) and columns (0,2);
    // lag 2: (0,3) (2,2).
    const std::vector<double> v{0, 1, 3, 2, nan, 2};
    std::vector<double> pairs;
    const auto g = gridSemivariogram(v, 3, 2, 2, &pairs);
    EXPECT_DOUBLE_EQ(pairs[1], 4);  // (0,1), (1,3) along rows; (0,2) down column 0; (3,2) col 2
    EXPECT_DOUBLE_EQ(g[1], 0.5 * (1 + 4 + 4 + 1) / 4);
    EXPECT_DOUBLE_EQ(pairs[2], 2);
    EXPECT_DOUBLE_EQ(g[2], 0.5 * (9 + 0) / 2);
}

TEST(Kriging, FitCovarianceRecoversAModelSemivariogram) {
    Covariance truth;
    truth.family = CovarianceFamily::Matern32;
    truth.sill_m2 = 4e-4;
    truth.range_cells = 5;
    truth.nugget_m2 = 1e-5;
    const double sensor = 9e-6;
    std::vector<double> gamma(16, 0.0), pairs(16, 100.0);
    for (int h = 1; h <= 15; h++)
        gamma[size_t(h)] =
            sensor + truth.nugget_m2 + truth.sill_m2 * (1 - truth.correlation(double(h)));
    const auto c = fitCovariance(gamma, pairs, sensor, CovarianceFamily::Matern32, 30);
    // The range is searched on a log grid with steps of 11 % (0.5 .. 30 cells, 40 values).
    EXPECT_NEAR(c.range_cells, 5.0, 0.3);
    EXPECT_NEAR(c.sill_m2, 4e-4, 3e-5);
    EXPECT_NEAR(c.nugget_m2, 1e-5, 5e-6);
    EXPECT_NEAR(truth.correlation(0), 1.0, 1e-15);
    EXPECT_NEAR(truth.correlation(5), (1 + std::sqrt(3.0)) * std::exp(-std::sqrt(3.0)), 1e-12);
}

TEST(Kriging, VarianceMatchesMonteCarloAndPredictionIsUnbiased) {
    // Draws of a Gaussian field (Matern 3/2, sill 1e-4 m^2, range 3 cells) with an unknown mean
    // at 12 scattered cells plus a target cell; each draw is kriged at the target. The mean of
    // the reported variance must match the mean squared error, and the error must average 0.
    const std::vector<std::pair<int, int>> at{{0, 0}, {5, 1}, {2, 4}, {7, 7}, {1, 7}, {6, 4},
                                              {3, 1}, {4, 6}, {0, 3}, {7, 2}, {2, 6}, {5, 7}};
    const int target_i = 3, target_j = 3;
    Covariance cov;
    cov.family = CovarianceFamily::Matern32;
    cov.sill_m2 = 1e-4;
    cov.range_cells = 3;
    const double sensor_m = 0.003;
    const int n = int(at.size());
    Eigen::MatrixXd C(n + 1, n + 1);
    auto pos = [&](int k) {
        return k < n ? at[size_t(k)] : std::pair<int, int>{target_i, target_j};
    };
    for (int a = 0; a <= n; a++)
        for (int b = 0; b <= n; b++) {
            const double d = std::hypot(pos(a).first - pos(b).first, pos(a).second - pos(b).second);
            C(a, b) =
                cov.sill_m2 * cov.correlation(d) + (a == b && a < n ? sensor_m * sensor_m : 0);
        }
    const Eigen::MatrixXd L = C.llt().matrixL();
    std::mt19937 rng(3);
    std::normal_distribution<double> unit(0, 1);
    GaussianSurface constant;  // m = 0: ordinary kriging
    double se = 0, sv = 0, sErr = 0;
    const int draws = 4000;
    for (int d = 0; d < draws; d++) {
        Eigen::VectorXd z(n + 1);
        for (int k = 0; k <= n; k++) z[k] = unit(rng);
        const Eigen::VectorXd f = (L * z).array() + 0.05;  // true mean 5 cm, not given
        std::vector<SurfaceSample> s;
        for (int k = 0; k < n; k++)
            s.push_back({at[size_t(k)].first, at[size_t(k)].second, f[k], sensor_m});
        const UniversalKriging uk(s, constant, cov, 0.0);
        std::vector<double> mean, var;
        uk.predict({double(target_i)}, {double(target_j)}, mean, var);
        const double e = mean[0] - f[n];
        se += e * e, sv += var[0], sErr += e;
    }
    const double mse = se / draws, meanVar = sv / draws;
    EXPECT_NEAR(meanVar / mse, 1.0, 0.08) << "mse " << mse << ", mean variance " << meanVar;
    EXPECT_LT(std::abs(sErr / draws), 3 * std::sqrt(mse / draws));
    // The kriging variance is far below the field's own variance (the data inform the target)
    // and above the simple-kriging bound of a known mean.
    EXPECT_LT(mse, 0.5 * cov.sill_m2);
}

TEST(Kriging, InterpolatesExactDataAndRevertsToTheTrendFarAway) {
    Covariance cov;
    cov.sill_m2 = 1e-4;
    cov.range_cells = 2;
    std::vector<SurfaceSample> s{{0, 0, 0.010, 1e-6}, {1, 0, 0.014, 1e-6}, {0, 1, 0.012, 1e-6}};
    GaussianSurface constant;
    const UniversalKriging uk(s, constant, cov, 0.0);
    std::vector<double> mean, var;
    uk.predict({1.0, 200.0}, {0.0, 200.0}, mean, var);
    EXPECT_NEAR(mean[0], 0.014, 1e-6);  // a sample with (almost) no noise is reproduced
    EXPECT_LT(var[0], 1e-10);
    EXPECT_NEAR(mean[1], uk.trend().c0_m, 1e-12);  // beyond the range: the GLS mean
    EXPECT_GT(uk.trend().c0_m, 0.010);
    EXPECT_LT(uk.trend().c0_m, 0.014);
}
