/* Part of the multibin elevation-mapping library. */
#pragma once

#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/poses/CPose3D.h>
#include <mrpt/poses/CPose3DPDFGaussian.h>

#include <limits>
#include <string>
#include <vector>

#include "multibin/geometry/PointsWithCovariance.h"
#include "multibin/sensors/SensorModelOptions.h"
#include "multibin/sensors/SensorStats.h"

namespace multibin::sensors {

/** Restored intensity of eq 1 [-]: Ires = sqrt(I * 1023 / vAGC), I the raw intensity, vAGC the
 * AGC voltage (raw units). */
double restoredIntensity(double rawIntensity, double agcVoltage);

/** Mixed-pixel detection by clustering. `ranges_m` holds one range per beam in scan order, with
 * +infinity for beams without a return. Consecutive beams whose ranges differ by at most
 * `opts.mixedPixelJump_m` form a cluster; a cluster of at most `opts.mixedPixelMaxBeams` beams
 * whose ranges all lie strictly between the ranges of the beams just before and just after it
 * (no return counting as infinitely far) is a mixed measurement: the beam straddled a foreground
 * edge and the background; unless the cluster continues the linear trend of the two beams
 * before it or of the two beams after it (a surface seen at a grazing angle: large steps, steady
 * slope). A small cluster nearer (or farther) than both neighbours is a thin object and is kept.
 * Returns one flag per beam, true = mixed. */
std::vector<bool> findMixedPixels(const std::vector<float>& ranges_m,
                                  const LaserModelOptions& opts);

/** Points of a laser scan in its sensor frame with range-only covariance along the beam
 * (sigma_r(r) of opts.rangeSigma; the bearing is taken as exact, eq 3). Beams without a return,
 * NaN, outside [minRange_m, maxRange_m], of low restored intensity (when the scan has intensities
 * and opts.agcByLabel has the scan's label) or mixed are skipped and counted in `stats`. */
void laserScanToPoints(const mrpt::obs::CObservation2DRangeScan& scan,
                       const LaserModelOptions& opts, double minRange_m, double maxRange_m,
                       PointsWithCov& out, LaserStats& stats);

/** Eq 14's Delta_zmax(k) [m]: the largest height change between a bin estimated from the previous
 * scan and a point of this scan that range error and pose error allow,
 *
 *   Delta_zmax = n * max_i sqrt(2 sigma_zr,i^2 + sigma_zp,i^2) + allowance,
 *
 * sigma_zr,i = sigma_r(r_i) |e_z . d_i| the height error of point i from its range error (d_i the
 * beam in the map frame; two such errors, the bin's and the point's), sigma_zp,i the height error
 * of the difference of the two scans' pose errors at point i:
 * sigma_zp^2 = s_a^2 + s_b^2 - 2 rho s_a s_b, s_a^2 = (J_R C_prev J_R^T)_zz,
 * s_b^2 = (J_R C_cur J_R^T)_zz, rho = opts.continuityPoseCorrelation, J_R the Jacobian of the map
 * point w.r.t. the robot pose, evaluated at point i for both poses. n = opts.continuitySigmas,
 * allowance = opts.continuityAllowance_m (terrain relief inside a cell). Points are sensor-frame
 * points of this scan. Returns +infinity for an empty scan. */
double continuityBound_m(const PointsWithCov& sensorPoints, const mrpt::poses::CPose3D& sensorPose,
                         const mrpt::poses::CPose3DPDFGaussian& previousRobotPose,
                         const mrpt::poses::CPose3DPDFGaussian& currentRobotPose,
                         const LaserModelOptions& opts);

}  // namespace multibin::sensors
