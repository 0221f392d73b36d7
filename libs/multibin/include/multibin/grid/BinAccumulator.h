/* Part of the multibin elevation-mapping library. */
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>

#include "multibin/grid/Bin.h"
#include "multibin/grid/BinUpdate.h"
#include "multibin/util/Counters.h"

namespace multibin {

/** How an accumulator fuses heights (eq 15). */
enum class HeightFusion {
    /** Gain form, one height at a time (fuse()): the height after each point is known, as eq 14
     * needs for the next laser point; also a bin fused from another grid. */
    kSequential,
    /** Information form over a run of points (HeightInformation): one division at the close
     * instead of one chained through every point; the same estimate up to rounding. */
    kInformation,
};

/** The update of one bin by new data: the one home of what an update does to each statistic of
 * a bin (BinEstimate: the height and variance of eq 15, the plane moments, the pose codes, the
 * certainty counter of eqs 13-14, the point count). open() on the bin; addPoint() / addHeight()
 * add points that passed the gates (a laser's caller tests eq 14 with passesEq14() first),
 * merge() an estimate from elsewhere; close() leaves the bin up to date. The grid's per-point
 * path (laser), its runs of points in one bin (stereo, depth, lidar) and its bin merge
 * (BinGrid::fuseBin) all use it.
 *
 * kInformation keeps the run's update in the accumulator (in registers: the grid's run loop
 * inlines it) and writes it back at close(). kSequential updates the bin in place, point by
 * point: the bin is the running estimate eq 14 reads after each point (and a copy cost the
 * laser path 7 % more instructions: the copied moments vectorised into shuffles). */
template <HeightFusion kFusion>
class BinAccumulator {
    static constexpr bool kSequential = kFusion == HeightFusion::kSequential;

public:
    /** Starts the update of `bin`; points are placed relative to the centre of its cell,
     * (cellX_m, cellY_m) [m]. */
    void open(BinEstimate& bin, double cellX_m, double cellY_m) {
        if constexpr (kSequential) m_bin = &bin;
        m_cellX_m = cellX_m;
        m_cellY_m = cellY_m;
        m_points = 0;
        m_maxHeight_m = -std::numeric_limits<double>::infinity();
        if constexpr (!kSequential) {
            m_plane = bin.plane;
            m_poseHeightCode = m_poseHorizontalCode = 0;
            // A bin of variance 0 is exact: its height cannot move (and 1/0 has no place in the
            // information form).
            m_frozen = bin.pointCount > 0 && !(bin.variance_m2 > 0);
            m_information = HeightInformation{};
            if (bin.pointCount > 0 && !m_frozen) m_information.add(bin.height_m, bin.variance_m2);
        }
    }

    /** Eq 14 against the estimate so far (sequential fusion). */
    bool passesEq14(double height_m, double continuityBound_m) const {
        static_assert(kSequential, "eq 14 needs the height after each point");
        return multibin::passesEq14(*m_bin, height_m, continuityBound_m);
    }

    /** A point at (x_m, y_m) [m] of height `height_m` and variance `variance_m2` (at least
     * kMinFusedVariance_m2), whose weight is `weight` = 1 / variance_m2 [1/m^2]. */
    void addPoint(float x_m, float y_m, double height_m, double variance_m2, double weight,
                  const BinUpdateParams& params) {
        addHeight(height_m, variance_m2, weight, params);
        addPlanePoint(kSequential ? m_bin->plane : m_plane, float(x_m - m_cellX_m),
                      float(y_m - m_cellY_m), float(height_m), float(weight));
    }
    /** A height without a place (it says nothing of the slope). */
    void addHeight(double height_m, double variance_m2, double weight,
                   const BinUpdateParams& params) {
        if constexpr (kSequential) {
            (void)weight;
            addMeasurement(*m_bin, height_m, variance_m2, params);
        } else {
            (void)variance_m2;
            (void)params;
            m_information.addWeighted(height_m, weight);
            m_points++;
        }
        m_maxHeight_m = std::max(m_maxHeight_m, height_m);
    }
    /** Lowers the pose codes to these where they are less (0: not known, changes nothing). */
    void lowerPoseCodes(uint8_t heightCode, uint8_t horizontalCode) {
        if constexpr (kSequential) {
            lowerPoseSigmaCodes(*m_bin, heightCode, horizontalCode);
        } else {
            m_poseHeightCode = leastPoseSigmaCode(m_poseHeightCode, heightCode);
            m_poseHorizontalCode = leastPoseSigmaCode(m_poseHorizontalCode, horizontalCode);
        }
    }
    /** An estimate from elsewhere (another grid's bin, same cell and index): its height fused
     * with eq 15, its moments merged exactly, certainty and points added. */
    void merge(const BinEstimate& other) {
        static_assert(kSequential, "a bin is fused in gain form");
        BinEstimate& bin = *m_bin;
        fuse(bin.height_m, bin.variance_m2, other.height_m, other.variance_m2);
        mergePlaneMoments(bin.plane, other.plane);
        lowerPoseSigmaCodes(bin, other.poseHeightSigmaCode, other.poseHorizontalSigmaCode);
        bin.certainty += other.certainty;
        util::addSaturating(bin.pointCount, other.pointCount);
    }

    /** Leaves `bin`, the bin it was opened on, up to date. `wholeIncrement`:
     * isExactWholeFloat(params.certaintyIncrement) (addCertainty). */
    void close(BinEstimate& bin, const BinUpdateParams& params, bool wholeIncrement) const {
        if constexpr (!kSequential) {
            if (!m_frozen) {
                bin.height_m = static_cast<float>(m_information.height_m());
                bin.variance_m2 = static_cast<float>(m_information.variance_m2());
            }
            bin.plane = m_plane;
            addCertainty(bin.certainty, params.certaintyIncrement, m_points, wholeIncrement);
            lowerPoseSigmaCodes(bin, m_poseHeightCode, m_poseHorizontalCode);
            util::addSaturating(bin.pointCount, m_points);
        } else {
            (void)bin;  // updated in place
            (void)params;
            (void)wholeIncrement;
        }
    }

    /** Points added since open() (information form). */
    uint32_t points() const { return m_points; }
    /** The highest height added since open() [m] (-infinity: none). */
    double maxHeight_m() const { return m_maxHeight_m; }

private:
    BinEstimate* m_bin = nullptr;  //!< sequential: the bin, updated in place
    double m_cellX_m = 0, m_cellY_m = 0;
    uint32_t m_points = 0;
    double m_maxHeight_m = 0;
    // Information form: the run's update, written back by close().
    HeightInformation m_information;
    PlaneMoments m_plane;
    uint8_t m_poseHeightCode = 0, m_poseHorizontalCode = 0;
    bool m_frozen = false;  //!< the bin has variance 0: its height stays
};

}  // namespace multibin
