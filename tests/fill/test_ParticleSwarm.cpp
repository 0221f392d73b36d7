/* The particle swarm (ParticleSwarm.h): a known minimum, determinism, the box. */
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "multibin/fill/ParticleSwarm.h"

using namespace multibin::fill;

TEST(ParticleSwarm, FindsMinimumOfRosenbrockAndIsDeterministic) {
    auto rosen = [](const std::vector<double>& x) {
        return 100 * std::pow(x[1] - x[0] * x[0], 2) + std::pow(1 - x[0], 2);
    };
    ParticleSwarmOptions o;
    o.particles = 30;
    o.iterations = 300;
    const auto a = minimizeParticleSwarm(rosen, {-2, -2}, {2, 2}, o);
    EXPECT_NEAR(a.x[0], 1.0, 0.05);
    EXPECT_NEAR(a.x[1], 1.0, 0.1);
    EXPECT_LT(a.value, 1e-3);
    EXPECT_EQ(a.evaluations, 30 * 301);
    const auto b = minimizeParticleSwarm(rosen, {-2, -2}, {2, 2}, o);
    EXPECT_EQ(a.x, b.x);  // same seed, same swarm
    o.seed = 2;
    const auto c = minimizeParticleSwarm(rosen, {-2, -2}, {2, 2}, o);
    EXPECT_NE(a.x, c.x);
}

TEST(ParticleSwarm, StaysInBoxAndUsesInitialGuess) {
    // Unconstrained minimum at (5, 5), outside the box: the answer is the corner.
    auto f = [](const std::vector<double>& x) {
        return std::pow(x[0] - 5, 2) + std::pow(x[1] - 5, 2);
    };
    ParticleSwarmOptions o;
    o.iterations = 50;
    const auto r = minimizeParticleSwarm(f, {0, 0}, {1, 2}, o);
    EXPECT_DOUBLE_EQ(r.x[0], 1.0);
    EXPECT_DOUBLE_EQ(r.x[1], 2.0);
    o.iterations = 0;  // only the initial swarm: the given guess must be evaluated
    const auto g = minimizeParticleSwarm(f, {0, 0}, {1, 2}, o, {{1.0, 2.0}});
    EXPECT_DOUBLE_EQ(g.value, 16 + 9);
    EXPECT_THROW(minimizeParticleSwarm(f, {0}, {1, 2}, o), std::invalid_argument);
    EXPECT_THROW(minimizeParticleSwarm(f, {1, 0}, {0, 2}, o), std::invalid_argument);
}
