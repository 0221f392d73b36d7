/* Part of the multibin elevation-mapping library. */
#pragma once

#include <cstdint>

namespace multibin {

/** What one vertical bin of a cell knows: the state of the update rule (eqs 13-15, BinUpdate.h).
 * Every per-bin statistic lives here and nowhere else: a method that needs more per bin (the
 * sub-cell surface's moments, say) adds its fields to this struct, and the store, the update
 * rule's callers and the serialization see one type. 20 bytes. */
struct BinEstimate {
    float height_m = 0;     //!< Kalman height estimate [m]
    float variance_m2 = 0;  //!< Kalman variance, without the floor [m^2]
    float certainty = 0;    //!< certainty counter c (eqs 13-14)
    uint32_t pointCount = 0;
    int16_t index = 0;  //!< vertical bin index n: covers [n, n+1) * binHeight [m]
    uint16_t reserved = 0;
};

/** A bin as BinStore keeps it: its estimate and the storage link to the next bin of its cell
 * (BinStore::kNoBin ends the chain). Only BinStore reads or writes `next`. 24 bytes. */
struct Bin : BinEstimate {
    uint32_t next = 0;
};
static_assert(sizeof(Bin) == 24, "a stored bin must stay within 24 bytes");

}  // namespace multibin
