/* terrain-sim scenarios: determinism, rawlog / simplemap structure, the shipped data read by
 * MRPT's CRawlog and stock rawlog-edit, CLI errors. */
#include <gtest/gtest.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/maps/CSimpleMap.h>
#include <mrpt/math/wrap2pi.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationRobotPose.h>
#include <mrpt/obs/CObservationStereoImages.h>
#include <mrpt/obs/CRawlog.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose3DPDFGaussian.h>
#include <mrpt/serialization/CArchive.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "Scenario.h"
#include "sim_fixtures.h"

namespace fs = std::filesystem;
using namespace terrain_sim;

namespace {

std::string readBytes(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
}

fs::path tempDir(const std::string& name) {
    const fs::path d = fs::path(MULTIBIN_BINARY_DIR) / "test_sim_tmp" / name;
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

/** A short scenario over one real board: quick, but every code path (laser, stereo, disparity). */
ScenarioConfig smallConfig(const std::string& scenario, uint64_t seed, const std::string& prefix) {
    ScenarioConfig cfg;
    cfg.terrainFiles = {std::string(MULTIBIN_REFERENCE_DATA_DIR) + "/terrain/littledog/B.asc",
                        std::string(MULTIBIN_REFERENCE_DATA_DIR) + "/terrain/littledog/CC.asc"};
    cfg.tilesX = 2;
    cfg.tilesY = 1;
    cfg.scenario = scenario;
    cfg.seed = seed;
    cfg.outPrefix = prefix;
    cfg.margin_m = 0.3;
    cfg.stereo.width_px = 80;
    cfg.stereo.height_px = 60;
    cfg.trajectory.stereoRate_hz = 5;
    cfg.trajectory.maxFrames = 8;
    return cfg;
}

const char* kSuffixes[] = {".rawlog", ".simplemap", "_gt.asc", ".ini", "_path.txt"};

struct Counts {
    size_t frames = 0, poses = 0, scans = 0, stereo = 0, disparity = 0;
};

/** Loads a rawlog with MRPT's CRawlog and checks the contract's layout of every sensory frame. */
Counts checkRawlogLayout(const std::string& path) {
    mrpt::obs::CRawlog log;
    EXPECT_TRUE(log.loadFromRawLogFile(path)) << path;
    Counts c;
    for (size_t i = 0; i < log.size(); ++i) {
        if (log.getType(i) != mrpt::obs::CRawlog::etSensoryFrame) continue;
        const auto sf = log.getAsObservations(i);
        c.frames++;
        EXPECT_GE(sf->size(), 2u);
        const auto first =
            std::dynamic_pointer_cast<mrpt::obs::CObservationRobotPose>(*sf->begin());
        EXPECT_TRUE(first) << "frame " << i << ": the robot pose must come first";
        if (!first) continue;
        EXPECT_EQ(first->sensorLabel, "ROBOT_POSE");
        for (const auto& o : *sf) {
            EXPECT_EQ(o->timestamp, first->timestamp);
            if (std::dynamic_pointer_cast<mrpt::obs::CObservationRobotPose>(o)) {
                c.poses++;
            } else if (auto s = std::dynamic_pointer_cast<mrpt::obs::CObservation2DRangeScan>(o)) {
                c.scans++;
                EXPECT_EQ(s->sensorLabel, "LASER");
                EXPECT_EQ(s->getScanSize(), 683u);
                EXPECT_TRUE(s->hasIntensity());
                EXPECT_TRUE(s->rightToLeft);
                EXPECT_NEAR(s->maxRange, 4.0, 1e-6);
                EXPECT_NEAR(s->sensorPose.pitch(), M_PI / 4, 1e-9);
            } else if (auto st =
                           std::dynamic_pointer_cast<mrpt::obs::CObservationStereoImages>(o)) {
                c.stereo++;
                EXPECT_EQ(st->sensorLabel, "STEREO");
                EXPECT_FALSE(st->imageLeft.isExternallyStored());
                EXPECT_EQ(st->imageLeft.getWidth(), st->leftCamera.ncols);
                EXPECT_NEAR(st->rightCameraPose.x(), 0.09, 1e-12);
                if (st->hasImageDisparity) {
                    c.disparity++;
                    EXPECT_EQ(st->imageDisparity.getPixelDepth(), mrpt::img::PixelDepth::D16U);
                }
            }
        }
    }
    return c;
}

/** Runs a shell command, its stdout and stderr captured in the build tree. */
int run(const std::string& cmd, std::string* out = nullptr) {
    // One file per test: ctest may run the tests in parallel.
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string(info->test_suite_name()) + "." + info->name() + ".txt";
    std::replace(name.begin(), name.end(), '/', '_');
    const fs::path log = fs::path(MULTIBIN_BINARY_DIR) / "test_sim_tmp" / name;
    fs::create_directories(log.parent_path());
    const std::string full = cmd + " > " + log.string() + " 2>&1";
    const int rc = std::system(full.c_str());
    if (out) *out = readBytes(log.string());
    return rc;
}

}  // namespace

TEST(TerrainSimScenario, SameSeedGivesByteIdenticalOutput) {
    for (const std::string scenario : {"mockup", "walk"}) {
        const fs::path d = tempDir("determinism_" + scenario);
        runScenario(smallConfig(scenario, 42, (d / "a").string()));
        runScenario(smallConfig(scenario, 42, (d / "b").string()));
        runScenario(smallConfig(scenario, 43, (d / "c").string()));
        for (const char* s : kSuffixes) {
            const std::string a = readBytes((d / "a").string() + s);
            ASSERT_FALSE(a.empty()) << s;
            EXPECT_EQ(a, readBytes((d / "b").string() + s)) << scenario << s;
        }
        EXPECT_NE(readBytes((d / "a.rawlog").string()), readBytes((d / "c.rawlog").string()));
    }
}

TEST(TerrainSimScenario, RawlogAndSimplemapFollowTheContract) {
    const fs::path d = tempDir("layout");
    const auto cfg = smallConfig("walk", 5, (d / "w").string());
    const auto sum = runScenario(cfg);
    const Counts c = checkRawlogLayout((d / "w.rawlog").string());
    EXPECT_EQ(c.frames, 8u);
    EXPECT_EQ(c.poses, 8u);
    EXPECT_EQ(c.scans, 8u);
    EXPECT_EQ(c.stereo, sum.stereoFrames);
    EXPECT_EQ(c.disparity, sum.stereoFrames);
    EXPECT_EQ(sum.stereoFrames, 4u);  // 5 Hz against the 10 Hz laser

    mrpt::maps::CSimpleMap sm;
    mrpt::io::CFileGZInputStream in((d / "w.simplemap").string());
    auto arch = mrpt::serialization::archiveFrom(in);
    arch >> sm;
    ASSERT_EQ(sm.size(), 8u);
    for (const auto& kf : sm) {
        const auto pdf = std::dynamic_pointer_cast<mrpt::poses::CPose3DPDFGaussian>(kf.pose);
        ASSERT_TRUE(pdf);
        EXPECT_GT(pdf->cov(0, 0), 0.0);
    }
    // The walk's pose covariance grows between corrections (every 2 s = 20 frames).
    const auto p0 =
        std::dynamic_pointer_cast<mrpt::poses::CPose3DPDFGaussian>(std::get<0>(sm.get(0)));
    const auto p7 =
        std::dynamic_pointer_cast<mrpt::poses::CPose3DPDFGaussian>(std::get<0>(sm.get(7)));
    EXPECT_NEAR(p7->cov(0, 0) - p0->cov(0, 0), 7 * 0.001 * 0.001, 1e-12);

    // The path file: one row per frame, 9 columns.
    std::ifstream path((d / "w_path.txt").string());
    size_t rows = 0;
    for (std::string line; std::getline(path, line);) {
        if (line.empty() || line[0] == '#') continue;
        std::istringstream ss(line);
        double v;
        int cols = 0;
        while (ss >> v) ++cols;
        EXPECT_EQ(cols, 9);
        ++rows;
    }
    EXPECT_EQ(rows, 8u);
    // Ground truth raster: the map's cell size by default, cells aligned at multiples of it.
    const auto gt = multibin::EsriAsciiGrid::load((d / "w_gt.asc").string());
    EXPECT_NEAR(gt.cellsize_m, 0.015, 1e-12);
    EXPECT_NEAR(std::fmod(gt.xllcenter_m / 0.015 + 1000.5, 1.0), 0.0, 1e-6);
    // The ini carries the contract's keys.
    const std::string ini = readBytes((d / "w.ini").string());
    for (const char* key : {"[MappingApplication]", "laser_agc = LASER:512",
                            "stereo_left_intrinsics_sigma", "stereo_right_intrinsics_sigma",
                            "stereo_extrinsics_sigma", "stereo_matching_sigma_px = 0.25"})
        EXPECT_NE(ini.find(key), std::string::npos) << key;
}

TEST(TerrainSimCli, BadArgumentsGiveOneLineErrorAndExit1) {
    const std::string exe = TERRAIN_SIM_EXE;
    const std::string board = std::string(MULTIBIN_REFERENCE_DATA_DIR) + "/terrain/littledog/B.asc";
    const fs::path d = tempDir("cli");
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"--scenario mockup --out " + (d / "x").string(), "--terrain is required"},
        {"--terrain /nonexistent.asc --scenario mockup --out " + (d / "x").string(),
         "/nonexistent.asc"},
        {"--terrain " + board + " --scenario run --out x", "not mockup or walk"},
        {"--terrain " + board + " --tiles 3y3 --scenario walk --out x", "--tiles"},
        {"--terrain " + board + " --scenario walk --seed -4 --out x", "--seed"},
        {"--terrain " + board + " --scenario walk --bogus 1 --out x", "unknown option"},
        {"--terrain " + board + " --scenario walk --gt-cell 5 --out " + (d / "g").string(),
         "larger than the terrain"},
        {"--terrain " + board + " --scenario walk --out /nonexistent/dir/x", "cannot write"},
        {"--terrain " + board + " --scenario walk --noise loud --out x",
         "not matched, independent or exact"},
        {"--terrain " + board + " --scenario walk --tail-dof 2 --out x", "--tail-dof"},
        {"--terrain " + board + " --scenario walk --outliers 1.5 --out x", "--outliers"},
        {"--terrain " + board + " --scenario walk --laser-range-bias 0.01 --out x",
         "--laser-range-bias"},
        {"--terrain " + board + " --scenario walk --stereo-principal-point-error a,1 --out x",
         "--stereo-principal-point-error"},
    };
    for (const auto& [args, expect] : cases) {
        std::string out;
        const int rc = run(exe + " " + args, &out);
        EXPECT_TRUE(WIFEXITED(rc) && WEXITSTATUS(rc) == 1) << args;
        EXPECT_NE(out.find("terrain-sim: error:"), std::string::npos) << out;
        EXPECT_NE(out.find(expect), std::string::npos) << out;
        EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << out;
    }
}

