/* Part of the multibin elevation-mapping library: terrain-sim. */
#include "Scenario.h"

#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/maps/CSimpleMap.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CObservationRobotPose.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/serialization/CArchive.h>

#include <cstdio>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace terrain_sim {

mrpt::Clock::time_point syntheticStamp(double t_s) {
    // 2012-12-11 00:00:00 UTC (ROBIO 2012) as the start of every scenario.
    return mrpt::Clock::fromDouble(1355184000.0 + t_s);
}

namespace {

std::string joinSigmas(const double* v, size_t n) {
    std::ostringstream s;
    s << std::setprecision(6);
    for (size_t i = 0; i < n; ++i) s << (i ? " " : "") << v[i];
    return s.str();
}

void writeText(const std::string& path, const std::string& text) {
    std::ofstream f(path, std::ios::binary);
    if (!f) throw std::runtime_error("cannot write '" + path + "'");
    f << text;
    if (!f) throw std::runtime_error("error writing '" + path + "'");
}

}  // namespace

std::string mapperIni(const ScenarioConfig& cfg) {
    const auto& s = cfg.stereo;
    std::ostringstream o;
    o << std::setprecision(10);
    o << "# Written by terrain-sim (scenario " << cfg.scenario << ", seed " << cfg.seed
      << "): a CMultiMetricMap / elevation-mapper ini\n"
      << "# for this scenario's rawlog and simplemap. Stereo calibration (rectified, zero "
         "distortion):\n"
      << "#   " << s.width_px << "x" << s.height_px << " px, fx = fy = " << s.fx_px()
      << " px, cx = " << s.cx_px() << " px, cy = " << s.cy_px()
      << " px, baseline = " << s.baseline_m << " m\n"
      << "[MappingApplication]\n"
      << "multiBinElevationMap_count = 1\n\n"
      << "[MappingApplication_multiBinElevationMap_00_creationOpts]\n"
      << "resolution_m = " << cfg.gtCell_m << "\n"
      << "bin_height_m = 0.05\n\n"
      << "[MappingApplication_multiBinElevationMap_00_insertOpts]\n"
      << "# AGC voltage of each laser, for eq 1: Ires = sqrt(I * 1023 / vAGC)\n"
      << "laser_agc = " << cfg.laser.label << ":" << cfg.laser.agc << "\n"
      << "# Calibration standard deviations: fx fy cx cy k1 k2 p1 p2 k3 [px px px px - - - - -]\n"
      << "stereo_left_intrinsics_sigma = " << joinSigmas(s.intrinsicsSigma.data(), 9) << "\n"
      << "stereo_right_intrinsics_sigma = " << joinSigmas(s.intrinsicsSigma.data(), 9) << "\n"
      << "# Right camera relative to the left: rx ry rz [rad] tx ty tz [m]\n"
      << "stereo_extrinsics_sigma = " << joinSigmas(s.extrinsicsSigma.data(), 6) << "\n"
      << "stereo_matching_sigma_px = " << s.matchingSigma_px << "\n";
    return o.str();
}

void applyIndependentNoise(ScenarioConfig& cfg) {
    for (ErrorShape* e : {&cfg.laser.errors, &cfg.stereo.errors}) {
        e->tailDof = 4;
        e->outlierFraction = 0.01;
        e->outlierSpan = 0.5;
    }
    cfg.laser.rangeBias0_m = -0.002;
    cfg.laser.rangeBiasSlope = 0.01;
    cfg.laser.mixedProbability = 1.0;
    cfg.laser.mixedJump_m = 0.015;
    cfg.laser.pitchError_rad = 0.3 * M_PI / 180.0;
    cfg.stereo.mixedProbability = 0.5;
    cfg.stereo.baselineError_m = 0.0003;
    cfg.stereo.cxError_px = 0.5;
    cfg.stereo.cyError_px = 0.5;
}

void applyExactMeasurements(ScenarioConfig& cfg) {
    cfg.laser.errors.drawnErrorScale = 0;
    cfg.stereo.errors.drawnErrorScale = 0;
    cfg.stereo.haloWidth_px = 0;
    cfg.trajectory.poseErrorScale = 0;
}

