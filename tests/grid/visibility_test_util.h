/* Helpers of the visibility constraint's tests (test_VisibilityConstraint.cpp,
 * test_VisibilityStages.cpp). */
#pragma once

#include <array>
#include <cstdint>
#include <cstring>
#include <vector>

#include "multibin/grid/BinGrid.h"

namespace multibin::test {

/** A point at (x, y, z) with 1 mm horizontal and sigmaZ_m vertical standard deviation. */
inline PointWithCov pointAt(double x, double y, double z, double sigmaZ_m) {
    PointWithCov p;
    p.point_m = Eigen::Vector3f(float(x), float(y), float(z));
    p.cov_m2 = {1e-6f, 0, 0, 1e-6f, 0, float(sigmaZ_m * sigmaZ_m)};
    return p;
}

/** Every bin of the window, cell by cell in chain order, as raw bytes: equal only if every bin
 * is bit-identical. */
inline std::vector<std::array<uint32_t, 5>> binsOf(const BinGrid& g) {
    std::vector<std::array<uint32_t, 5>> out;
    const CellWindow& w = g.window();
    for (int iy = w.iy0; iy < w.iy0 + w.ny; iy++)
        for (int ix = w.ix0; ix < w.ix0 + w.nx; ix++)
            g.forEachBin(ix, iy, [&](const Bin& b) {
                std::array<uint32_t, 5> r;
                std::memcpy(&r[0], &b.height_m, 4);
                std::memcpy(&r[1], &b.variance_m2, 4);
                std::memcpy(&r[2], &b.certainty, 4);
                r[3] = b.pointCount;
                r[4] = uint32_t(uint16_t(b.index)) | (uint32_t(ix - w.ix0) << 16);
                out.push_back(r);
            });
    return out;
}

}  // namespace multibin::test
