/* Part of the multibin elevation-mapping library. */
#include "multibin/fill/ParticleSwarm.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

namespace multibin::fill {

ParticleSwarmResult minimizeParticleSwarm(
    const std::function<double(const std::vector<double>&)>& objective,
    const std::vector<double>& lo, const std::vector<double>& hi,
    const ParticleSwarmOptions& options, const std::vector<std::vector<double>>& initial) {
    const size_t dim = lo.size();
    if (dim == 0 || hi.size() != dim)
        throw std::invalid_argument(
            "minimizeParticleSwarm: lo and hi must be non-empty, same size");
    for (size_t d = 0; d < dim; d++)
        if (!(lo[d] <= hi[d]))
            throw std::invalid_argument("minimizeParticleSwarm: lo > hi in dimension " +
                                        std::to_string(d));
    if (options.particles < 1 || options.iterations < 0)
        throw std::invalid_argument(
            "minimizeParticleSwarm: particles must be >= 1, iterations >= 0");

    std::mt19937 rng(options.seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const size_t np = size_t(options.particles);
    std::vector<std::vector<double>> x(np, std::vector<double>(dim)), v = x, best = x;
    std::vector<double> bestVal(np), vmax(dim);
    for (size_t d = 0; d < dim; d++) vmax[d] = options.maxVelocityFraction * (hi[d] - lo[d]);

    ParticleSwarmResult out;
    out.value = std::numeric_limits<double>::infinity();
    auto evaluate = [&](const std::vector<double>& p) {
        double f = objective(p);
        out.evaluations++;
        // A NaN objective (degenerate model) must never win.
        return std::isnan(f) ? std::numeric_limits<double>::infinity() : f;
    };
    for (size_t k = 0; k < np; k++) {
        for (size_t d = 0; d < dim; d++) {
            x[k][d] = k < initial.size() && initial[k].size() == dim
                          ? std::clamp(initial[k][d], lo[d], hi[d])
                          : lo[d] + unit(rng) * (hi[d] - lo[d]);
            v[k][d] = (unit(rng) - 0.5) * vmax[d];
        }
        best[k] = x[k];
        bestVal[k] = evaluate(x[k]);
        if (bestVal[k] < out.value) {
            out.value = bestVal[k];
            out.x = x[k];
        }
    }
    for (int it = 0; it < options.iterations; it++) {
        for (size_t k = 0; k < np; k++) {
            for (size_t d = 0; d < dim; d++) {
                const double r1 = unit(rng), r2 = unit(rng);
                double vel = options.inertia * v[k][d] +
                             options.cognitive * r1 * (best[k][d] - x[k][d]) +
                             options.social * r2 * (out.x[d] - x[k][d]);
                vel = std::clamp(vel, -vmax[d], vmax[d]);
                double pos = x[k][d] + vel;
                if (pos < lo[d] || pos > hi[d]) {  // stop at the wall
                    pos = std::clamp(pos, lo[d], hi[d]);
                    vel = 0;
                }
                v[k][d] = vel;
                x[k][d] = pos;
            }
            const double f = evaluate(x[k]);
            if (f < bestVal[k]) {
                bestVal[k] = f;
                best[k] = x[k];
                if (f < out.value) {
                    out.value = f;
                    out.x = x[k];
                }
            }
        }
    }
    if (out.x.empty()) out.x = x[0];  // every evaluation was infinite
    return out;
}

}  // namespace multibin::fill
