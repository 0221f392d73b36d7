/* The elevation-mapper program as a user runs it: --help, --section, the per-class report and the
 * non-zero exit of a run that fuses nothing, rasters bounded by the known area, --outputs, and
 * output safety (no input overwritten, no truncated file on a full disk, errors name files). */
#include <gtest/gtest.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/maps/CSimplePointsMap.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/obs/CObservationPointCloud.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/serialization/CArchive.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>

#include "mapper_run.h"
#include "multibin/io/EsriAsciiGrid.h"
#include "multibin/map/MapStatistics.h"

namespace fs = std::filesystem;

namespace {

using mapper_run::readAll;
using mapper_run::runMapper;
using mapper_run::RunResult;

fs::path scratchDir(const std::string& name) {
    return mapper_run::scratchDir("test_elevation_mapper", name);
}

void writeRawlog(const fs::path& path,
                 const std::vector<mrpt::serialization::CSerializable::Ptr>& e) {
    mrpt::io::CFileGZOutputStream f(path.string());
    auto arch = mrpt::serialization::archiveFrom(f);
    for (const auto& o : e) arch << *o;
}

/** A rawlog of one small depth-like point cloud: `side` x `side` points 1 cm apart on the floor
 * (z = -0.3 m) 1 m ahead of the robot at the origin. */
void writePatchRawlog(const fs::path& path, int side = 10) {
    auto cloud = mrpt::obs::CObservationPointCloud::Create();
    auto pts = mrpt::maps::CSimplePointsMap::Create();
    for (int i = 0; i < side; i++)
        for (int j = 0; j < side; j++) pts->insertPoint(1.0f + 0.01f * i, 0.01f * j, -0.3f);
    cloud->pointcloud = pts;
    cloud->sensorLabel = "CLOUD";
    writeRawlog(path, {cloud});
}

/** The ground truth of writePatchRawlog(): the floor at z = -0.3 m around the patch. */
void writePatchTruth(const fs::path& path) {
    multibin::EsriAsciiGrid gt;
    gt.cellsize_m = 0.02;
    gt.xllcenter_m = 0.9;
    gt.yllcenter_m = -0.1;
    gt.heights_m.setConstant(20, 20, -0.3f);
    gt.save(path.string());
}

/** An ini with the map in `section`; `creation` adds keys to its creation options. */
void writeIni(const fs::path& path, const std::string& section = "MappingApplication",
              const std::string& creation = "") {
    std::ofstream f(path);
    f << "[" << section << "]\nmultiBinElevationMap_count = 1\n[" << section
      << "_multiBinElevationMap_00_creationOpts]\nresolution = 0.02\n"
      << creation << "\n";
}

std::set<std::string> filesIn(const fs::path& dir) {
    std::set<std::string> names;
    for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
    return names;
}

size_t lines(const std::string& s) { return size_t(std::count(s.begin(), s.end(), '\n')); }

}  // namespace

// --help names every option the parser takes, and the default of each that has one.
TEST(ElevationMapperCli, HelpListsEveryOptionWithItsDefault) {
    const fs::path d = scratchDir("help");
    const RunResult r = runMapper(d, "--help");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    for (const char* flag : {"--config", "--section", "-s,", "--rawlog", "--simplemap", "--out",
                             "--outputs", "--ground-truth", "--with-mrf", "--profile",
                             "--eval-area", "--no-plots", "--help", "--export-resolution"})
        EXPECT_NE(r.out.find(flag), std::string::npos) << flag << " missing from --help";
    for (const char* def : {"default: MappingApplication", "default: elevation-mapper-out",
                            "default: map,tif,scene,png"})
        EXPECT_NE(r.out.find(def), std::string::npos) << def << " missing from --help";
    for (const char* group : {"map:", "tif:", "scene:", "png:", "asc:", "ply:"})
        EXPECT_NE(r.out.find(group), std::string::npos) << group << " missing from --help";
}

