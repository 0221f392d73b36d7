/* Part of the multibin elevation-mapping library. */
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "multibin/grid/Bin.h"
#include "multibin/util/Counters.h"

namespace multibin {

/** Parameters of the per-point bin update (eqs 13-15). */
struct BinUpdateParams {
    double binHeight_m = 0.05;               //!< vertical bin size [m]
    float certaintyIncrement = 1.0f;         //!< `a` of eqs 13-14
    double maxElevationUncertainty_m = 0.1;  //!< Delta_max: a point counts if 3 sigma_z <= this [m]
    double varianceFloor_m2 = 0.002 * 0.002;  //!< reported variance never falls below this [m^2]

    /** Eq 13 gate: a height with this variance [m^2] counts only if its 99.7 % interval
     * (3 sigma) lies within Delta_max. */
    bool passesEq13(double variance_m2) const {
        return !(9.0 * variance_m2 > maxElevationUncertainty_m * maxElevationUncertainty_m);
    }
};

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

    void add(double height_m, double variance_m2) { addWeighted(height_m, 1.0 / variance_m2); }
    /** The same with the weight w = 1/var [1/m^2] already computed. */
    void addWeighted(double height_m, double weight) {
        information += weight;
        weightedHeight += height_m * weight;
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

/** 2^24: every integer up to it is a float, so sums of whole numbers that stay below it are
 * exact in float. */
constexpr float kFloatExactIntegerLimit = 16777216.0f;

/** Whether `v` is a whole number below kFloatExactIntegerLimit in magnitude (addCertainty). */
inline bool isExactWholeFloat(float v) {
    return std::abs(v) < kFloatExactIntegerLimit && float(static_cast<int32_t>(v)) == v;
}

/** `certainty += increment`, `times` times over, in float: what a bin's certainty counter becomes
 * after `times` measurements. Whole numbers below 2^24 add exactly in float, so for them (the
 * default increment 1 on any counter that was not decremented by a fraction) one addition gives
 * the sequence's result bit for bit; otherwise the sequence is run. `wholeIncrement`:
 * isExactWholeFloat(increment), for callers that add the same increment many times. */
inline void addCertainty(float& certainty, float increment, uint32_t times, bool wholeIncrement) {
    const double total = double(certainty) + double(increment) * double(times);
    if (wholeIncrement && isExactWholeFloat(certainty) &&
        std::abs(total) <= double(kFloatExactIntegerLimit)) {
        certainty = static_cast<float>(total);
        return;
    }
    for (uint32_t k = 0; k < times; k++) certainty += increment;
}
inline void addCertainty(float& certainty, float increment, uint32_t times) {
    addCertainty(certainty, increment, times, isExactWholeFloat(increment));
}

/** Adds a point at (dx_m, dy_m) from its cell's centre, height z_m, weight w = 1/var_z to the
 * bin's plane moments: the centred update of a weighted mean and co-moments (West 1979). */
inline void addPlanePoint(PlaneMoments& m, float dx_m, float dy_m, float z_m, float w) {
    // In float: the offsets are at most a cell and the height's deviations from the bin's mean
    // at most a bin, far inside float's 7 digits; the stored moments are floats anyway.
    const float W = m.weight + w;
    const float f = w / W, k = w - w * f;  // k = w W_old / W
    const float ex = dx_m - m.mx_m, ey = dy_m - m.my_m, ez = z_m - m.mz_m;
    m.weight = W;
    m.mx_m += f * ex;
    m.my_m += f * ey;
    m.mz_m += f * ez;
    m.sxx += k * ex * ex;
    m.sxy += k * ex * ey;
    m.syy += k * ey * ey;
    m.sxz += k * ex * ez;
    m.syz += k * ey * ez;
    m.szz += k * ez * ez;
}

/** Merges the moments `o` (their x, y shifted by (dx_m, dy_m), e.g. a neighbouring cell's
 * centre) into `m`: exact, as if every point of both had been added (parallel axis theorem). */
inline void mergePlaneMoments(PlaneMoments& m, const PlaneMoments& o, double dx_m = 0,
                              double dy_m = 0) {
    if (!(o.weight > 0)) return;
    if (!(m.weight > 0)) {
        m = o;
        m.mx_m = static_cast<float>(o.mx_m + dx_m);
        m.my_m = static_cast<float>(o.my_m + dy_m);
        return;
    }
    const double W = double(m.weight) + double(o.weight);
    const double f = double(o.weight) / W, k = double(m.weight) * f;
    const double ex = o.mx_m + dx_m - m.mx_m, ey = o.my_m + dy_m - m.my_m, ez = o.mz_m - m.mz_m;
    m.weight = static_cast<float>(W);
    m.mx_m = static_cast<float>(m.mx_m + f * ex);
    m.my_m = static_cast<float>(m.my_m + f * ey);
    m.mz_m = static_cast<float>(m.mz_m + f * ez);
    m.sxx = static_cast<float>(double(m.sxx) + o.sxx + k * ex * ex);
    m.sxy = static_cast<float>(double(m.sxy) + o.sxy + k * ex * ey);
    m.syy = static_cast<float>(double(m.syy) + o.syy + k * ey * ey);
    m.sxz = static_cast<float>(double(m.sxz) + o.sxz + k * ex * ez);
    m.syz = static_cast<float>(double(m.syz) + o.syz + k * ey * ez);
    m.szz = static_cast<float>(double(m.szz) + o.szz + k * ez * ez);
}

/** Eq 14: a laser point must agree with a bin that is already certain (c > 0) to within
 * `continuityBound_m`; a bin without certainty has no height to compare against. */
inline bool passesEq14(const BinEstimate& bin, double height_m, double continuityBound_m) {
    return !(bin.certainty > 0 && std::abs(height_m - bin.height_m) > continuityBound_m);
}

/** @name The pose part of a bin's points, kept apart from its fused variance
 * A variance in one byte: the exponent and the two leading mantissa bits of its float, so code
 * c >= 1 stands for a variance within 19 % below the true one (sigma within 9 %), from
 * 2^-40 m^2 (sigma 1 um; anything smaller) to 2^23 m^2; 0 stands for "not known" (no point with
 * a pose part yet, or a map saved before version 4). Encoding is a shift: no table, no log, so the
 * insertion core can afford it per run of points.
 * @{ */
namespace detail {
/** The float bits of 2^-40, shifted by 21, minus 1: code 1 is 2^-40 m^2. */
constexpr int32_t kPoseCodeBias = ((127 - 40) << 2) - 1;
inline uint32_t floatBits(float v) {
    uint32_t u;
    std::memcpy(&u, &v, sizeof u);
    return u;
}
}  // namespace detail

/** The variance [m^2] of a code (0 for "not known"). */
inline double poseVariance_m2(uint8_t code) {
    if (code == 0) return 0;
    const uint32_t u = uint32_t(int32_t(code) + detail::kPoseCodeBias) << 21;
    float v;
    std::memcpy(&v, &u, sizeof v);
    return v;
}

/** The code of `variance_m2` (rounded down; 2^-40 m^2 or less, negative rounding included, gives
 * 1; 2^23 m^2 or more 253); NaN gives 0 (not known). */
inline uint8_t poseSigmaCode(float variance_m2) {
    // Branch-free (a select for NaN), so loops over points vectorise.
    const bool known = variance_m2 == variance_m2;
    const float v = std::min(std::max(variance_m2, 0x1p-40f), 0x1p23f);
    const int32_t code = int32_t(detail::floatBits(v) >> 21) - detail::kPoseCodeBias;
    return static_cast<uint8_t>(known ? code : 0);
}

/** The least of two codes that are known (0: not known). */
inline uint8_t leastPoseSigmaCode(uint8_t a, uint8_t b) {
    return a == 0 ? b : b == 0 ? a : std::min(a, b);
}

/** Lowers `bin`'s two codes to these where they are less (0: not known, changes nothing). */
inline void lowerPoseSigmaCodes(BinEstimate& bin, uint8_t heightCode, uint8_t horizontalCode) {
    bin.poseHeightSigmaCode = leastPoseSigmaCode(bin.poseHeightSigmaCode, heightCode);
    bin.poseHorizontalSigmaCode = leastPoseSigmaCode(bin.poseHorizontalSigmaCode, horizontalCode);
}

/** @} */

/** Standard deviation of a bin's estimate: sqrt(max(variance, floor)) [m]; the visibility
 * constraint's margin. (The variance a query reports also keeps the pose part: CellSurface.h.) */
inline double binSigma_m(const BinEstimate& b, const BinUpdateParams& p) {
    return std::sqrt(std::max<double>(b.variance_m2, p.varianceFloor_m2));
}
/** @} */

}  // namespace multibin
