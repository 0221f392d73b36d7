/* Part of the multibin elevation-mapping library: the elevation-mapper program. */
#pragma once

#include <mrpt/maps/CMultiBinElevationMap.h>

#include <cstddef>
#include <string>
#include <vector>

/** What the run's counts say a user must know, one line each, printed at the end of the run:
 * no surface seen below the sensors (a horizontal laser maps walls, not terrain), every
 * observation mapped with the default pose covariance, most points rejected by one gate (named
 * with the option that governs it). Empty when the run needs no warning. */
struct RunFacts {
    /** Observations the map took points from with a pose covariance of the input's own
     * (CObservationRobotPose, odometry composed since one, a simplemap keyframe). */
    size_t observationsWithPoseCovariance = 0;
};

std::vector<std::string> runWarnings(const mrpt::maps::CMultiBinElevationMap& map,
                                     const RunFacts& facts);

/** The gate that rejected most of the points that reached a gate, if it rejected more than half
 * of them: "eq 13 gate (too uncertain): 8243 of 11305 points (73 %); governed by ...". Empty
 * otherwise. */
std::string dominantRejection(const mrpt::maps::CMultiBinElevationMap& map);