class ShippedScenario : public ::testing::TestWithParam<std::string> {
protected:
    std::string prefix() const {
        return std::string(MULTIBIN_SOURCE_DIR) + "/rawlogs/" + GetParam();
    }
};

TEST_P(ShippedScenario, CRawlogLoadsItWithTheExpectedObservations) {
    const Counts c = checkRawlogLayout(prefix() + ".rawlog");
    EXPECT_GT(c.frames, 100u);
    EXPECT_EQ(c.poses, c.frames);
    EXPECT_EQ(c.scans, c.frames);
    EXPECT_GE(c.stereo, 10u);
    EXPECT_EQ(c.disparity, c.stereo);
    size_t bytes = 0;
    for (const char* s : kSuffixes) {
        ASSERT_TRUE(fs::exists(prefix() + s)) << prefix() + s;
        bytes += fs::file_size(prefix() + s);
    }
    EXPECT_LT(bytes, 10u * 1000 * 1000) << "a shipped scenario must stay under 10 MB";
}

TEST_P(ShippedScenario, StockRawlogEditReadsIt) {
    ASSERT_FALSE(std::string(MULTIBIN_RAWLOG_EDIT).empty()) << "rawlog-edit not found";
    const std::string exe = MULTIBIN_RAWLOG_EDIT;
    std::string out;
    int rc = run(exe + " --info -i " + prefix() + ".rawlog", &out);
    EXPECT_EQ(rc, 0) << out;
    for (const char* s :
         {"LASER", "STEREO", "ROBOT_POSE", "Actions/SensoryFrame format       : Yes"})
        EXPECT_NE(out.find(s), std::string::npos) << s << "\n" << out;
    const fs::path d = tempDir("list_images_" + GetParam());
    const std::string list = (d / "images.txt").string();
    rc = run(exe + " --list-images -i " + prefix() + ".rawlog --text-file-output " + list, &out);
    EXPECT_EQ(rc, 0) << out;
    ASSERT_TRUE(fs::exists(list)) << out;
    EXPECT_EQ(fs::file_size(list), 0u) << "images are inline: no external image files listed";
}

