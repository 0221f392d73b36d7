/* Part of the multibin elevation-mapping library: the Python module.
 * numpy input checked before it reaches the map: shapes, dtypes, finiteness, covariances. Every
 * error names the Python function, the argument and the problem. */
#pragma once

#include <mrpt/math/CMatrixFixed.h>
#include <mrpt/poses/CPose3D.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>

#include "multibin/geometry/PointsWithCovariance.h"

namespace multibin::python {

/** A real-valued numpy array in C order as float64: `obj` converted (lists, float32 and integer
 * arrays too). Throws pybind11::type_error if `obj` is not an array of real numbers (complex,
 * bool, object, strings). `where` is "function: argument" for messages. */
pybind11::array_t<double, pybind11::array::c_style> realArray(const pybind11::handle& obj,
                                                              const std::string& where);

/** Points Nx3 [m] and their covariances Nx3x3 [m^2] as the library's points; `offset_m` is
 * subtracted from x and y (the map origin: the library's points are relative to it). Throws
 * ValueError (std::invalid_argument) for a wrong shape, a non-finite coordinate or covariance
 * entry, a covariance that is not symmetric or not positive semi-definite, naming the index. */
PointsWithCov pointsWithCovariance(const std::string& function, const pybind11::handle& points,
                                   const pybind11::handle& covariances, double offsetX_m = 0,
                                   double offsetY_m = 0);

/** A 6-DoF pose (x, y, z [m], yaw, pitch, roll [rad]: MRPT's CPose3D order), finite. */
mrpt::poses::CPose3D pose6(const std::string& where, const pybind11::handle& pose);

/** A 6x6 pose covariance over (x, y, z, yaw, pitch, roll): finite, symmetric, positive
 * semi-definite. */
mrpt::math::CMatrixDouble66 poseCovariance(const std::string& where, const pybind11::handle& cov);

}  // namespace multibin::python
