/* Part of the multibin elevation-mapping library: terrain-sim. Maps a random scene with the
 * library's default options (and MRPT's CHeightGridMap2D on the same points) and scores it
 * against the scene's truth (doc/random-scenes.md). */
#pragma once

#include "RandomScene.h"

#include <array>
#include <cmath>
#include <cstddef>
#include <functional>
#include <limits>
#include <vector>

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

/** Stereo only (`random-scenes --sensor stereo`): the library's map and the naive pipeline
 * (NaiveStereo.h) fed the same rendered pairs, scored against the truth raster. */
struct StereoSceneScores {
    /** One scored area: cells with a truth, held by each (the map: measured cells, getHeight();
     * the naive grid: cells with a point), and the squared errors on the cells both hold. */
    struct Area {
        size_t truthCells = 0, mapCells = 0, naiveCells = 0, commonCells = 0;
        double mapSumSq_m2 = 0, naiveSumSq_m2 = 0;
        /** Where the error sits: common cells the map has more than kFar_m off, and their part
         * of the map's (and of the naive grid's) squared error. */
        static constexpr double kFar_m = 0.03;
        size_t mapFarCells = 0;
        double mapFarSumSq_m2 = 0, naiveOnMapFarSumSq_m2 = 0;
        /** Cells only the naive grid holds, and its squared error there: what its extra
         * coverage is worth. Cells each holds within kFar_m of the truth (all it holds). */
        size_t naiveOnlyCells = 0;
        double naiveOnlySumSq_m2 = 0;
        size_t mapGood = 0, naiveGood = 0;
        /** Common cells within 2 cells of a step of the truth (truths more than kStep_m apart
         * within 5 x 5 cells: the boards' edges, drops between tiles, steep rock), and both
         * squared errors there. */
        static constexpr double kStep_m = 0.1;
        size_t stepCells = 0;
        double mapStepSumSq_m2 = 0, naiveStepSumSq_m2 = 0;
        /** The RMSE ratio on the common cells away from such steps, and on them. */
        double ratioOffSteps() const;
        double ratioOnSteps() const { return std::sqrt(mapStepSumSq_m2 / naiveStepSumSq_m2); }
        double mapRmse_m() const;
        double naiveRmse_m() const;
        double mapCoverage() const { return truthCells ? double(mapCells) / truthCells : 0; }
        double naiveCoverage() const { return truthCells ? double(naiveCells) / truthCells : 0; }
    };
    Area boards;  //!< the tiles (rough, textured ground), away from every placement + 1 cell
    Area raster;  //!< the whole truth raster (flat textureless margin too), same exclusion
    size_t stereoFrames = 0;
    /** Per cell of `boards` either holds, when asked for: x, y, truth, map, map sigma, naive [m]
     * (NaN where one holds nothing). */
    std::vector<std::array<double, 6>> cells;
};

/** Renders every pass's stereo pairs (1 Hz, the scene's texture and camera, the object where it
 * stands in that pass) and feeds them (a) to a CMultiBinElevationMap with default options and the
 * rig's calibration sigmas (mapperIni), then `configure` if given, each pair with its frame's pose
 * PDF, and (b) to the naive pipeline at the estimated pose, at the map's cell size. `keepCells`
 * fills StereoSceneScores::cells; `naiveAsMap` is a control: the naive pipeline stands in for
 * the map too, so that a check of the bound can be seen to fail. */
StereoSceneScores scoreRandomSceneStereo(
    const RandomScene& scene,
    const std::function<void(mrpt::maps::CMultiBinElevationMap&)>& configure = {},
    bool keepCells = false, bool naiveAsMap = false);

/** Maps every pass of the scene (laser, 10 Hz, the pass's pose PDFs) into a
 * CMultiBinElevationMap (default options, then `configure` if given, e.g. options from an ini)
 * and a CHeightGridMap2D (mean) fed the same points, and once more with the object never there,
 * then scores both against the scene's ground. */
RandomSceneScores scoreRandomScene(
    const RandomScene& scene,
    const std::function<void(mrpt::maps::CMultiBinElevationMap&)>& configure = {});

}  // namespace terrain_sim
