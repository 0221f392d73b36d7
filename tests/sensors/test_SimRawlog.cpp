/* The sensor models on terrain-sim's mock-up scenario (rawlogs/mockup.*): the reader side of the
 * sensor contract end to end, with the scenario's own ini (laser AGC, stereo calibration sigmas).
 * Heights are compared with the ground truth; the figures printed here are quoted in
 * doc/sensor-models.md. */
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/maps/CSimpleMap.h>
#include <mrpt/obs/CObservationStereoImages.h>
#include <mrpt/serialization/CArchive.h>

#include <cmath>
#include <cstdio>

#include "multibin/io/EsriAsciiGrid.h"
#include "multibin/map/MapStatistics.h"
#include "multibin/sensors/SensorDispatch.h"

namespace {
const std::string kRawlogs = MULTIBIN_SOURCE_DIR "/rawlogs/";

struct Outcome {
    size_t cells = 0, within3Sigma = 0;
    double sumSq = 0;
    mrpt::maps::CMultiBinElevationMap::TInsertionOptions opts;
    multibin::sensors::SensorModelStats stats;
    multibin::InsertStats core;
};

/** Inserts the scenario with the sensors of `labels` (all if empty); `sgbm`: drop the simulator's
 * disparity images so the model runs StereoSGBM on the rendered pairs. */
Outcome run(const std::string& scenario, const std::vector<std::string>& labels, bool sgbm = false,
            double poseCorrelation = 0.0) {
    const std::string kPrefix = kRawlogs + scenario;
    mrpt::maps::CMultiBinElevationMap::TCreationOptions c;
    c.resolution_m = 0.015;
    mrpt::maps::CMultiBinElevationMap map(c);
    mrpt::config::CConfigFile ini(kPrefix + ".ini");
    map.insertionOptions.loadFromConfigFile(
        ini, "MappingApplication_multiBinElevationMap_00_insertOpts");
    map.insertionOptions.sensor_labels = labels;
    map.insertionOptions.sensors.laser.continuityPoseCorrelation = poseCorrelation;
    mrpt::maps::CSimpleMap sm;
    mrpt::io::CFileGZInputStream f(kPrefix + ".simplemap");
    mrpt::serialization::archiveFrom(f) >> sm;
    if (sgbm)
        for (size_t i = 0; i < sm.size(); i++)
            for (auto& obs : *std::get<1>(sm.get(i)))
                if (auto st = std::dynamic_pointer_cast<mrpt::obs::CObservationStereoImages>(obs))
                    st->hasImageDisparity = false;
    map.insertSimpleMapWithPosePdfs(sm);

    const auto gt = multibin::EsriAsciiGrid::load(kPrefix + "_gt.asc");
    Outcome o;
    o.opts = map.insertionOptions;
    o.stats = map.statistics().sensorModels;
    o.core = map.statistics().insert;
    for (int r = 0; r < gt.rows(); r++)
        for (int k = 0; k < gt.cols(); k++) {
            const double x = gt.xllcenter_m + k * gt.cellsize_m,
                         y = gt.yllcenter_m + r * gt.cellsize_m;
            double h, s;
            if (!std::isfinite(gt.heights_m(r, k)) || !map.getHeight(x, y, h, s)) continue;
            const double e = h - gt.heights_m(r, k);
            o.cells++;
            o.sumSq += e * e;
            if (std::abs(e) <= 3 * s) o.within3Sigma++;
        }
    std::printf("%-12s cells %6zu  RMSE %.4f m  within 3 sigma %.1f %%\n",
                labels.empty() ? "LASER+STEREO" : (labels[0] + (sgbm ? "/SGBM" : "")).c_str(),
                o.cells, std::sqrt(o.sumSq / double(o.cells)),
                100.0 * double(o.within3Sigma) / double(o.cells));
    return o;
}
}  // namespace

TEST(SimMockup, ContractIniLoadsAndEverySensorPathInserts) {
    const Outcome laser = run("mockup", {"LASER"});
    const auto& L = laser.stats.laser;
    std::printf(
        "laser: %zu beams, %zu kept, %zu no return, %zu low intensity, %zu mixed, "
        "%zu continuity-rejected\n",
        L.beams, L.kept, L.noReturn, L.lowIntensity, L.mixedPixel, laser.core.continuityRejected);
    EXPECT_DOUBLE_EQ(laser.opts.sensors.laser.agcByLabel.at("LASER"), 512);
    EXPECT_GT(L.kept, 10000u);
    EXPECT_GT(L.lowIntensity, 0u);  // the scenario's dark patches
    EXPECT_GT(L.mixedPixel, 0u);    // the simulator's mixed pixels at board edges
    EXPECT_GT(laser.cells, 5000u);

    const Outcome stereo = run("mockup", {"STEREO"});
    const auto& S = stereo.stats.stereo;
    std::printf(
        "stereo: %zu pairs, %zu table builds, %zu px visited, %zu kept, %zu no disparity, "
        "%zu halo, %zu near-cluster, %zu too near\n",
        S.pairs, S.tableBuilds, S.pixels, S.kept, S.noDisparity, S.halo, S.nearCluster, S.tooNear);
    EXPECT_EQ(S.tableBuilds, 1u);  // one calibration: one table
    EXPECT_GT(S.kept, 10000u);
    EXPECT_GT(S.halo, 0u);
    EXPECT_GT(stereo.cells, 5000u);

    const Outcome sgbm = run("mockup", {"STEREO"}, true);
    const auto& G = sgbm.stats.stereo;
    std::printf(
        "stereo/SGBM: %zu px visited, %zu kept, %zu no disparity, %zu halo, "
        "%zu near-cluster\n",
        G.pixels, G.kept, G.noDisparity, G.halo, G.nearCluster);
    EXPECT_GT(G.kept, 10000u);
    EXPECT_GT(sgbm.cells, 5000u);

    const Outcome both = run("mockup", {});
    EXPECT_GT(both.cells, laser.cells);
    // Honest sigmas: most observed cells hold the truth within 3 sigma.
    for (const Outcome* o : {&laser, &stereo, &sgbm, &both})
        EXPECT_GT(double(o->within3Sigma) / double(o->cells), 0.8);
}

TEST(SimWalk, DriftingPosesStillInsertConsistently) {
    // The walk: pose errors drift between corrections, so consecutive scans' pose covariances
    // differ and eq 14's bound follows them.
    const Outcome laser = run("walk", {"LASER"});
    std::printf("laser: %zu kept, %zu low intensity, %zu mixed, %zu continuity-rejected\n",
                laser.stats.laser.kept, laser.stats.laser.lowIntensity,
                laser.stats.laser.mixedPixel, laser.core.continuityRejected);
    // Its pose errors are a random walk between corrections: consecutive scans' errors are
    // strongly correlated, which laser_continuity_pose_correlation can state.
    const Outcome correlated = run("walk", {"LASER"}, false, 0.95);
    std::printf("laser, pose correlation 0.95: %zu continuity-rejected\n",
                correlated.core.continuityRejected);
    EXPECT_GE(correlated.core.continuityRejected, laser.core.continuityRejected);
    const Outcome both = run("walk", {});
    EXPECT_GT(laser.cells, 5000u);
    EXPECT_LT(double(laser.core.continuityRejected), 0.05 * double(laser.stats.laser.kept));
    for (const Outcome* o : {&laser, &correlated, &both})
        EXPECT_GT(double(o->within3Sigma) / double(o->cells), 0.8);
}