ScenarioSummary runScenario(const ScenarioConfig& cfg) {
    cfg.laser.errors.validate("laser");
    cfg.stereo.errors.validate("stereo");
    if (!(cfg.laser.mixedProbability >= 0 && cfg.laser.mixedProbability <= 1) ||
        !(cfg.stereo.mixedProbability >= 0 && cfg.stereo.mixedProbability <= 1))
        throw std::invalid_argument("mixed-pixel probability must be in [0, 1]");
    if (!(cfg.laser.mixedJump_m > 0))
        throw std::invalid_argument("laser mixed-pixel jump must be > 0");
    if (cfg.outPrefix.empty()) throw std::invalid_argument("no output prefix (--out) given");
    if (cfg.terrainFiles.empty()) throw std::invalid_argument("no terrain file (--terrain) given");
    if (cfg.scenario != "mockup" && cfg.scenario != "walk")
        throw std::invalid_argument("unknown scenario '" + cfg.scenario +
                                    "' (expected mockup or walk)");
    std::vector<multibin::EsriAsciiGrid> boards;
    for (const auto& f : cfg.terrainFiles) boards.push_back(multibin::EsriAsciiGrid::load(f));
    const Terrain terrain = Terrain::fromBoards(boards, cfg.tilesX, cfg.tilesY, cfg.margin_m);
    const multibin::EsriAsciiGrid groundTruth = terrain.groundTruth(cfg.gtCell_m);  // fail early
    const SurfaceTexture texture(terrain, cfg.seed, cfg.darkPatches);
    const LaserSim laser(cfg.laser, terrain, texture, cfg.seed);
    const StereoSim stereo(cfg.stereo, terrain, texture);

    // Independent random streams, so that changing one sensor leaves the others' noise alone.
    std::mt19937_64 poseRng(hash64(cfg.seed * 3 + 1)), laserRng(hash64(cfg.seed * 3 + 2)),
        stereoRng(hash64(cfg.seed * 3 + 3));
    const std::vector<Frame> frames = cfg.scenario == "mockup"
                                          ? mockupTrajectory(terrain, cfg.trajectory, poseRng)
                                          : walkTrajectory(terrain, cfg.trajectory, poseRng);
    if (frames.empty()) throw std::invalid_argument("the trajectory has no frames");

    ScenarioSummary sum;
    const std::string rawlogPath = cfg.outPrefix + ".rawlog";
    mrpt::io::CFileGZOutputStream rawOut;
    if (!rawOut.open(rawlogPath)) throw std::runtime_error("cannot write '" + rawlogPath + "'");
    auto rawArch = mrpt::serialization::archiveFrom(rawOut);
    mrpt::maps::CSimpleMap simplemap;
    std::ostringstream path;
    path << "# terrain-sim true robot path, scenario " << cfg.scenario << ", seed " << cfg.seed
         << "\n# Map frame: +x forward (walking direction), +y left, +z up [m]; robot frame\n"
         << "# origin on the ground under the body centre; angles in MRPT's convention\n"
         << "# (yaw about z, then pitch about y (positive = nose down), then roll about x) [rad].\n"
         << "# Laser pose = robot (+) laser sensorPose, left camera = robot (+) cameraPose (see "
            "the rawlog).\n"
         << "# frame t_s x_m y_m z_m yaw_rad pitch_rad roll_rad stereo\n";
    path << std::setprecision(9);
    std::vector<BeamTruth> beams;
    mrpt::poses::CPose2D previousEstimate(frames.front().estimate.mean);
    for (size_t k = 0; k < frames.size(); ++k) {
        const Frame& f = frames[k];
        const auto stamp = syntheticStamp(f.t_s);
        auto poseObs = mrpt::obs::CObservationRobotPose::Create();
        poseObs->sensorLabel = "ROBOT_POSE";
        poseObs->timestamp = stamp;
        poseObs->pose = f.estimate;
        auto scan = laser.scan(f.truth, stamp, laserRng, &beams);
        for (const auto& b : beams) {
            sum.laserBeams++;
            sum.laserDropouts += b.dropout;
            sum.laserDark += b.dark;
            sum.laserMixed += b.mixed;
        }
        for (size_t i = 0; i < scan->getScanSize(); ++i)
            sum.laserReturns += scan->getScanRangeValidity(i);
        auto sf = mrpt::obs::CSensoryFrame::Create();
        auto sfMap = mrpt::obs::CSensoryFrame::Create();  // simplemap: the keyframe PDF is the pose
        sf->insert(poseObs);
        sf->insert(scan);
        sfMap->insert(scan);
        if (f.stereo) {
            auto st = stereo.observation(stereo.render(f.truth, stereoRng), stamp);
            sf->insert(st);
            sfMap->insert(st);
            sum.stereoFrames++;
        }
        // Odometry: the planar (x, y, yaw) increment of the pose estimate since the previous
        // frame, so that
        // RawLogViewer and MRPT's odometry-based tools show the path. The mapper takes its poses
        // from ROBOT_POSE (mean and covariance), which overrides odometry.
        mrpt::obs::CActionCollection acts;
        mrpt::obs::CActionRobotMovement2D odo;
        odo.timestamp = stamp;
        const mrpt::poses::CPose2D estimate(f.estimate.mean);  // x, y, yaw
        odo.computeFromOdometry(estimate - previousEstimate,
                                mrpt::obs::CActionRobotMovement2D::TMotionModelOptions());
        acts.insert(odo);
        previousEstimate = estimate;
        rawArch << acts << *sf;
        simplemap.insert(mrpt::poses::CPose3DPDFGaussian::Create(f.estimate), sfMap);
        const auto& p = f.truth;
        path << k << " " << f.t_s << " " << p.x() << " " << p.y() << " " << p.z() << " " << p.yaw()
             << " " << p.pitch() << " " << p.roll() << " " << int(f.stereo) << "\n";
    }
    rawOut.close();
    sum.frames = frames.size();
    sum.files.push_back(rawlogPath);

    const std::string smPath = cfg.outPrefix + ".simplemap";
    {
        mrpt::io::CFileGZOutputStream smOut;
        if (!smOut.open(smPath)) throw std::runtime_error("cannot write '" + smPath + "'");
        auto a = mrpt::serialization::archiveFrom(smOut);
        a << simplemap;
    }
    sum.files.push_back(smPath);
    groundTruth.save(cfg.outPrefix + "_gt.asc");
    sum.files.push_back(cfg.outPrefix + "_gt.asc");
    writeText(cfg.outPrefix + ".ini", mapperIni(cfg));
    sum.files.push_back(cfg.outPrefix + ".ini");
    writeText(cfg.outPrefix + "_path.txt", path.str());
    sum.files.push_back(cfg.outPrefix + "_path.txt");
    return sum;
}

}  // namespace terrain_sim