// The rawlog carries odometry (a planar increment per frame) so that RawLogViewer and MRPT's
// odometry-based tools show the path: the odometry accumulated over the actions must follow the
// ROBOT_POSE estimates in x, y and yaw (a rawlog without actions leaves it at the origin).
TEST_P(ShippedScenario, OdometryActionsFollowThePoseEstimates) {
    mrpt::io::CFileGZInputStream in(prefix() + ".rawlog");
    auto arch = mrpt::serialization::archiveFrom(in);
    mrpt::poses::CPose2D odometry, firstEstimate;
    size_t actions = 0, compared = 0;
    bool haveFirst = false;
    double worstXY_m = 0, worstYaw_rad = 0;
    for (;;) {
        mrpt::serialization::CSerializable::Ptr obj;
        try {
            obj = arch.ReadObject();
        } catch (const mrpt::serialization::CExceptionEOF&) {
            break;
        }
        if (auto acts = std::dynamic_pointer_cast<mrpt::obs::CActionCollection>(obj)) {
            auto move = acts->getBestMovementEstimation();
            ASSERT_TRUE(move) << "action collection " << actions << " holds no odometry";
            odometry = odometry + move->poseChange->getMeanVal();
            actions++;
        } else if (auto sf = std::dynamic_pointer_cast<mrpt::obs::CSensoryFrame>(obj)) {
            auto rp = sf->getObservationByClass<mrpt::obs::CObservationRobotPose>();
            ASSERT_TRUE(rp);
            const mrpt::poses::CPose2D estimate(rp->pose.mean);
            if (!haveFirst) {
                firstEstimate = estimate;  // odometry starts at the first frame's pose
                haveFirst = true;
            }
            const mrpt::poses::CPose2D expected = estimate - firstEstimate;
            worstXY_m = std::max(worstXY_m, expected.distanceTo(odometry));
            worstYaw_rad = std::max(
                worstYaw_rad, std::abs(mrpt::math::wrapToPi(expected.phi() - odometry.phi())));
            compared++;
        }
    }
    EXPECT_EQ(actions, compared);
    EXPECT_GT(compared, 100u);
    // Planar increments of the planar projection compose back to it (float rounding only).
    EXPECT_LT(worstXY_m, 1e-4);
    EXPECT_LT(worstYaw_rad, 1e-4);
    EXPECT_GT(odometry.norm(), 1.0) << "the robot walks more than a metre";
}

