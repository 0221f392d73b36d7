/* Part of the multibin elevation-mapping library. */
#pragma once

#include <functional>
#include <vector>

namespace multibin::fill {

/** Settings of the global-best particle swarm optimiser (constriction coefficients of Clerc and
 * Kennedy 2002 by default). The same seed gives the same result: the swarm is deterministic. */
struct ParticleSwarmOptions {
    int particles = 20;                //!< swarm size [-]
    int iterations = 40;               //!< velocity updates per particle [-]
    unsigned seed = 1;                 //!< seed of the std::mt19937 that places and moves particles
    double inertia = 0.7298;           //!< velocity kept from one step to the next [-]
    double cognitive = 1.49618;        //!< pull towards the particle's own best [-]
    double social = 1.49618;           //!< pull towards the swarm's best [-]
    double maxVelocityFraction = 0.5;  //!< speed limit per step, as a fraction of the box [-]
};

struct ParticleSwarmResult {
    std::vector<double> x;  //!< best position found
    double value = 0;       //!< objective at x
    int evaluations = 0;    //!< objective calls made
};

/** Minimises `objective` over the box lo <= x <= hi (positions are clamped to the box).
 *
 * `initial` positions (each of the box's dimension, clamped) replace the first random particles,
 * so a caller can seed the swarm with a good guess (e.g. the previous model plus one term).
 * Throws std::invalid_argument if lo and hi differ in size, are empty or lo > hi. */
ParticleSwarmResult minimizeParticleSwarm(
    const std::function<double(const std::vector<double>&)>& objective,
    const std::vector<double>& lo, const std::vector<double>& hi,
    const ParticleSwarmOptions& options, const std::vector<std::vector<double>>& initial = {});

}  // namespace multibin::fill