// --section picks the ini section, as observations2map's -s does.
TEST(ElevationMapperCli, SectionChoosesTheIniSection) {
    const fs::path d = scratchDir("section");
    writePatchRawlog(d / "patch.rawlog");
    writeIni(d / "maps.ini", "MyMaps");
    const std::string common =
        "--config " + (d / "maps.ini").string() + " --rawlog " + (d / "patch.rawlog").string();
    const RunResult def = runMapper(d, common + " --out " + (d / "a").string());
    EXPECT_EQ(def.exitCode, 1);
    EXPECT_NE(def.err.find("[MappingApplication]"), std::string::npos) << def.err;
    EXPECT_NE(def.err.find("--section"), std::string::npos) << def.err;
    const RunResult s = runMapper(d, common + " -s MyMaps --out " + (d / "b").string());
    EXPECT_EQ(s.exitCode, 0) << s.err;
    const RunResult l = runMapper(d, common + " --section MyMaps --out " + (d / "c").string());
    EXPECT_EQ(l.exitCode, 0) << l.err;
    EXPECT_TRUE(fs::exists(d / "c" / "elevation_map.bin"));
}

// A rawlog holding only odometry (actions and CObservationOdometry) fuses nothing: exit 1 and one
// line that names the rawlog and says why (the unsupported class), no outputs.
TEST(ElevationMapperCli, NoPointFusedIsAnErrorThatSaysWhy) {
    const fs::path d = scratchDir("odometry_only");
    std::vector<mrpt::serialization::CSerializable::Ptr> entries;
    for (int k = 0; k < 5; k++) {
        auto acts = mrpt::obs::CActionCollection::Create();
        mrpt::obs::CActionRobotMovement2D move;
        move.computeFromOdometry(mrpt::poses::CPose2D(0.1, 0, 0),
                                 mrpt::obs::CActionRobotMovement2D::TMotionModelOptions());
        acts->insert(move);
        entries.push_back(acts);
        auto sf = mrpt::obs::CSensoryFrame::Create();
        auto odo = mrpt::obs::CObservationOdometry::Create();
        odo->odometry = mrpt::poses::CPose2D(0.1 * k, 0, 0);
        sf->insert(odo);
        entries.push_back(sf);
    }
    writeRawlog(d / "odometry.rawlog", entries);
    writeIni(d / "maps.ini");
    const RunResult r =
        runMapper(d, "--config " + (d / "maps.ini").string() + " --rawlog " +
                         (d / "odometry.rawlog").string() + " --out " + (d / "out").string());
    EXPECT_EQ(r.exitCode, 1) << r.out;
    EXPECT_EQ(lines(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find("odometry.rawlog"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("no point fused"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("CObservationOdometry: 5 unsupported"), std::string::npos) << r.err;
    // The per-class report on stdout names the class too.
    EXPECT_NE(r.out.find("CObservationOdometry: 5 skipped: unsupported class"), std::string::npos)
        << r.out;
    EXPECT_FALSE(fs::exists(d / "out" / "elevation_map.bin"));
}

// The report counts per class what was used and what was skipped by label.
TEST(ElevationMapperCli, ReportCountsUsedAndSkippedByLabelPerClass) {
    const fs::path d = scratchDir("report");
    writePatchRawlog(d / "patch.rawlog");
    writeIni(d / "maps.ini");
    const RunResult used =
        runMapper(d, "--config " + (d / "maps.ini").string() + " --rawlog " +
                         (d / "patch.rawlog").string() + " --out " + (d / "out").string());
    ASSERT_EQ(used.exitCode, 0) << used.err;
    EXPECT_NE(used.out.find("CObservationPointCloud: 1 used (100 points fused, 0 rejected)"),
              std::string::npos)
        << used.out;

    std::ofstream(d / "maps.ini", std::ios::app)
        << "[MappingApplication_multiBinElevationMap_00_insertOpts]\nsensor_labels = LIDAR\n";
    const RunResult skipped =
        runMapper(d, "--config " + (d / "maps.ini").string() + " --rawlog " +
                         (d / "patch.rawlog").string() + " --out " + (d / "out2").string());
    EXPECT_EQ(skipped.exitCode, 1);
    EXPECT_NE(skipped.out.find("CObservationPointCloud: 1 skipped by label"), std::string::npos)
        << skipped.out;
    EXPECT_NE(skipped.err.find("skipped by sensor_labels"), std::string::npos) << skipped.err;
}

// A 10 x 10 cm patch in a 20 x 20 m window (1000 x 1000 cells): the rasters cover the patch and
// a margin, not the window, so every output together stays small (a raster of the window would be
// 4 MB as a float TIFF alone). The traversability layers are computed over the whole window: a
// 40 m window took half a minute under the sanitizers.
TEST(ElevationMapperOutputs, SparseMapRastersCoverTheKnownAreaOnly) {
    const fs::path d = scratchDir("sparse");
    writePatchRawlog(d / "patch.rawlog");
    writeIni(d / "maps.ini", "MappingApplication",
             "grow = false\nmin_x = -10\nmax_x = 10\nmin_y = -10\nmax_y = 10\n");
    const RunResult r = runMapper(d, "--config " + (d / "maps.ini").string() + " --rawlog " +
                                         (d / "patch.rawlog").string() + " --outputs all --out " +
                                         (d / "out").string());
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto g = multibin::EsriAsciiGrid::load((d / "out" / "elevation_height.asc").string());
    // The patch spans 5-6 cells of 2 cm; 5 cells of margin on each side; filling may add a few.
    EXPECT_LE(g.cols(), 30);
    EXPECT_LE(g.rows(), 30);
    uintmax_t total = 0;
    for (const auto& e : fs::directory_iterator(d / "out")) total += fs::file_size(e.path());
    EXPECT_LT(total, 1u << 20) << "bytes written: " << total;
}

// --outputs chooses the files: the default set, a single group, and an unknown group named.
TEST(ElevationMapperOutputs, OutputsChoosesWhatIsWritten) {
    const fs::path d = scratchDir("outputs");
    writePatchRawlog(d / "patch.rawlog");
    writeIni(d / "maps.ini");
    const std::string common =
        "--config " + (d / "maps.ini").string() + " --rawlog " + (d / "patch.rawlog").string();
    ASSERT_EQ(runMapper(d, common + " --out " + (d / "def").string()).exitCode, 0);
    EXPECT_EQ(
        filesIn(d / "def"),
        (std::set<std::string>{"elevation_map.bin", "elevation_height.tif", "elevation_height.tfw",
                               "elevation.3Dscene", "elevation_height.png", "elevation_sigma.png",
                               "elevation_source.png"}));
    ASSERT_EQ(runMapper(d, common + " --outputs asc,ply --out " + (d / "asc").string()).exitCode,
              0);
    EXPECT_EQ(filesIn(d / "asc"),
              (std::set<std::string>{"elevation_height.asc", "elevation_sigma.asc",
                                     "elevation_certainty.asc", "elevation_source.asc",
                                     "elevation_untraversable.asc", "elevation_step.asc",
                                     "elevation_slope.asc", "elevation_roughness.asc",
                                     "elevation_foothold.asc", "elevation.ply"}));
    const RunResult bad =
        runMapper(d, common + " --outputs map,geotiff --out " + (d / "bad").string());
    EXPECT_EQ(bad.exitCode, 1);
    EXPECT_NE(bad.err.find("'geotiff'"), std::string::npos) << bad.err;

    // The serialized map loads back as the map that was written.
    mrpt::io::CFileGZInputStream in((d / "def" / "elevation_map.bin").string());
    mrpt::maps::CMultiBinElevationMap map;
    mrpt::serialization::archiveFrom(in) >> map;
    EXPECT_EQ(map.statistics().insert.accepted, 0u);  // statistics are not serialized
    double h = 0, s = 0;
    EXPECT_TRUE(map.getHeight(1.05, 0.05, h, s));
    EXPECT_NEAR(h, -0.3, 0.01);
}

// --export-resolution samples the sub-cell surface over the rasters' area, finer than the map;
// a cell size that is not a positive number is an error naming the flag.
TEST(ElevationMapperOutputs, ExportResolutionSamplesTheSubCellSurface) {
    const fs::path d = scratchDir("supersampled");
    writePatchRawlog(d / "patch.rawlog");
    writeIni(d / "maps.ini");
    const std::string common =
        "--config " + (d / "maps.ini").string() + " --rawlog " + (d / "patch.rawlog").string();
    const RunResult r = runMapper(
        d, common + " --outputs asc --export-resolution 0.005 --out " + (d / "o").string());
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto coarse = multibin::EsriAsciiGrid::load((d / "o" / "elevation_height.asc").string());
    const auto fine =
        multibin::EsriAsciiGrid::load((d / "o" / "elevation_height_supersampled.asc").string());
    const auto sigma =
        multibin::EsriAsciiGrid::load((d / "o" / "elevation_sigma_supersampled.asc").string());
    EXPECT_DOUBLE_EQ(fine.cellsize_m, 0.005);
    EXPECT_NEAR(fine.xllcenter_m - 0.0025, coarse.xllcenter_m - 0.5 * coarse.cellsize_m, 1e-9);
    EXPECT_NEAR(fine.yllcenter_m - 0.0025, coarse.yllcenter_m - 0.5 * coarse.cellsize_m, 1e-9);
    EXPECT_NEAR(fine.cols() * 0.005, coarse.cols() * coarse.cellsize_m, 0.005);
    EXPECT_EQ(sigma.cols(), fine.cols());
    // The patch is flat at -0.3 m: every sample the coarse raster knows is known, and flat.
    size_t known = 0;
    for (int r = 0; r < fine.rows(); r++)
        for (int c = 0; c < fine.cols(); c++) {
            const double x = fine.xllcenter_m + c * 0.005, y = fine.yllcenter_m + r * 0.005;
            const int cc = int(std::floor((x - coarse.xllcenter_m) / coarse.cellsize_m + 0.5));
            const int rr = int(std::floor((y - coarse.yllcenter_m) / coarse.cellsize_m + 0.5));
            if (!std::isfinite(coarse.heights_m(rr, cc))) continue;
            ASSERT_TRUE(std::isfinite(fine.heights_m(r, c))) << x << ", " << y;
            EXPECT_NEAR(fine.heights_m(r, c), -0.3, 0.01) << x << ", " << y;
            known++;
        }
    EXPECT_GT(known, 16u);
    const RunResult bad =
        runMapper(d, common + " --export-resolution 0 --out " + (d / "bad").string());
    EXPECT_EQ(bad.exitCode, 1);
    EXPECT_NE(bad.err.find("--export-resolution"), std::string::npos) << bad.err;
}

// An input at the path of an output is an error naming both, before anything is written, and the
// input is left as it was: ini, rawlog and ground truth.
TEST(ElevationMapperOutputs, NeverOverwritesAnInput) {
    const fs::path d = scratchDir("inputs");
    const fs::path out = d / "out";
    fs::create_directories(out);
    writePatchRawlog(out / "elevation.ply");  // a rawlog where the mesh would go
    writeIni(d / "maps.ini");
    const std::string rawlogBytes = readAll(out / "elevation.ply");
    RunResult r =
        runMapper(d, "--config " + (d / "maps.ini").string() + " --rawlog " +
                         (out / "elevation.ply").string() + " --outputs all --out " + out.string());
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_EQ(lines(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find("would overwrite the input --rawlog"), std::string::npos) << r.err;
    EXPECT_EQ(readAll(out / "elevation.ply"), rawlogBytes);
    EXPECT_EQ(filesIn(out), (std::set<std::string>{"elevation.ply"}));

    writeIni(out / "elevation_map.bin");  // an ini where the map would go
    writePatchRawlog(d / "patch.rawlog");
    const std::string iniBytes = readAll(out / "elevation_map.bin");
    r = runMapper(d, "--config " + (out / "elevation_map.bin").string() + " --rawlog " +
                         (d / "patch.rawlog").string() + " --out " + out.string());
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find("would overwrite the input --config"), std::string::npos) << r.err;
    EXPECT_EQ(readAll(out / "elevation_map.bin"), iniBytes);

    // A ground truth where the evaluation writes its truth raster.
    writePatchTruth(out / "eval_truth.asc");
    const std::string gtBytes = readAll(out / "eval_truth.asc");
    r = runMapper(d, "--config " + (d / "maps.ini").string() + " --rawlog " +
                         (d / "patch.rawlog").string() + " --ground-truth " +
                         (out / "eval_truth.asc").string() + " --no-plots --out " + out.string());
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find("would overwrite the input --ground-truth"), std::string::npos) << r.err;
    EXPECT_EQ(readAll(out / "eval_truth.asc"), gtBytes);
}

// A full disk (here: a file size limit, ulimit -f) fails with an error naming the file it could
// not write, and leaves no truncated file: each file is the previous complete one or absent, and
// no temporary file remains.
TEST(ElevationMapperOutputs, FullDiskLeavesNoTruncatedFile) {
    const fs::path d = scratchDir("full_disk");
    writePatchRawlog(d / "patch.rawlog", 40);
    writeIni(d / "maps.ini");
    const std::string args = "--config " + (d / "maps.ini").string() + " --rawlog " +
                             (d / "patch.rawlog").string() + " --outputs all --out " +
                             (d / "out").string();
    ASSERT_EQ(runMapper(d, args).exitCode, 0);
    std::map<std::string, std::string> complete;
    for (const auto& name : filesIn(d / "out")) complete[name] = readAll(d / "out" / name);
    size_t largest = 0;
    for (const auto& [name, bytes] : complete) largest = std::max(largest, bytes.size());
    ASSERT_GT(largest, 2048u);

    // dash counts ulimit -f in 512-byte blocks: 2 blocks stops every file over 1 KiB.
    const RunResult r = runMapper(d, args, "trap \"\" XFSZ; ulimit -f 2;");
    EXPECT_EQ(r.exitCode, 1) << r.out;
    EXPECT_EQ(lines(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find((d / "out").string()), std::string::npos) << r.err;
    for (const auto& name : filesIn(d / "out")) {
        EXPECT_EQ(name.find(".partial"), std::string::npos) << "temporary file left: " << name;
        if (complete.count(name))
            EXPECT_TRUE(readAll(d / "out" / name) == complete[name]) << name << " is not complete";
    }
}

// On a terminal (here a pseudo-terminal made by script(1)) every stage draws its progress line:
// mapping, filling, the layers, writing and the figures; off a terminal nothing of it reaches
// stderr.
TEST(ElevationMapperCli, ProgressOnATerminalForEveryStage) {
    if (std::system("command -v script >/dev/null 2>&1") != 0)
        GTEST_SKIP() << "script(1) (bsdutils) is not installed";
    const fs::path d = scratchDir("progress");
    writePatchRawlog(d / "patch.rawlog");
    writeIni(d / "maps.ini");
    writePatchTruth(d / "gt.asc");
    const std::string args = "--config " + (d / "maps.ini").string() + " --rawlog " +
                             (d / "patch.rawlog").string() + " --ground-truth " +
                             (d / "gt.asc").string() + " --out " + (d / "out").string();
    const std::string cmd = "script -qec \"" + std::string(ELEVATION_MAPPER_EXE) + " " + args +
                            " >/dev/null\" /dev/null > " + (d / "tty.txt").string() +
                            " 2>&1 < /dev/null";
    ASSERT_EQ(std::system(cmd.c_str()), 0);
    const std::string tty = readAll(d / "tty.txt");
    for (const char* stage : {"mapping [", "filling [", "layers [", "writing [", "figures ["})
        EXPECT_NE(tty.find(stage), std::string::npos) << stage << " missing from:\n" << tty;
    // The layer panels are drawn from a scratch copy of the rasters: none is left in the output.
    EXPECT_TRUE(fs::exists(d / "out" / "layers.png"));
    EXPECT_FALSE(fs::exists(d / "out" / "elevation_height.asc"));

    const RunResult plain = runMapper(d, args + " --no-plots");
    EXPECT_EQ(plain.exitCode, 0);
    EXPECT_EQ(plain.err, "");
}

namespace {
/** The number after `"field": ` in the entry of `method` of a traversability.json. */
double jsonField(const std::string& json, const std::string& method, const std::string& field) {
    const size_t m = json.find("\"" + method + "\": {");
    if (m == std::string::npos) return NAN;
    const size_t f = json.find("\"" + field + "\": ", m);
    return f == std::string::npos ? NAN : std::stod(json.substr(f + field.size() + 4));
}
}  // namespace

// The traversability scores (doc/traversability.md): a truth raster at 5 mm with a 0.085 m step
// along x = 1.3 m, scored over --eval-area 0.995..1.605 x -0.005..0.605 m at 20 mm cells with
// a disc of 0.05 m, the step as the only limit (0.08 m) and a calibration that would hide the
// step (biases -0.01 m, -90 deg, -0.1 m; the step's slope and roughness terms negative). By hand:
// the cells scored are those whose disc lies in the area, centres 1.05..1.55 by 0.05..0.55 m, 26 x
// 26 = 676; the truth calls the 4 columns of centres 1.27..1.33 untraversable (their discs reach
// across 1.3; those at 1.25 and 1.35 stop 2.5 mm short of the other side's samples), and so do the
// truth's own cell means thresholded at the limits themselves (the calibration is the map layer's,
// not theirs): F1 1.
TEST(ElevationMapperTraversability, BaselinesAreThresholdedAtTheLimitsOnDiscsInsideTheArea) {
    const fs::path d = scratchDir("traversability_scores");
    writePatchRawlog(d / "patch.rawlog", 60);
    writeIni(d / "maps.ini");
    {
        std::ofstream f(d / "maps.ini", std::ios::app);
        f << "[MappingApplication_multiBinElevationMap_00_traversabilityOpts]\n"
             "max_slope_deg = 89\nmax_roughness_m = 1\n"  // the step alone decides
             "step_bias_m = -0.01\nslope_bias_deg = -90\nroughness_bias_m = -0.1\n"
             "step_slope_gain = -0.01\nstep_roughness_gain = -10\n";
    }
    multibin::EsriAsciiGrid gt;
    gt.cellsize_m = 0.005;
    gt.xllcenter_m = 0.9025;  // samples between, never on, the cells' edges
    gt.yllcenter_m = -0.0975;
    gt.heights_m.resize(160, 160);
    for (int r = 0; r < 160; r++)
        for (int c = 0; c < 160; c++)
            gt.heights_m(r, c) = gt.xllcenter_m + c * gt.cellsize_m > 1.3 ? -0.215f : -0.3f;
    gt.save((d / "gt.asc").string());
    const RunResult r = runMapper(d, "--config " + (d / "maps.ini").string() + " --rawlog " +
                                         (d / "patch.rawlog").string() + " --ground-truth " +
                                         (d / "gt.asc").string() +
                                         " --eval-area 0.995,1.605,-0.005,0.605 --no-plots "
                                         "--outputs map --out " +
                                         (d / "out").string());
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const std::string json = readAll(d / "out" / "traversability.json");
    for (const char* m : {"multibin", "truth_cell_means_thresholded"})
        EXPECT_EQ(jsonField(json, m, "truth_cells"), 676) << m << "\n" << json;
    EXPECT_EQ(jsonField(json, "truth_cell_means_thresholded", "tp"), 4 * 26) << json;
    EXPECT_EQ(jsonField(json, "truth_cell_means_thresholded", "f1"), 1.0) << json;
    EXPECT_EQ(jsonField(json, "truth_at_cell_centres_thresholded", "f1"), 1.0) << json;
}
