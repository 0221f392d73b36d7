/* Eq 16, the sum of Gaussians (GaussianSurface.h), and the Akaike criterion: by hand, exact
 * recovery, the true number of terms, bad samples. */
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "fill_test_util.h"
#include "multibin/fill/GaussianSurface.h"
#include "multibin/fill/ModelSelection.h"

using namespace multibin::fill;
using namespace fill_test;

TEST(GaussianSurface, CorrectedAicByHand) {
    // n ln(chi2/n) + 2k + 2k(k+1)/(n-k-1) with n = 100, k = 6, chi2 = 50.
    EXPECT_NEAR(correctedAic(50, 100, 6), 100 * std::log(0.5) + 12 + 84.0 / 93.0, 1e-12);
    EXPECT_TRUE(std::isinf(correctedAic(1, 7, 6)));
    EXPECT_NEAR(bayesianCriterion(50, 100, 6), 100 * std::log(0.5) + 6 * std::log(100.0), 1e-12);
}

TEST(GaussianSurface, RecoversOneGaussianExactly) {
    const auto samples = gaussianSamples({term(0.05, 9.0, 15.0, 3.0)}, 0.02, 24, 1e-4, 1);
    GaussianFitOptions o;
    o.swarm.iterations = 80;
    const auto g = fitGaussianSurfaceFixed(samples, 24, 1, o);
    ASSERT_EQ(g.terms.size(), 1u);
    EXPECT_NEAR(g.c0_m, 0.02, 2e-4);
    EXPECT_NEAR(g.terms[0].c_m, 0.05, 5e-4);
    EXPECT_NEAR(g.terms[0].a1, 9.0, 0.05);
    EXPECT_NEAR(g.terms[0].a2, 15.0, 0.05);
    EXPECT_NEAR(g.terms[0].lambda1, -0.5 / 9.0, 0.002);
    EXPECT_NEAR(g.rmsResidual_m, 1e-4, 3e-5);                                   // down to the noise
    EXPECT_NEAR(g(12, 12), 0.02 + 0.05 * std::exp(-(9.0 + 9.0) / 18.0), 3e-4);  // in the hole
}

TEST(GaussianSurface, CriteriaChooseTheTrueNumberOfGaussians) {
    // Surfaces of 0..4 well-separated Gaussians (2-5 cm high, 2-3.5 cells wide) plus 2 mm noise
    // on a 24 x 24 area with a 4 x 4 hole, four noise draws each.
    const std::vector<GaussianTerm> pool{term(0.04, 5, 6, 2.5), term(-0.03, 18, 17, 3.0),
                                         term(0.05, 17, 5, 2.0), term(0.03, 6, 18, 3.5)};
    GaussianFitOptions aic, bic;
    aic.maxTerms = bic.maxTerms = 6;
    bic.criterion = ModelCriterion::BIC;
    int aicExact = 0, cases = 0;
    for (int m = 0; m <= 4; m++)
        for (unsigned seed = 1; seed <= 4; seed++) {
            const std::vector<GaussianTerm> terms(pool.begin(), pool.begin() + m);
            const auto samples = gaussianSamples(terms, 0.01, 24, 0.002, seed);
            const auto a = fitGaussianSurface(samples, 24, aic);
            const auto b = fitGaussianSurface(samples, 24, bic);
            const int ma = int(a.terms.size());
            // AIC never misses a real term; its known weakness is one extra term that fits
            // noise (the optimised centre and width make a term worth more than 5 parameters).
            EXPECT_GE(ma, m) << "AICc, true m = " << m << ", seed " << seed;
            EXPECT_LE(ma, m + 1) << "AICc, true m = " << m << ", seed " << seed;
            aicExact += ma == m;
            cases++;
            EXPECT_EQ(int(b.terms.size()), m) << "BIC, true m = " << m << ", seed " << seed;
            EXPECT_LT(a.rmsResidual_m, 0.0022) << "m = " << m;  // at the noise level
        }
    EXPECT_GE(aicExact, cases / 2) << aicExact << " of " << cases;
    std::printf("AICc chose the true m in %d of %d cases, BIC in all\n", aicExact, cases);
}

TEST(GaussianSurface, RejectsBadSamples) {
    GaussianFitOptions o;
    EXPECT_THROW(fitGaussianSurface({}, 10, o), std::invalid_argument);
    EXPECT_THROW(fitGaussianSurface({{10, 0, 0.1, 0.01}}, 10, o), std::invalid_argument);
    EXPECT_THROW(fitGaussianSurface({{1, 1, 0.1, 0.0}}, 10, o), std::invalid_argument);
}
