/* Part of the multibin elevation-mapping library: terrain-sim. */
#pragma once

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

namespace terrain_sim {

/** Sensor errors that the library's sensor models do not describe, shared by the laser and the
 * stereo camera. All off by default (the "matched" noise: Gaussian, drawn with the model's own
 * sigma), so the default output is unchanged; `--noise independent` turns them on. */
struct ErrorShape {
    /** 0: Gaussian noise. Otherwise Student-t with this many degrees of freedom (> 2), scaled to
     * the same standard deviation as the Gaussian it replaces: same sigma, heavier tails. */
    int tailDof = 0;
    /** Share of measurements replaced by a gross error: the true value times U(1 - span, 1 +
     * span) (range for the laser, disparity for stereo). */
    double outlierFraction = 0.0;
    double outlierSpan = 0.5;
    /** Scale of every drawn measurement error (noise, per-surface and dark-return bias): 1, or
     * 0 for exact measurements (`--noise exact`). The written sigmas stay the same; the draws
     * still happen, so the same seed gives the same scene with the errors removed. */
    double drawnErrorScale = 1.0;

    bool heavyTails() const { return tailDof > 0; }
    void validate(const std::string& what) const {
        if (tailDof != 0 && tailDof <= 2)
            throw std::invalid_argument(what + ": Student-t degrees of freedom must be > 2 (got " +
                                        std::to_string(tailDof) + ")");
        if (!(outlierFraction >= 0 && outlierFraction <= 1))
            throw std::invalid_argument(what + ": outlier fraction must be in [0, 1]");
        if (!(outlierSpan > 0 && outlierSpan < 1))
            throw std::invalid_argument(what + ": outlier span must be in (0, 1)");
    }

    /** Factor that turns a standard normal draw z into a unit-variance Student-t draw:
     * t = z sqrt(nu / chi2_nu) has variance nu / (nu - 2), hence sqrt((nu - 2) / chi2_nu).
     * Draws nothing (and returns 1) with Gaussian noise, so matched runs keep their stream. */
    double tailFactor(std::mt19937_64& rng) const {
        if (!heavyTails()) return 1.0;
        std::chi_squared_distribution<double> chi2(tailDof);
        return std::sqrt((tailDof - 2.0) / chi2(rng));
    }

    /** Whether this measurement is an outlier, and if so its factor on the true value in
     * `factor`. Draws nothing when outliers are off. */
    bool drawOutlier(std::mt19937_64& rng, double& factor) const {
        if (outlierFraction <= 0) return false;
        std::uniform_real_distribution<double> u(0.0, 1.0);
        const double pick = u(rng), f = u(rng);
        if (pick >= outlierFraction) return false;
        factor = 1.0 - outlierSpan + 2.0 * outlierSpan * f;
        return true;
    }
};

}  // namespace terrain_sim
