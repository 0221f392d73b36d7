/* Part of the multibin elevation-mapping library: observation fields checked at the boundary. */
#include "multibin/sensors/ObservationChecks.h"

#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/obs/CObservationPointCloud.h>
#include <mrpt/obs/CObservationRotatingScan.h>
#include <mrpt/obs/CObservationStereoImages.h>
#include <mrpt/obs/CObservationVelodyneScan.h>
#include <mrpt/poses/CPose3DPDFParticles.h>
#include <mrpt/poses/CPose3DPDFSOG.h>

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace multibin::sensors {
namespace {

constexpr double kFullTurn_rad = 6.283185307179586;
/** How far a stored rotation may be from orthonormal: float-stored poses are within 1e-6; a
 * scaled or zero matrix is off by its scale. */
constexpr double kRotationTolerance = 1e-4;
/** The longest stereo baseline a rig can have [m]: a rover's is below 1.5 m. */
constexpr double kMaxBaseline_m = 100;

/** "<class> '<label>'" of `obs`. */
std::string nameOf(const mrpt::obs::CObservation& obs) {
    return std::string(obs.GetRuntimeClass()->className) + " '" + obs.sensorLabel + "'";
}

[[noreturn]] void fail(const std::string& what, const std::string& field, double value,
                       const std::string& rule) {
    std::ostringstream os;
    os << what << ": " << field << " " << value << " " << rule;
    throw std::invalid_argument(os.str());
}

/** Checks a depth camera's focal lengths and centre (pixels): positive and finite, finite. */
void checkCamera(const mrpt::img::TCamera& c, const std::string& what, const std::string& field) {
    for (const auto& [name, v] : {std::pair{".fx", c.fx()}, {".fy", c.fy()}})
        if (!(v > 0 && std::isfinite(v)))
            fail(what, field + name, v, "px must be positive and finite");
    for (const auto& [name, v] : {std::pair{".cx", c.cx()}, {".cy", c.cy()}})
        if (!std::isfinite(v)) fail(what, field + name, v, "px must be finite");
}

void checkRotatingScan(const mrpt::obs::CObservationRotatingScan& s, const std::string& what) {
    checkPose(s.sensorPose, what + ": sensorPose");
    if (!(std::abs(s.azimuthSpan) > 0 && std::abs(s.azimuthSpan) <= kFullTurn_rad * (1 + 1e-6)))
        fail(what, "azimuthSpan", s.azimuthSpan, "rad must be non-zero and at most a turn");
    if (!std::isfinite(s.startAzimuth)) fail(what, "startAzimuth", s.startAzimuth, "rad");
    if (!(s.rangeResolution > 0 && std::isfinite(s.rangeResolution)))
        fail(what, "rangeResolution", s.rangeResolution, "m must be positive and finite");
    if (std::isnan(s.maxRange)) fail(what, "maxRange", s.maxRange, "m must be a number");
}

void checkStereo(const mrpt::obs::CObservationStereoImages& s, const std::string& what) {
    checkPose(mrpt::poses::CPose3D(s.cameraPose), what + ": cameraPose");
    checkPose(mrpt::poses::CPose3D(s.rightCameraPose), what + ": rightCameraPose");
    // A negative focal length the class cannot hold; the rest of the calibrations is the stereo
    // model's (it counts the pairs it refuses: badCalibration).
    for (const auto& [field, v] : {std::pair{"leftCamera.fx", s.leftCamera.fx()},
                                   {"leftCamera.fy", s.leftCamera.fy()},
                                   {"rightCamera.fx", s.rightCamera.fx()},
                                   {"rightCamera.fy", s.rightCamera.fy()}})
        if (v < 0) fail(what, field, v, "px: a focal length must not be negative");
    const double baseline_m = s.rightCameraPose.norm();
    if (!(baseline_m <= kMaxBaseline_m))
        fail(what, "rightCameraPose baseline", baseline_m, "m is beyond any stereo rig (100 m)");
}

void checkDepth(const mrpt::obs::CObservation3DRangeScan& s, const std::string& what) {
    checkPose(s.sensorPose, what + ": sensorPose");
    checkPose(s.relativePoseIntensityWRTDepth, what + ": relativePoseIntensityWRTDepth");
    if (!s.hasRangeImage) return;  // points given in 3D: no calibration, no range unit read
    checkCamera(s.cameraParams, what, "cameraParams");
    if (!(s.rangeUnits > 0 && std::isfinite(s.rangeUnits)))
        fail(what, "rangeUnits", s.rangeUnits, "m must be positive and finite");
}

}  // namespace

void checkPose(const mrpt::poses::CPose3D& pose, const std::string& what) {
    const auto& R = pose.getRotationMatrix();
    const Eigen::Matrix3d r = R.asEigen();
    const Eigen::Vector3d t(pose.x(), pose.y(), pose.z());
    if (!r.allFinite() || !t.allFinite()) throw std::invalid_argument(what + " is not finite");
    const double offOrthonormal =
        (r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    if (!(offOrthonormal <= kRotationTolerance) || !(r.determinant() > 0)) {
        std::ostringstream os;
        os << what << " has a rotation matrix that is not a rotation (R^T R differs from I by "
           << offOrthonormal << ", det " << r.determinant() << ")";
        throw std::invalid_argument(os.str());
    }
}

void checkPosePdf(const mrpt::poses::CPose3DPDF& pdf, const std::string& what) {
    if (const auto* p = dynamic_cast<const mrpt::poses::CPose3DPDFParticles*>(&pdf);
        p && p->size() == 0)
        throw std::invalid_argument(what + " is a particle set with no particles: no pose");
    if (const auto* s = dynamic_cast<const mrpt::poses::CPose3DPDFSOG*>(&pdf); s && s->size() == 0)
        throw std::invalid_argument(what + " is a sum of Gaussians with no mode: no pose");
    mrpt::poses::CPose3D mean;
    pdf.getMean(mean);
    checkPose(mean, what + " (its mean)");
}

std::string apertureProblem(const mrpt::obs::CObservation2DRangeScan& scan) {
    if (scan.getScanSize() < 2 ||
        (scan.aperture > 0 && scan.aperture <= kFullTurn_rad * (1 + 1e-6)))
        return {};
    return nameOf(scan) + ": aperture " + std::to_string(scan.aperture) +
           " rad must be in (0, 2 pi] rad";
}

void checkObservationFields(const mrpt::obs::CObservation& obs) {
    const std::string what = nameOf(obs);
    if (const auto* s = dynamic_cast<const mrpt::obs::CObservation2DRangeScan*>(&obs)) {
        checkPose(s->sensorPose, what + ": sensorPose");
    } else if (const auto* st = dynamic_cast<const mrpt::obs::CObservationStereoImages*>(&obs)) {
        checkStereo(*st, what);
    } else if (const auto* d = dynamic_cast<const mrpt::obs::CObservation3DRangeScan*>(&obs)) {
        checkDepth(*d, what);
    } else if (const auto* c = dynamic_cast<const mrpt::obs::CObservationPointCloud*>(&obs)) {
        checkPose(c->sensorPose, what + ": sensorPose");
    } else if (const auto* v = dynamic_cast<const mrpt::obs::CObservationVelodyneScan*>(&obs)) {
        checkPose(v->sensorPose, what + ": sensorPose");
    } else if (const auto* r = dynamic_cast<const mrpt::obs::CObservationRotatingScan*>(&obs)) {
        checkRotatingScan(*r, what);
    }
}

}  // namespace multibin::sensors
