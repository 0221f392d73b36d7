/* Part of the multibin elevation-mapping library. */
#include <algorithm>
#include <cmath>
#include <cstddef>

#include "multibin/grid/VisibilityStages.h"

namespace multibin::visibility {

Region buildRegion(const BinGrid& grid, const Eigen::Vector3d& sensor_m,
                   std::vector<float>& table) {
    Region region;
    table.clear();
    const std::vector<BinGrid::UpdatedCell>& updated = grid.updatedCells();
    if (updated.empty()) return region;
    int ixLo = grid.cellIndex(sensor_m.x()), ixHi = ixLo;
    int iyLo = grid.cellIndex(sensor_m.y()), iyHi = iyLo;
    // A NaN sensor height makes every ray comparison fail (no ray edits): leave it out.
    double lowest_m =
        std::isnan(sensor_m.z()) ? std::numeric_limits<double>::infinity() : sensor_m.z();
    for (const BinGrid::UpdatedCell& u : updated) {
        ixLo = std::min(ixLo, u.ix);
        ixHi = std::max(ixHi, u.ix);
        iyLo = std::min(iyLo, u.iy);
        iyHi = std::max(iyHi, u.iy);
        lowest_m = std::min(lowest_m, double(u.maxHeight_m));
    }
    const CellWindow& w = grid.window();
    const int bxLo = BinGrid::blockOf(std::max(ixLo - 1, w.ix0));
    const int bxHi = BinGrid::blockOf(std::min(ixHi + 1, w.ix0 + w.nx - 1));
    const int byLo = BinGrid::blockOf(std::max(iyLo - 1, w.iy0));
    const int byHi = BinGrid::blockOf(std::min(iyHi + 1, w.iy0 + w.ny - 1));
    // Up to 2^18 blocks (1 MB): the walks look bounds up here, without the block table's
    // wrap-around and tags.
    if (!(bxHi >= bxLo && byHi >= byLo &&
          double(bxHi - bxLo + 1) * double(byHi - byLo + 1) <= double(1 << 18)))
        return region;
    region.x0 = bxLo;
    region.y0 = byLo;
    region.nx = unsigned(bxHi - bxLo + 1);
    region.ny = unsigned(byHi - byLo + 1);
    region.lowestLine_m = lowest_m;
    table.resize(size_t(region.nx) * region.ny);
    for (int by = byLo; by <= byHi; by++)
        for (int bx = bxLo; bx <= bxHi; bx++) {
            const float b = grid.blockMaxHeight_m(bx, by);
            table[unsigned(bx - bxLo) + unsigned(by - byLo) * region.nx] = b;
            region.maxBound_m = std::max(region.maxBound_m, b);
        }
    region.bound_m = table.data();
    return region;
}

size_t countRays(const BinGrid& grid, const Eigen::Vector3d& sensor_m) {
    // As SightLine::setEnds decides (length >= cell), the square root only near the edge.
    const double cell = grid.cellSize_m();
    const double cell2Lo = cell * cell * (1 - 1e-9), cell2Hi = cell * cell * (1 + 1e-9);
    size_t rays = 0;
    for (const BinGrid::UpdatedCell& u : grid.updatedCells()) {
        const double dx = sensor_m.x() - grid.cellCenter_m(u.ix);
        const double dy = sensor_m.y() - grid.cellCenter_m(u.iy);
        const double d2 = dx * dx + dy * dy;
        rays += d2 > cell2Hi ? 1 : d2 < cell2Lo ? 0 : !(std::sqrt(d2) < cell);
    }
    return rays;
}

TowardsSensor buildTowardsSensor(const BinGrid& grid, const Region& region,
                                 const Eigen::Vector3d& sensor_m, const BoundTest& bounds,
                                 std::vector<float>& table) {
    TowardsSensor towards;
    towards.region = &region;
    table.clear();
    if (region.empty()) return towards;
    const int sensorBx = BinGrid::blockOf(grid.cellIndex(sensor_m.x()));
    const int sensorBy = BinGrid::blockOf(grid.cellIndex(sensor_m.y()));
    if (sensorBx < region.x0 || sensorBx >= region.x0 + int(region.nx) || sensorBy < region.y0 ||
        sensorBy >= region.y0 + int(region.ny))
        return towards;
    float nearSensor_m = -std::numeric_limits<float>::infinity();
    for (int by = sensorBy - 1; by <= sensorBy + 1; by++)
        for (int bx = sensorBx - 1; bx <= sensorBx + 1; bx++)
            nearSensor_m = std::max(nearSensor_m, region.blockBound(grid, bx, by));
    if (bounds.mayConflict(nearSensor_m, sensor_m.z() - 1e-6)) return towards;
    // Rows, then the blocks of a row, outwards from the sensor's: a block's rectangle is itself
    // and the rectangles of its neighbours towards the sensor (the same maxima in any order).
    // toX / toY: the offset of the neighbour towards the sensor's column / row, 0 in it.
    table.resize(size_t(region.nx) * region.ny);
    const ptrdiff_t nx = ptrdiff_t(region.nx), ny = ptrdiff_t(region.ny);
    const ptrdiff_t sensorX = sensorBx - region.x0, sensorY = sensorBy - region.y0;
    auto row = [&](ptrdiff_t y, ptrdiff_t toY) {
        auto block = [&](ptrdiff_t x, ptrdiff_t toX) {
            const ptrdiff_t i = x + y * nx;
            float r = region.bound_m[size_t(i)];
            if (toX != 0) r = std::max(r, table[size_t(i + toX)]);
            if (toY != 0) r = std::max(r, table[size_t(i + toY * nx)]);
            table[size_t(i)] = r;
        };
        for (ptrdiff_t x = sensorX; x >= 0; x--) block(x, x == sensorX ? 0 : 1);
        for (ptrdiff_t x = sensorX + 1; x < nx; x++) block(x, -1);
    };
    for (ptrdiff_t y = sensorY; y >= 0; y--) row(y, y == sensorY ? 0 : 1);
    for (ptrdiff_t y = sensorY + 1; y < ny; y++) row(y, -1);
    towards.bound_m = table.data();
    return towards;
}

bool rayTestsApply(const BinGrid& grid, const Region& region, const Eigen::Vector3d& sensor_m) {
    const double block_m = BinGrid::kBlockCells * grid.cellSize_m();
    const double regionExtent_m = std::max(
        {std::abs(sensor_m.x()), std::abs(sensor_m.y()), std::abs(double(region.x0)) * block_m,
         std::abs(double(region.y0)) * block_m, std::abs(double(region.x0) + region.nx) * block_m,
         std::abs(double(region.y0) + region.ny) * block_m});
    return !region.empty() && std::abs(sensor_m.z()) < kMaxRayHeight_m &&
           regionExtent_m < kMaxCoordinate_m;
}

}  // namespace multibin::visibility
