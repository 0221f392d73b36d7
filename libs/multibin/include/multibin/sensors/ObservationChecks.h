/* Part of the multibin elevation-mapping library. */
#pragma once

#include <mrpt/obs/CObservation.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/poses/CPose3D.h>
#include <mrpt/poses/CPose3DPDF.h>

#include <string>

namespace multibin::sensors {

/** @name Observation fields checked at the boundary
 * Every field of an MRPT observation that a sensor model reads is checked once, here, before any
 * model runs: a value the class cannot hold (a rotation matrix that is not a rotation, a negative
 * focal length or range unit, an absurd baseline, an aperture or azimuth span beyond a turn) is
 * an std::invalid_argument "<class> '<label>': <field> <problem>", never read as it is.
 * @{ */

/** Checks the fields of `obs` that its class's models read (sensor and camera poses, apertures
 * and azimuth spans, calibrations, range units); the 2D scan's aperture is the laser model's
 * (apertureProblem), which counts the beams it refuses. */
void checkObservationFields(const mrpt::obs::CObservation& obs);

/** Why the aperture of `scan` cannot give its beam angles (NaN, zero, negative or more than a
 * turn, with two beams or more), or "" if it can. */
std::string apertureProblem(const mrpt::obs::CObservation2DRangeScan& scan);

/** Checks that `pose` is finite and its rotation matrix a rotation (orthonormal, determinant
 * +1): MRPT builds a pose from a stored quaternion without normalising it, so a scaled or zero
 * one gives a scaled or zero matrix. `what` names the pose in the error. */
void checkPose(const mrpt::poses::CPose3D& pose, const std::string& what);

/** Checks a keyframe's pose PDF before its mean is taken: particles with none, or a sum of
 * Gaussians with no mode, hold no pose (MRPT's mean of them is the origin); the mean is then
 * checked as checkPose(). */
void checkPosePdf(const mrpt::poses::CPose3DPDF& pdf, const std::string& what);
/** @} */

}  // namespace multibin::sensors
