/* Accuracy of a map's heights at query points that lie on no lattice: the one-height-per-cell
 * floor, the cell's value (nearest), bilinear interpolation of the cell values and the sub-cell
 * surface (heightAt), all at the same points against the truth there. Used by the test
 * SubCellSurface.* and by the tool surface_accuracy (doc/sub-cell-surface.md). */
#pragma once

#include <mrpt/maps/CMultiBinElevationMap.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

namespace multibin::test {

struct SurfaceAccuracy {
    size_t points = 0;               //!< query points scored (every method answers at each)
    double floor_m = 0;              //!< RMSE of the exact mean of the truth over each cell [m]
    double nearest_m = 0;            //!< RMSE of the cell's value (cellHeight) [m]
    double bilinear_m = 0;           //!< RMSE of bilinear interpolation of the cell values [m]
    double heightAt_m = 0;           //!< RMSE of the sub-cell surface (heightAt) [m]
    double within3Sigma = 0;         //!< fraction of |heightAt - truth| <= 3 sigma
    double nearestWithin3Sigma = 0;  //!< the same for the cell's value and its sigma
    size_t drawn = 0;                //!< points drawn to find `points` where all answer
};

/** One scored query point: each method's error [m] and the truth's relief in its cell. */
struct QueryPointErrors {
    std::array<double, 4> error_m;  //!< floor, nearest, bilinear, heightAt: answer - truth [m]
    double cellRelief_m;            //!< highest minus lowest truth sample of the point's cell [m]
    double x_m, y_m, truth_m;       //!< the query point and the true height there [m]
};

/** `count` uniformly random points in [x0, x1) x [y0, y1) (seed `seed`) where the truth, every
 * method and the four cells around the point (for bilinear) have a height. `truth(x, y)` is the
 * true height (NaN if unknown); the cell mean is the mean of `truth` over a 10 x 10 grid of
 * sub-samples of the cell (NaN if any is). */
inline SurfaceAccuracy measureSurfaceAccuracy(const mrpt::maps::CMultiBinElevationMap& map,
                                              const std::function<double(double, double)>& truth,
                                              double x0, double x1, double y0, double y1,
                                              size_t count, unsigned seed,
                                              std::vector<QueryPointErrors>* errors = nullptr) {
    const double s = map.dem_get_resolution();
    auto cellIndex = [s](double v) { return static_cast<int>(std::floor(v / s)); };
    // The cell's mean of the truth; also its relief (max - min of the samples).
    auto cellMean = [&](int ix, int iy, double& relief_m) {
        double sum = 0, lo = INFINITY, hi = -INFINITY;
        for (int j = 0; j < 10; j++)
            for (int i = 0; i < 10; i++) {
                const double t = truth((ix + (i + 0.5) / 10) * s, (iy + (j + 0.5) / 10) * s);
                sum += t;
                lo = std::min(lo, t);
                hi = std::max(hi, t);
            }
        relief_m = hi - lo;
        return sum / 100;
    };
    auto cellValue = [&](int ix, int iy, double& h) {
        double sigma;
        return map.cellHeight((ix + 0.5) * s, (iy + 0.5) * s, h, sigma);
    };
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> ux(x0, x1), uy(y0, y1);
    SurfaceAccuracy a;
    double se[4] = {0, 0, 0, 0};
    size_t within = 0, nearestWithin = 0;
    while (a.points < count && a.drawn < 50 * count) {
        a.drawn++;
        const double x = ux(rng), y = uy(rng);
        const double t = truth(x, y);
        if (!std::isfinite(t)) continue;
        double relief_m;
        const double floorValue = cellMean(cellIndex(x), cellIndex(y), relief_m);
        double hNear, sNear, hAt, sAt;
        if (!std::isfinite(floorValue) || !map.cellHeight(x, y, hNear, sNear) ||
            !map.heightAt(x, y, hAt, sAt))
            continue;
        // Bilinear between the four cell centres around the point.
        const int bx = cellIndex(x - 0.5 * s), by = cellIndex(y - 0.5 * s);
        const double fx = (x - (bx + 0.5) * s) / s, fy = (y - (by + 0.5) * s) / s;
        double h00, h10, h01, h11;
        if (!cellValue(bx, by, h00) || !cellValue(bx + 1, by, h10) || !cellValue(bx, by + 1, h01) ||
            !cellValue(bx + 1, by + 1, h11))
            continue;
        const double hBilinear =
            (1 - fy) * ((1 - fx) * h00 + fx * h10) + fy * ((1 - fx) * h01 + fx * h11);
        const double e[4] = {floorValue - t, hNear - t, hBilinear - t, hAt - t};
        for (int k = 0; k < 4; k++) se[k] += e[k] * e[k];
        if (errors) errors->push_back({{e[0], e[1], e[2], e[3]}, relief_m, x, y, t});
        if (std::abs(e[3]) <= 3 * sAt) within++;
        if (std::abs(e[1]) <= 3 * sNear) nearestWithin++;
        a.points++;
    }
    if (a.points == 0) return a;
    const double n = double(a.points);
    a.floor_m = std::sqrt(se[0] / n);
    a.nearest_m = std::sqrt(se[1] / n);
    a.bilinear_m = std::sqrt(se[2] / n);
    a.heightAt_m = std::sqrt(se[3] / n);
    a.within3Sigma = double(within) / n;
    a.nearestWithin3Sigma = double(nearestWithin) / n;
    return a;
}

}  // namespace multibin::test
