/* Part of the multibin elevation-mapping library. */
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

#include "multibin/fill/FillOptions.h"
#include "multibin/fill/SparseFill.h"

namespace multibin::fill {

/** Bounds each filled cell's height from above by its clearance: `clearance_m(ix, iy)`, the
 * lowest height at which a line of sight passed over the cell without a return there (+infinity
 * where none did), plus options.clearance.margin_m. A cell the sensor never hit lies below the
 * lines of sight over it, while the fill interpolates it from its rim, whose measured cells are
 * the ones the rays did hit (the top of the step that hides a shadow, say): the fill's error in
 * such gaps is mostly the fill lying above the truth (doc/gap-filling.md). Sigmas are kept.
 * Nothing when options.clearance.enabled is false. Returns the cells lowered. */
template <typename Clearance>
size_t boundByClearance(FilledCells& filled, const FillOptions& options, Clearance&& clearance_m) {
    if (!options.clearance.enabled) return 0;
    std::vector<std::pair<int, int>> lowered;
    filled.forEachFilled([&](int ix, int iy, const FilledCell& c) {
        if (c.height_m > clearance_m(ix, iy) + options.clearance.margin_m)
            lowered.emplace_back(ix, iy);
    });
    // Written after the visit: forEachFilled hands out read-only cells.
    for (const auto& [ix, iy] : lowered) {
        FilledCell& c = filled.cells.at(ix, iy);  // its tile exists: no tile added
        c.height_m = static_cast<float>(clearance_m(ix, iy) + options.clearance.margin_m);
    }
    return lowered.size();
}

}  // namespace multibin::fill
