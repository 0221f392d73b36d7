/* Part of the multibin elevation-mapping library. */
#include "multibin/geometry/Lattice.h"

#include <cmath>

namespace multibin {

bool Lattice::cellOf(double x_m, double y_m, int& col, int& row) const {
    if (!std::isfinite(x_m) || !std::isfinite(y_m)) return false;
    const double fx = std::floor(x_m / cellSize_m), fy = std::floor(y_m / cellSize_m);
    // Far outside any window: no int overflow.
    if (!(std::abs(fx) < 1e9) || !(std::abs(fy) < 1e9)) return false;
    col = static_cast<int>(fx) - window.ix0;
    row = static_cast<int>(fy) - window.iy0;
    return inside(col, row);
}

}  // namespace multibin
