/* Part of the multibin elevation-mapping library. */
#pragma once

#include <algorithm>
#include <cmath>

#include "multibin/map/Bin.h"
#include "multibin/map/MapTypes.h"
#include "multibin/util/Counters.h"

namespace multibin {

/** @name The update rule of a bin: eq 15, a static 1-D Kalman filter over heights. The one home
 * of its arithmetic: the per-point update, runs of points fused at once, bins fused from another
 * grid and the cell surface's merge of neighbouring bins all call these.
 * @{ */

/** The least height variance a point is fused with [m^2]: an exact height (an exact pose and a
 * horizontal range-only beam give variance 0) would make the information form's 1/var
 * infinite; (1 um)^2 is exact for any terrain. */
constexpr double kMinFusedVariance_m2 = 1e-12;

/** Eq 15 in gain form: fuses a height `z_m` with variance `zVariance_m2` into the estimate
 * (height_m, variance_m2), stored as floats. Two exact estimates (both variances 0) average. */
inline void fuse(float& height_m, float& variance_m2, double z_m, double zVariance_m2) {
    const double var = variance_m2;
    const double sum = var + zVariance_m2;
    const double K = sum > 0 ? var / sum : 0.5;
    height_m = static_cast<float>(height_m - K * (height_m - z_m));
    variance_m2 = static_cast<float>((1.0 - K) * var);
}

/** Eq 15 in information form: 1/var = sum 1/var_i, h/var = sum h_i/var_i. The same estimate as
 * the gain form applied in sequence, up to rounding, with one division per height added instead
 * of a division chained through every update. */
struct HeightInformation {
    double information = 0;     //!< sum of 1/var [1/m^2]
    double weightedHeight = 0;  //!< sum of h/var [1/m]

    void add(double height_m, double variance_m2) {
        const double w = 1.0 / variance_m2;
        information += w;
        weightedHeight += height_m * w;
    }
    double variance_m2() const { return 1.0 / information; }
    double height_m() const { return weightedHeight * variance_m2(); }
};

/** One measurement accepted into `bin` (the gates of eqs 13-14 passed): its certainty grows by
 * the increment `a`, the first measurement initialises the estimate, later ones are fused. */
inline void addMeasurement(BinEstimate& bin, double height_m, double variance_m2,
                           const BinUpdateParams& params) {
    bin.certainty += params.certaintyIncrement;
    if (bin.pointCount == 0) {
        bin.height_m = static_cast<float>(height_m);
        bin.variance_m2 = static_cast<float>(variance_m2);
    } else {
        fuse(bin.height_m, bin.variance_m2, height_m, variance_m2);
    }
    util::addSaturating(bin.pointCount, 1u);
}

/** Eq 14: a laser point must agree with a bin that is already certain (c > 0) to within
 * `continuityBound_m`; a bin without certainty has no height to compare against. */
inline bool passesEq14(const BinEstimate& bin, double height_m, double continuityBound_m) {
    return !(bin.certainty > 0 && std::abs(height_m - bin.height_m) > continuityBound_m);
}

/** Reported standard deviation of a bin: sqrt(max(variance, floor)) [m]. */
inline double binSigma_m(const BinEstimate& b, const BinUpdateParams& p) {
    return std::sqrt(std::max<double>(b.variance_m2, p.varianceFloor_m2));
}
/** @} */

}  // namespace multibin
