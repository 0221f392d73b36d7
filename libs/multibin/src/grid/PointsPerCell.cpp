/* Part of the multibin elevation-mapping library. */
#include "multibin/grid/PointsPerCell.h"

#include <Eigen/Core>

#include <cmath>
#include <limits>
#include <unordered_map>

namespace multibin {

size_t removeFailingOwnGate(PointsWithCov& mapPoints, const BinUpdateParams& params) {
    const size_t before = mapPoints.size();
    size_t n = 0;
    for (size_t i = 0; i < before; i++) {
        const PointWithCov& p = mapPoints[i];
        const bool failsOwnGate =
            p.point_m.allFinite() && std::isfinite(p.cov_m2.zz) && !params.passesEq13(p.cov_m2.zz);
        if (!failsOwnGate) mapPoints[n++] = p;
    }
    mapPoints.resize(n);
    return before - n;
}

std::vector<uint32_t> pointsPerCell(const BinGrid& grid, const PointsWithCov& mapPoints) {
    const size_t n = mapPoints.size();
    std::vector<Eigen::Vector2i> cell(n);
    Eigen::Vector2i lo = Eigen::Vector2i::Constant(std::numeric_limits<int>::max()), hi = -lo;
    for (size_t i = 0; i < n; i++) {
        cell[i] = {grid.cellIndex(mapPoints[i].point_m.x()),
                   grid.cellIndex(mapPoints[i].point_m.y())};
        lo = lo.cwiseMin(cell[i]);
        hi = hi.cwiseMax(cell[i]);
    }
    std::vector<uint32_t> perPoint(n);
    if (n == 0) return perPoint;
    // The counts live in a dense array over the points' cells, or a hash map if that is too
    // large (points scattered far apart).
    const int64_t nx = int64_t(hi.x()) - lo.x() + 1, ny = int64_t(hi.y()) - lo.y() + 1;
    if (nx * ny <= int64_t(4 * n + (1 << 20))) {
        std::vector<uint32_t> dense(size_t(nx * ny), 0);
        auto at = [&](const Eigen::Vector2i& c) -> uint32_t& {
            return dense[size_t((int64_t(c.y()) - lo.y()) * nx + (int64_t(c.x()) - lo.x()))];
        };
        for (size_t i = 0; i < n; i++) at(cell[i])++;
        for (size_t i = 0; i < n; i++) perPoint[i] = at(cell[i]);
    } else {
        std::unordered_map<uint64_t, uint32_t> sparse;
        // Both indices' 32 bits, unsigned: shifting a negative index is undefined.
        auto key = [](const Eigen::Vector2i& c) {
            return (uint64_t(uint32_t(c.x())) << 32) | uint32_t(c.y());
        };
        for (size_t i = 0; i < n; i++) sparse[key(cell[i])]++;
        for (size_t i = 0; i < n; i++) perPoint[i] = sparse[key(cell[i])];
    }
    return perPoint;
}

}  // namespace multibin
