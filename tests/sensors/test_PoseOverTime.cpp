/* The pose of each observation of a rawlog over time (apps/elevation-mapper/PoseOverTime.h,
 * RawlogSource): the latest CObservationRobotPose within robot_pose_max_dt_s, else that pose
 * composed with the odometry since it (covariance grown), else the default; counted. */
#include <gtest/gtest.h>
#include <mrpt/io/CMemoryStream.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationRobotPose.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPosePDFGaussian.h>
#include <mrpt/serialization/CArchive.h>

#include <string>
#include <vector>

#include "RawlogSource.h"

namespace {
mrpt::Clock::time_point at(double t_s) {
    return mrpt::Clock::fromDouble(1.7e9 + t_s);  // a fixed epoch: the test is deterministic
}

mrpt::obs::CObservation2DRangeScan::Ptr scanAt(double t_s, const std::string& label) {
    auto scan = mrpt::obs::CObservation2DRangeScan::Create();
    scan->sensorLabel = label;
    scan->resizeScan(3);
    for (size_t i = 0; i < 3; i++) scan->setScanRange(i, 1.f), scan->setScanRangeValidity(i, true);
    scan->timestamp = at(t_s);
    return scan;
}

mrpt::obs::CObservationRobotPose::Ptr robotPoseAt(double t_s, double x_m) {
    auto rp = mrpt::obs::CObservationRobotPose::Create();
    rp->pose.mean = mrpt::poses::CPose3D(x_m, 0, 0, 0, 0, 0);
    for (int i = 0; i < 6; i++) rp->pose.cov(i, i) = 1e-4;
    rp->timestamp = at(t_s);
    return rp;
}

struct Seen {
    std::string label;
    mrpt::poses::CPose3DPDFGaussian pose;
    bool hasCov;
};
}  // namespace

// A robot pose at t = 0 (x = 1 m), then 1 m of odometry (MRPT's Gaussian motion model), then a scan
// at t = 2 s: the scan is at x = 2 m with the pose's covariance grown by the odometry's (before: at
// x = 1 m, the first pose, forever). A second robot pose at t = 10 s serves a scan 0.2 s later; a
// scan at t = 20 s with no odometry since gets the default covariance (before: the 10 s-old
// pose's).
TEST(PoseOverTime, LatestRobotPoseThenOdometrySinceItThenTheDefault) {
    mrpt::io::CMemoryStream mem;
    auto out = mrpt::serialization::archiveFrom(mem);
    auto frame = [&](std::vector<mrpt::obs::CObservation::Ptr> obs) {
        mrpt::obs::CSensoryFrame sf;
        for (auto& o : obs) sf.insert(o);
        out << sf;
    };
    frame({robotPoseAt(0, 1.0), scanAt(0.1, "A")});
    double stepVarX_m2 = 0;
    {
        mrpt::obs::CActionCollection acts;
        mrpt::obs::CActionRobotMovement2D move;
        // MRPT stores the raw odometry and rebuilds the PDF from the motion model when read.
        mrpt::obs::CActionRobotMovement2D::TMotionModelOptions model;
        model.modelSelection = mrpt::obs::CActionRobotMovement2D::mmGaussian;
        move.computeFromOdometry(mrpt::poses::CPose2D(1, 0, 0), model);
        stepVarX_m2 = move.poseChange->getCovariance()(0, 0);
        acts.insert(move);
        out << acts;
    }
    frame({scanAt(2.0, "B")});
    frame({robotPoseAt(10.0, 5.0), scanAt(10.2, "C")});
    frame({scanAt(20.0, "D")});
    mem.Seek(0);

    std::vector<Seen> seen;
    PoseCounts counts;
    RawlogSource::forEachInStream(
        mem, "test", mem.getTotalBytesCount(),
        [&](const mrpt::obs::CObservation::Ptr& obs, const mrpt::poses::CPose3DPDFGaussian& pose,
            bool hasCov) {
            if (!std::dynamic_pointer_cast<mrpt::obs::CObservationRobotPose>(obs))
                seen.push_back({obs->sensorLabel, pose, hasCov});
        },
        {}, 0.5, &counts);
    ASSERT_EQ(seen.size(), 4u);
    EXPECT_TRUE(seen[0].hasCov);
    EXPECT_NEAR(seen[0].pose.mean.x(), 1.0, 1e-9);
    EXPECT_TRUE(seen[1].hasCov);
    EXPECT_NEAR(seen[1].pose.mean.x(), 2.0, 1e-9);  // the pose + the odometry since it
    ASSERT_GT(stepVarX_m2, 1e-4);
    EXPECT_NEAR(seen[1].pose.cov(0, 0), 1e-4 + stepVarX_m2, 1e-6);  // grown by the odometry's
    EXPECT_TRUE(seen[2].hasCov);
    EXPECT_NEAR(seen[2].pose.mean.x(), 5.0, 1e-9);
    EXPECT_NEAR(seen[2].pose.cov(0, 0), 1e-4, 1e-12);
    EXPECT_FALSE(seen[3].hasCov);  // 10 s old, no odometry since: the map's default
    EXPECT_NEAR(seen[3].pose.mean.x(), 5.0, 1e-9);
    EXPECT_EQ(counts.robotPose, 2u);
    EXPECT_EQ(counts.odometrySinceRobotPose, 1u);
    EXPECT_EQ(counts.defaultCovariance, 1u);
}
