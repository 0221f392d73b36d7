/* Part of the multibin elevation-mapping library: terrain-sim. Maps a random scene with the
 * library's default options (and MRPT's CHeightGridMap2D on the same points) and scores it
 * against the scene's truth (doc/random-scenes.md). */
#pragma once

#include "RandomScene.h"

#include <cstddef>
#include <functional>
#include <limits>

namespace mrpt::maps {
class CMultiBinElevationMap;
}

namespace terrain_sim {

/** The issue-38 quantities of one scene; NaN where the scene has no such cells. */
struct RandomSceneScores {
    static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
    /** Vacated object: cells over a footprint the object left, grown by one cell. RMSE from the
     * ground of dem_get_z (after dem_update_map) and of MRPT's mean [m]. */
    double objectRmse_m = kNaN, objectMrptRmse_m = kNaN;
    /** The same cells in the map of the scene with the object never there: the floor [m]. */
    double objectNoObjectRmse_m = kNaN;
    /** The same over the cells a pass after the last one in which the object stood on them
     * (footprint + 1 cell) put a laser point in (the others no observation could correct) [m],
     * and their number. */
    double objectSeenAgainRmse_m = kNaN;
    size_t objectSeenAgainCells = 0;
    size_t objectCells = 0, objectUnknown = 0;
    double objectWorstError_m = kNaN;  //!< largest |DEM - ground| over those cells [m]
    /** What those cells hold at the end (a bin "at the ground" lies within 30 mm of the truth),
     * and the squared error [m^2] summed over each kind, [kind][1] over the cells seen again
     * (objectSeenAgainRmse_m), [kind][0] over the others: why the object's place is wrong, and
     * whether any later observation could have told. */
    enum CellKind { StaleWinsBesideGround, OnlyStale, NoBin, GroundWins, kCellKinds };
    double objectSquaredError_m2[kCellKinds][2] = {};
    size_t objectCellsOfKind[kCellKinds][2] = {};
    /** Static terrain (every measured cell away from the object's placements), the map with the
     * object and the same scene mapped with the object never there, on the cells both measured. */
    double staticRmse_m = kNaN, staticRmseNoObject_m = kNaN;
    double staticMrptRmse_m = kNaN;  //!< MRPT's mean on those cells (where it has data) [m]
    size_t staticCells = 0;
    /** Filled cells where MRPT's grid has no data: RMSE of the map's filled heights [m]. */
    double filledRmse_m = kNaN;
    size_t filledCells = 0;
    /** Random query points on the boards (away from the object): heightAt() and MRPT's cell at
     * the same points, both against the true surface there [m]. */
    double queryRmse_m = kNaN, queryMrptRmse_m = kNaN;
    /** The floor of any one-height-per-cell map there: the true mean of the point's cell [m]. */
    double queryFloorRmse_m = kNaN;
    size_t queryPoints = 0;
};

/** Maps every pass of the scene (laser, 10 Hz, the pass's pose PDFs) into a
 * CMultiBinElevationMap (default options, then `configure` if given, e.g. options from an ini)
 * and a CHeightGridMap2D (mean) fed the same points, and once more with the object never there,
 * then scores both against the scene's ground. */
RandomSceneScores scoreRandomScene(
    const RandomScene& scene,
    const std::function<void(mrpt::maps::CMultiBinElevationMap&)>& configure = {});

}  // namespace terrain_sim
