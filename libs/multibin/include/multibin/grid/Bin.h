/* Part of the multibin elevation-mapping library. */
#pragma once

#include <cstdint>

namespace multibin {

/** Weighted moments of a bin's points for the slope of its surface inside the cell (weights
 * 1/var_z, as eq 15's; x and y from the cell's centre): the weighted least-squares plane
 * through the points is z = mz + g . (p - m) with g = Sxy^-1 (sxz, syz), and its residual
 * sum szz - g . (sxz, syz) scales the gradient's covariance (CellSurface.h). Updated one point
 * at a time in centred form (West's algorithm), merged exactly (BinUpdate.h). 40 bytes. */
struct PlaneMoments {
    float weight = 0;                 //!< sum of w = 1/var_z [1/m^2]
    float mx_m = 0, my_m = 0;         //!< weighted mean x, y from the cell's centre [m]
    float mz_m = 0;                   //!< weighted mean height [m]
    float sxx = 0, sxy = 0, syy = 0;  //!< centred sums w dx dx ... [-]
    float sxz = 0, syz = 0, szz = 0;  //!< centred sums w dx dz ... [-]
};

/** What one vertical bin of a cell knows: the state of the update rule (eqs 13-15, BinUpdate.h).
 * Every per-bin statistic lives here and nowhere else: a method that needs more per bin (the
 * sub-cell surface's moments, say) adds its fields to this struct, and the store, the update
 * rule's callers and the serialization see one type. 60 bytes. */
struct BinEstimate {
    float height_m = 0;     //!< Kalman height estimate [m]
    float variance_m2 = 0;  //!< Kalman variance, without the floor [m^2]
    float certainty = 0;    //!< certainty counter c (eqs 13-14)
    uint32_t pointCount = 0;
    int16_t index = 0;  //!< vertical bin index n: covers [n, n+1) * binHeight [m]
    /** What the robot's pose uncertainty contributes to its points' height and horizontal
     * position, least over the points (codes of BinUpdate.h's poseSigmaCode; 0: not known). A
     * pose error is shared by every point of a frame and, drifting, by consecutive frames, so
     * fusing more points does not average it away: the reported variance keeps it as a floor
     * (serialized from version 4). */
    uint8_t poseHeightSigmaCode = 0;
    uint8_t poseHorizontalSigmaCode = 0;  //!< the same for the horizontal position
    PlaneMoments plane;                   //!< the slope inside the cell (serialized from version 3)
};

/** A bin as BinStore keeps it: its estimate and the storage link to the next bin of its cell
 * (BinStore::kNoBin ends the chain). Only BinStore reads or writes `next`. 64 bytes. */
struct Bin : BinEstimate {
    uint32_t next = 0;
};
static_assert(sizeof(Bin) == 64, "a stored bin must stay within 64 bytes (one cache line)");

}  // namespace multibin
