/* Part of the multibin elevation-mapping library: terrain-sim. The naive stereo pipeline a user
 * would write without the library (doc/sensor-models.md, "Stereo against the naive pipeline"):
 * OpenCV's StereoSGBM with the library's default parameters (so without its left-border padding,
 * `stereo_sgbm_full_width`), every pixel with a disparity triangulated and averaged in MRPT's
 * CHeightGridMap2D (mrSimpleAverage). Header-only: tests/sensors/stereo_naive.h (the fixed
 * scenarios) and the random scenes' stereo mode (RandomSceneScore.cpp) share it. */
#pragma once

#include <mrpt/maps/CHeightGridMap2D.h>
#include <mrpt/obs/CObservationStereoImages.h>
#include <mrpt/poses/CPose3D.h>

#include "multibin/sensors/StereoDisparity.h"
#include "multibin/sensors/StereoModel.h"

namespace terrain_sim {

/** Matches the pair of `obs` with SGBM (`sgbm`: the library's defaults unless an experiment
 * changes them) and inserts every triangulated pixel, seen from the robot pose `robot` (the
 * estimate's mean), into `grid`. The observation's disparity image, if any, is not used. */
inline void insertNaiveStereo(mrpt::maps::CHeightGridMap2D& grid,
                              const mrpt::obs::CObservationStereoImages& obs,
                              const mrpt::poses::CPose3D& robot,
                              const multibin::sensors::StereoModelOptions& sgbm = {}) {
    const auto g = multibin::sensors::StereoGeometry::fromObservation(obs);
    const auto disp = multibin::sensors::computeDisparitySGBM(obs.imageLeft, obs.imageRight, sgbm);
    const mrpt::poses::CPose3D cam = robot + mrpt::poses::CPose3D(obs.cameraPose);
    for (int v = 0; v < disp.height; v++)
        for (int u = 0; u < disp.width; u++) {
            if (!disp.valid(u, v)) continue;
            const Eigen::Vector3d p = g.triangulate(u, v, disp.at(u, v));
            double x, y, z;
            cam.composePoint(p.x(), p.y(), p.z(), x, y, z);
            grid.insertIndividualPoint(x, y, z);
        }
}

}  // namespace terrain_sim