INSTANTIATE_TEST_SUITE_P(Rawlogs, ShippedScenario, ::testing::Values("mockup", "walk"));

// The pose errors follow the stated covariances: k frames after a correction, the error of each
// pose parameter, normalised by the written sigma, has unit variance (chi-square over 2000
// independent correction periods, 99.9 %), for k = 0 and for the last frame before a correction.
// The mock-up's errors are independent draws from its constant covariance.
TEST(TerrainSimTrajectory, PoseErrorsFollowTheWrittenCovariance) {
    const Terrain t = Terrain::fromBoards({sim_test::flatBoard(11, 0.01, 0.0)}, 1, 1, 0.0);
    TrajectoryOptions o;
    o.walkSpeed_mps = 1e-6;
    o.mockupStep_m = 1e-6;
    o.maxFrames = 40000;
    for (const bool walk : {true, false}) {
        std::mt19937_64 rng(walk ? 17 : 18);
        const auto frames = walk ? walkTrajectory(t, o, rng) : mockupTrajectory(t, o, rng);
        ASSERT_EQ(frames.size(), 40000u);
        const int period = walk ? 20 : 1;
        for (const int k : {0, period - 1}) {
            std::array<double, 6> chi2{};
            size_t n = 0;
            for (size_t f = k; f < frames.size(); f += period) {
                const auto& e = frames[f].estimate;
                const auto& p = frames[f].truth;
                const double err[6] = {e.mean.x() - p.x(),         e.mean.y() - p.y(),
                                       e.mean.z() - p.z(),         e.mean.yaw() - p.yaw(),
                                       e.mean.pitch() - p.pitch(), e.mean.roll() - p.roll()};
                for (int i = 0; i < 6; ++i) chi2[i] += err[i] * err[i] / e.cov(i, i);
                ++n;
            }
            for (int i = 0; i < 6; ++i)
                EXPECT_NEAR(chi2[i], double(n), 3.29 * std::sqrt(2.0 * n))
                    << (walk ? "walk" : "mockup") << " k " << k << " param " << i;
        }
        if (walk) {  // the covariance grows between corrections, as stated
            const auto m = walkErrorModel();
            EXPECT_NEAR(frames[19].estimate.cov(0, 0),
                        m.sigma0[0] * m.sigma0[0] + 19 * m.sigmaStep[0] * m.sigmaStep[0], 1e-15);
            EXPECT_NEAR(frames[20].estimate.cov(0, 0), m.sigma0[0] * m.sigma0[0], 1e-15);
        }
    }
}
