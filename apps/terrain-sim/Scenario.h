/* Part of the multibin elevation-mapping library: terrain-sim. */
#pragma once

#include "LaserSim.h"
#include "StereoSim.h"
#include "Trajectory.h"

#include <cstdint>
#include <string>
#include <vector>

namespace terrain_sim {

/** Everything a terrain-sim run needs; defaults are the shipped set-up. */
struct ScenarioConfig {
    std::vector<std::string> terrainFiles;  //!< ESRI ASCII boards, tiled in this order (cycled)
    int tilesX = 3, tilesY = 3;             //!< tiles along x (walking direction) and y
    std::string scenario = "mockup";        //!< "mockup" or "walk"
    uint64_t seed = 1;
    std::string outPrefix;
    double gtCell_m = 0.015;  //!< ground-truth cell size (the paper's local grid) [m]
    double margin_m = 0.6;    //!< flat ground stored around the tiles [m]
    int darkPatches = 6;      //!< black discs on the boards
    LaserConfig laser;
    StereoConfig stereo;
    TrajectoryOptions trajectory;
};

struct ScenarioSummary {
    size_t frames = 0, stereoFrames = 0;
    size_t laserBeams = 0, laserReturns = 0, laserDropouts = 0, laserDark = 0, laserMixed = 0;
    std::vector<std::string> files;  //!< files written
};

/** Turns on the independent noise of doc/independent-evaluation.md (errors the library's models
 * do not describe, with the stated values): Student-t tails (4 dof) and 1 % outliers on both
 * sensors, a laser range bias of -2 mm + 1 % of the range, a mixed pixel at every laser depth edge
 * over 15 mm and at half the stereo depth edges, and calibration errors the written ini and
 * observations do not carry (laser pitch +0.3 deg, stereo baseline +0.3 mm, principal point
 * +0.5 px in u and v). */
void applyIndependentNoise(ScenarioConfig& cfg);

/** Makes every measurement and pose exact (`--noise exact`): no range or disparity noise, no
 * per-surface or dark-return range bias, no foreground fattening at stereo depth edges, the
 * estimated poses equal to the true ones; the written sigmas, pose covariances and ini unchanged,
 * so a map assumes its usual noise. What a map then misses is what the sensors never saw. */
void applyExactMeasurements(ScenarioConfig& cfg);

/** Builds the terrain, simulates the scenario and writes PREFIX.rawlog, PREFIX.simplemap,
 * PREFIX_gt.asc, PREFIX.ini and PREFIX_path.txt. Throws std::exception with a one-line message on
 * bad configuration or I/O failure. */
ScenarioSummary runScenario(const ScenarioConfig& cfg);

/** The elevation-mapper / CMultiMetricMap ini for a scenario (section prefix
 * [MappingApplication]), with the laser AGC and the stereo calibration sigmas of the contract. */
std::string mapperIni(const ScenarioConfig& cfg);

/** Synthetic timestamp of time t [s] since the start: a fixed epoch, never the clock. */
mrpt::Clock::time_point syntheticStamp(double t_s);

}  // namespace terrain_sim
