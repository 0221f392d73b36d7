/* Georeferenced coordinates (issue 15 item 4): the map holds its origin in double and keeps the
 * single-precision geometry relative to it, so the shipped mock-up moved to UTM-scale coordinates
 * is the same map, cell for cell, as at the origin; its rasters only move their corner. Also: the
 * origin's choice, its option keys, serialization (old files load with the origin they had), the
 * DEM interface and the 3D view at such coordinates. */
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/io/CFileInputStream.h>
#include <mrpt/io/CMemoryStream.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/obs/CObservationRobotPose.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/opengl/CMesh.h>
#include <mrpt/opengl/CSetOfObjects.h>
#include <mrpt/serialization/CArchive.h>

#include <array>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include "RawlogSource.h"
#include "mapper_run.h"
#include "multibin/grid/BinGrid.h"
#include "multibin/io/EsriAsciiGrid.h"
#include "multibin/io/RasterExport.h"
#include "multibin/map/MapInternals.h"
#include "multibin/map/MapStatistics.h"

namespace fs = std::filesystem;
using Map = mrpt::maps::CMultiBinElevationMap;

namespace {

const std::string kSource = MULTIBIN_SOURCE_DIR;
const std::string kIni = kSource + "/ini/mockup.ini";
const std::string kSection = "MappingApplication_multiBinElevationMap_00_";

fs::path scratchDir(const std::string& name) {
    return mapper_run::scratchDir("test_georeferenced", name);
}

/** Adds (dx, dy) [m] to every absolute pose a rawlog carries (CObservationRobotPose, alone or in
 * a sensory frame, and CObservationOdometry); sensor poses are on the robot and odometry actions
 * are increments, so they stay. Returns the number of poses moved. */
size_t writeShiftedRawlog(const std::string& in, const fs::path& out, double dx, double dy) {
    size_t moved = 0;
    auto shift = [&](mrpt::obs::CObservation& obs) {
        if (auto* rp = dynamic_cast<mrpt::obs::CObservationRobotPose*>(&obs)) {
            rp->pose.mean.x(rp->pose.mean.x() + dx);
            rp->pose.mean.y(rp->pose.mean.y() + dy);
            moved++;
        } else if (auto* od = dynamic_cast<mrpt::obs::CObservationOdometry*>(&obs)) {
            od->odometry.x(od->odometry.x() + dx);
            od->odometry.y(od->odometry.y() + dy);
            moved++;
        }
    };
    mrpt::io::CFileGZInputStream fin(in);
    auto ain = mrpt::serialization::archiveFrom(fin);
    mrpt::io::CFileGZOutputStream fout(out.string());
    auto aout = mrpt::serialization::archiveFrom(fout);
    for (;;) {
        mrpt::serialization::CSerializable::Ptr o;
        try {
            o = ain.ReadObject();
        } catch (const std::exception&) {
            break;  // end of the file
        }
        if (auto obs = std::dynamic_pointer_cast<mrpt::obs::CObservation>(o)) shift(*obs);
        if (auto sf = std::dynamic_pointer_cast<mrpt::obs::CSensoryFrame>(o))
            for (auto& obs : *sf) shift(*obs);
        aout << *o;
    }
    return moved;
}

/** The ground truth with its corner moved by (dx, dy) [m]. */
void writeShiftedTruth(const std::string& in, const fs::path& out, double dx, double dy) {
    multibin::EsriAsciiGrid g = multibin::EsriAsciiGrid::load(in);
    g.xllcenter_m += dx;
    g.yllcenter_m += dy;
    g.save(out.string());
}

/** The mock-up mapped as elevation-mapper maps it (ini/mockup.ini, the rawlog's pose PDFs),
 * then filled; `dual` maps it with the dual grid instead. */
std::unique_ptr<Map> mapMockup(const std::string& rawlog, bool dual = false) {
    mrpt::config::CConfigFile ini(kIni);
    Map::TCreationOptions c;
    c.loadFromConfigFile(ini, kSection + "creationOpts");
    c.dual_grid = dual;
    auto map = std::make_unique<Map>(c);
    map->insertionOptions.loadFromConfigFile(ini, kSection + "insertOpts");
    RawlogSource::forEachInRawlog(
        rawlog,
        [&](const mrpt::obs::CObservation::Ptr& obs, const mrpt::poses::CPose3DPDFGaussian& pose,
            bool poseHasCov) {
            if (poseHasCov)
                map->insertObservation(*obs, pose);
            else
                map->insertObservation(*obs, pose.mean);
        },
        {});
    map->flushLocalToGlobal();
    map->dem_update_map();
    return map;
}

/** The same cells (measured and filled), heights and sigmas within 0.1 mm, the raster corner
 * moved by exactly (dx, dy). Returns the number of measured cells. */
size_t expectSameMap(const Map& original, const Map& moved, double dx, double dy) {
    using L = Map::RasterLayer;
    const auto src0 = original.toRaster(L::Source), src1 = moved.toRaster(L::Source);
    EXPECT_EQ(src0.rows(), src1.rows());
    EXPECT_EQ(src0.cols(), src1.cols());
    if (src0.rows() != src1.rows() || src0.cols() != src1.cols()) return 0;
    EXPECT_NEAR(src1.xllcenter_m - src0.xllcenter_m, dx, 1e-6);
    EXPECT_NEAR(src1.yllcenter_m - src0.yllcenter_m, dy, 1e-6);
    const auto h0 = original.toRaster(L::Height), h1 = moved.toRaster(L::Height);
    const auto s0 = original.toRaster(L::Sigma), s1 = moved.toRaster(L::Sigma);
    size_t measured = 0, differentSource = 0, heightsOff = 0, sigmasOff = 0;
    float worst_m = 0;
    for (int r = 0; r < src0.rows(); r++)
        for (int c = 0; c < src0.cols(); c++) {
            const float a = src0.heights_m(r, c), b = src1.heights_m(r, c);
            if (!(a == b || (std::isnan(a) && std::isnan(b)))) {
                differentSource++;
                continue;
            }
            if (std::isnan(a)) continue;
            measured += a == 1.f;
            const float dh = std::abs(h0.heights_m(r, c) - h1.heights_m(r, c));
            worst_m = std::max(worst_m, dh);
            heightsOff += !(dh <= 1e-4f);
            sigmasOff += !(std::abs(s0.heights_m(r, c) - s1.heights_m(r, c)) <= 1e-4f);
        }
    EXPECT_EQ(differentSource, 0u) << "cells measured, filled or unknown in one map only";
    EXPECT_EQ(heightsOff, 0u) << "worst height difference " << worst_m << " m";
    EXPECT_EQ(sigmasOff, 0u);
    // The same map seen through the DEM interface at a known cell, in the pose frame.
    for (int r = 0; r < src0.rows(); r += 7)
        for (int c = 0; c < src0.cols(); c += 7) {
            if (src0.heights_m(r, c) != 1.f) continue;
            const double x = src0.xllcenter_m + c * src0.cellsize_m,
                         y = src0.yllcenter_m + r * src0.cellsize_m;
            double z0, z1;
            EXPECT_TRUE(original.dem_get_z(x, y, z0));
            EXPECT_TRUE(moved.dem_get_z(x + dx, y + dy, z1));
            EXPECT_NEAR(z0, z1, 1e-4);
        }
    EXPECT_NEAR(moved.getXMin() - original.getXMin(), dx, 1e-6);
    EXPECT_NEAR(moved.getYMax() - original.getYMax(), dy, 1e-6);
    return measured;
}

struct Shift {
    double dx, dy;
};
// UTM zone 33 near 48.7 N (easting, northing), and a far corner of the range doc/frames.md states.
const Shift kUtm{450000, 5400000}, kFar{-3000000, 9000000};

}  // namespace

TEST(Georeferenced, TheMockupMovedToUtmCoordinatesIsTheSameMapCellForCell) {
    const fs::path dir = scratchDir("cells");
    const std::string rawlog = kSource + "/rawlogs/mockup.rawlog";
    const auto original = mapMockup(rawlog);
    for (const Shift s : {kUtm, kFar}) {
        SCOPED_TRACE("moved by (" + std::to_string(s.dx) + ", " + std::to_string(s.dy) + ") m");
        const fs::path movedLog = dir / "moved.rawlog";
        EXPECT_EQ(writeShiftedRawlog(rawlog, movedLog, s.dx, s.dy), 203u);
        const auto moved = mapMockup(movedLog.string());
        EXPECT_NEAR(moved->mapOrigin().x, s.dx, 1e-9);  // the whole km nearest the first pose
        EXPECT_NEAR(moved->mapOrigin().y, s.dy, 1e-9);
        EXPECT_EQ(moved->statistics().insert.accepted, original->statistics().insert.accepted);
        const size_t measured = expectSameMap(*original, *moved, s.dx, s.dy);
        EXPECT_GT(measured, 20000u);  // the mock-up's measured cells, not an empty map
    }
}

TEST(Georeferenced, TheDualGridMovedToUtmCoordinatesIsTheSameMap) {
    const fs::path dir = scratchDir("dual");
    const std::string rawlog = kSource + "/rawlogs/mockup.rawlog";
    const auto original = mapMockup(rawlog, true);
    const fs::path movedLog = dir / "moved.rawlog";
    writeShiftedRawlog(rawlog, movedLog, kUtm.dx, kUtm.dy);
    const auto moved = mapMockup(movedLog.string(), true);
    EXPECT_GT(expectSameMap(*original, *moved, kUtm.dx, kUtm.dy), 1000u);
    // The local grid followed the robot in the same cells.
    EXPECT_EQ(multibin::MapInternals::localGrid(*moved).window(),
              multibin::MapInternals::localGrid(*original).window());
}

namespace {
/** elevation-mapper on the mock-up's ini (4 traversability draws) with this rawlog and ground
 * truth, into dir/out. */
mapper_run::RunResult runMapper(const fs::path& dir, const std::string& rawlog,
                                const std::string& truth) {
    return mapper_run::runMapper(dir, "--config " + mapper_run::mockupQuickIni(true) +
                                          " --rawlog " + rawlog + " --ground-truth " + truth +
                                          " --no-plots --outputs all --out " +
                                          (dir / "out").string());
}

/** The evaluation table's rows without the two timing columns (as compare-baseline.sh). */
std::vector<std::string> tableRows(const std::string& report) {
    std::vector<std::string> rows;
    std::istringstream in(report);
    for (std::string line; std::getline(in, line);) {
        if (line.empty() || line[0] == ' ') continue;  // the per-area lines below the table
        std::istringstream words(line);
        std::vector<std::string> w{std::istream_iterator<std::string>(words), {}};
        if (w.size() < 4) continue;
        for (const char* method : {"raw_", "laser_only", "multibin", "mrpt_"})
            if (w[0].rfind(method, 0) == 0) {
                w.resize(w.size() - 2);
                std::string row;
                for (const auto& x : w) row += x + " ";
                rows.push_back(row);
            }
    }
    return rows;
}
}  // namespace

// The mock-up's first 20 rawlog entries: the whole rawlog is mapped at UTM coordinates by the
// library above; here the program's evaluation and rasters (three runs of the whole took three
// minutes under the sanitizers).
TEST(Georeferenced, TheMapperGivesTheSameEvaluationAndRastersAtUtmCoordinates) {
    const std::string rawlog = mapper_run::mockupRawlogPrefix(20);
    const std::string truth = kSource + "/rawlogs/mockup_gt.asc";
    const fs::path d0 = scratchDir("mapper_original");
    const mapper_run::RunResult r0 = runMapper(d0, rawlog, truth);
    ASSERT_EQ(r0.exitCode, 0) << r0.out;
    const auto rows0 = tableRows(r0.out);
    EXPECT_EQ(rows0.size(), 6u) << r0.out;
    for (const Shift s : {kUtm, kFar}) {
        SCOPED_TRACE("moved by (" + std::to_string(s.dx) + ", " + std::to_string(s.dy) + ") m");
        const fs::path d1 = scratchDir(s.dx > 0 ? "mapper_moved" : "mapper_moved_far");
        writeShiftedRawlog(rawlog, d1 / "moved.rawlog", s.dx, s.dy);
        writeShiftedTruth(truth, d1 / "moved_gt.asc", s.dx, s.dy);
        const mapper_run::RunResult r1 =
            runMapper(d1, (d1 / "moved.rawlog").string(), (d1 / "moved_gt.asc").string());
        ASSERT_EQ(r1.exitCode, 0) << r1.out;
        EXPECT_EQ(tableRows(r1.out), rows0) << "original:\n" << r0.out << "\nmoved:\n" << r1.out;
        for (const char* layer : {"height", "sigma", "certainty", "source"}) {
            SCOPED_TRACE(layer);
            const std::string name = std::string("elevation_") + layer + ".asc";
            const auto a = multibin::EsriAsciiGrid::load((d0 / "out" / name).string());
            const auto b = multibin::EsriAsciiGrid::load((d1 / "out" / name).string());
            ASSERT_EQ(a.rows(), b.rows());
            ASSERT_EQ(a.cols(), b.cols());
            EXPECT_NEAR(b.xllcenter_m - a.xllcenter_m, s.dx, 1e-6);
            EXPECT_NEAR(b.yllcenter_m - a.yllcenter_m, s.dy, 1e-6);
            EXPECT_EQ(a.heights_m.array().isNaN().count(), b.heights_m.array().isNaN().count());
            const float worst = (a.heights_m - b.heights_m)
                                    .array()
                                    .isNaN()
                                    .select(0.f, (a.heights_m - b.heights_m).array().abs())
                                    .maxCoeff();
            EXPECT_LE(worst, 1e-4f);
        }
    }
}

TEST(Georeferenced, TheOriginIsTheWholeKilometreNearestTheFirstPoseOnTheCellLattice) {
    Map::TCreationOptions c;
    c.resolution_m = 0.03;
    // 452 km: 15 066 666.67 cells of 3 cm, so the origin is rounded to 15 066 667 cells.
    const auto o = c.originNear(451700.2, -5400499.9);
    EXPECT_NEAR(o.x, 15066667 * 0.03, 1e-6);
    EXPECT_NEAR(o.y, -5400000, 1e-6);
    EXPECT_EQ(c.originNear(499.9, -499.9).x, 0.0);  // maps near the frame's origin keep it
    EXPECT_EQ(c.originNear(499.9, -499.9).y, 0.0);

    Map map(c);
    EXPECT_EQ(map.mapOrigin().x, 0.0);
    ASSERT_TRUE(map.insertIndividualPoint(451700.2, -5400499.9, 0.3));
    EXPECT_NEAR(map.mapOrigin().x, o.x, 1e-9);
    EXPECT_NEAR(map.mapOrigin().y, o.y, 1e-9);
    double h, s;
    ASSERT_TRUE(map.getHeight(451700.2, -5400499.9, h, s));
    EXPECT_NEAR(h, 0.3, 1e-6);
    EXPECT_FALSE(map.getHeight(451700.2 + 0.05, -5400499.9, h, s));  // the next cell is unknown
    EXPECT_LE(map.getXMin(), 451700.2);
    EXPECT_GE(map.getXMax(), 451700.2);
    EXPECT_LT(map.getXMax() - map.getXMin(), 10.0);
    // The DEM interface by cell: the cell holding the point answers with its height.
    const size_t cx = size_t((451700.2 - map.getXMin()) / 0.03),
                 cy = size_t((-5400499.9 - map.getYMin()) / 0.03);
    double z;
    ASSERT_TRUE(map.dem_get_z_by_cell(cx, cy, z));
    EXPECT_NEAR(z, 0.3, 1e-6);
    // clear() lets the next data choose again.
    map.clear();
    ASSERT_TRUE(map.insertIndividualPoint(-2999.0, 12.0, 0.1));
    EXPECT_NEAR(map.mapOrigin().x, -3000.0, 0.03);
}

TEST(Georeferenced, AnExplicitOriginIsAnOptionAndAnExtentIsInThePoseFrame) {
    Map::TCreationOptions c;
    c.resolution_m = 0.02;
    c.grow = false;
    c.min_x = 450010, c.max_x = 450014, c.min_y = 5400020, c.max_y = 5400022;
    Map byExtent(c);  // automatic: near the extent's centre
    EXPECT_EQ(byExtent.mapOrigin().x, 450000.0);
    EXPECT_EQ(byExtent.mapOrigin().y, 5400000.0);
    EXPECT_NEAR(byExtent.getXMin(), 450010, 1e-6);
    EXPECT_NEAR(byExtent.getYMax(), 5400022, 1e-6);
    EXPECT_EQ(multibin::MapInternals::grid(byExtent).window().nx, 200);

    c.origin_auto = false;
    c.origin_x_m = 450012, c.origin_y_m = 5400021;
    Map fixed(c);
    EXPECT_EQ(fixed.mapOrigin().x, 450012.0);
    EXPECT_EQ(multibin::MapInternals::grid(fixed).window().ix0,
              -100);  // cells relative to the origin
    ASSERT_TRUE(fixed.insertIndividualPoint(450013.01, 5400020.51, 0.2));
    double h, s;
    ASSERT_TRUE(fixed.getHeight(450013.01, 5400020.51, h, s));
    EXPECT_NEAR(h, 0.2, 1e-6);

    // The keys round-trip through an ini file; a bad origin is refused naming its key.
    mrpt::config::CConfigFileMemory ini;
    c.saveToConfigFile(ini, "c");
    Map::TCreationOptions back;
    back.loadFromConfigFile(ini, "c");
    EXPECT_FALSE(back.origin_auto);
    EXPECT_EQ(back.origin_x_m, 450012.0);
    EXPECT_EQ(back.origin_y_m, 5400021.0);
    c.origin_y_m = std::numeric_limits<double>::quiet_NaN();
    try {
        c.validate();
        ADD_FAILURE() << "a NaN origin was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("origin_y_m"), std::string::npos) << e.what();
    }
    c.origin_y_m = 2e8;
    EXPECT_THROW(c.validate(), std::invalid_argument);
}

namespace {
std::vector<uint8_t> serialize(const Map& map) {
    mrpt::io::CMemoryStream buf;
    auto arch = mrpt::serialization::archiveFrom(buf);
    arch << map;
    const auto* p = static_cast<const uint8_t*>(buf.getRawBufferData());
    return std::vector<uint8_t>(p, p + buf.getTotalBytesCount());
}
void deserialize(const std::vector<uint8_t>& bytes, Map& map) {
    mrpt::io::CMemoryStream buf;
    buf.assignMemoryNotOwn(bytes.data(), bytes.size());
    auto arch = mrpt::serialization::archiveFrom(buf);
    arch >> map;
}
}  // namespace

TEST(Georeferenced, ASavedMapKeepsItsOrigin) {
    Map map;  // automatic origin, growing grid
    ASSERT_TRUE(map.insertIndividualPoint(450001.01, 5400002.03, 0.4));
    Map loaded;
    deserialize(serialize(map), loaded);
    EXPECT_EQ(loaded.mapOrigin().x, 450000.0);
    EXPECT_EQ(loaded.mapOrigin().y, 5400000.0);
    double h, s;
    ASSERT_TRUE(loaded.getHeight(450001.01, 5400002.03, h, s));
    EXPECT_NEAR(h, 0.4, 1e-6);
    EXPECT_EQ(loaded.getXMin(), map.getXMin());
    // New data at other coordinates go to the same cells as before the save.
    ASSERT_TRUE(loaded.insertIndividualPoint(450003.51, 5400001.03, 0.6));
    ASSERT_TRUE(loaded.getHeight(450003.51, 5400001.03, h, s));
    EXPECT_NEAR(h, 0.6, 1e-6);

    // A map that has not chosen its origin yet still chooses it after a load.
    Map empty;
    Map emptyLoaded;
    deserialize(serialize(empty), emptyLoaded);
    ASSERT_TRUE(emptyLoaded.insertIndividualPoint(-2999001.5, 9000000.5, 0.1));
    EXPECT_EQ(emptyLoaded.mapOrigin().x, -2999000.0);
}

// tests/map/data/map_v2_358b5a2.bin: a map saved by the library before it had an origin (commit
// 358b5a2; serialization version 2, options text without the origin keys): a 4 m x 4 m fixed
// extent at x in [1200, 1204] m with heights 0.25 m at (1201.01, 0.51) and 0.75 m at
// (1203.33, -1.27). Its cells are relative to (0, 0), not to the kilometre its extent would pick
// today.
TEST(Georeferenced, AMapSavedBeforeOriginsExistedLoadsAtOriginZero) {
    mrpt::io::CFileInputStream f(kSource + "/tests/map/data/map_v2_358b5a2.bin");
    auto arch = mrpt::serialization::archiveFrom(f);
    Map map;
    arch >> map;
    EXPECT_EQ(map.mapOrigin().x, 0.0);
    EXPECT_EQ(map.mapOrigin().y, 0.0);
    EXPECT_NEAR(map.getXMin(), 1200, 1e-9);
    double h, s;
    ASSERT_TRUE(map.getHeight(1201.01, 0.51, h, s));
    EXPECT_NEAR(h, 0.25, 1e-6);
    ASSERT_TRUE(map.getHeight(1203.33, -1.27, h, s));
    EXPECT_NEAR(h, 0.75, 1e-6);
    // Saved again, it keeps that origin.
    Map again;
    deserialize(serialize(map), again);
    EXPECT_EQ(again.mapOrigin().x, 0.0);
    ASSERT_TRUE(again.getHeight(1203.33, -1.27, h, s));
    EXPECT_NEAR(h, 0.75, 1e-6);
}

TEST(Georeferenced, The3DViewIsPlacedAtTheOriginWithSmallVertices) {
    Map map;
    for (int i = 0; i < 20; i++)
        for (int j = 0; j < 20; j++)
            map.insertIndividualPoint(450001.01 + 0.02 * i, 5400002.01 + 0.02 * j, 0.01 * i);
    mrpt::opengl::CSetOfObjects view;
    map.getVisualizationInto(view);
    auto placed =
        std::dynamic_pointer_cast<mrpt::opengl::CSetOfObjects>(view.getByName("map origin"));
    ASSERT_TRUE(placed);
    EXPECT_EQ(placed->getPoseX(), 450000.0);
    EXPECT_EQ(placed->getPoseY(), 5400000.0);
    auto mesh =
        std::dynamic_pointer_cast<mrpt::opengl::CMesh>(placed->getByName("CMultiBinElevationMap"));
    ASSERT_TRUE(mesh);
    EXPECT_NEAR(mesh->getxMin(), 1.01, 0.05);  // relative to the origin: floats stay exact
    EXPECT_NEAR(mesh->getyMin(), 2.01, 0.05);
}

TEST(Georeferenced, RasterFilesKeepUtmCoordinatesToTheMillimetre) {
    // A 2 x 2 raster of 1.5 cm cells whose lower-left centre is at UTM coordinates.
    multibin::EsriAsciiGrid g;
    g.cellsize_m = 0.015;
    g.xllcenter_m = 450000.0075;
    g.yllcenter_m = 5400001.5075;
    g.heights_m = Eigen::MatrixXf::Constant(2, 2, 0.25f);
    // PLY: vertex (col 1, row 1) at (450000.0225, 5400001.5225): x, y are doubles in the file.
    std::istringstream ply(multibin::meshPlyText(g));
    std::string line;
    std::vector<std::array<double, 3>> vertices;
    bool body = false;
    while (std::getline(ply, line)) {
        if (body && vertices.size() < 4) {
            std::istringstream v(line);
            std::array<double, 3> p{};
            v >> p[0] >> p[1] >> p[2];
            vertices.push_back(p);
        }
        body = body || line == "end_header";
    }
    ASSERT_EQ(vertices.size(), 4u);
    EXPECT_NEAR(vertices[3][0], 450000.0225, 1e-6);
    EXPECT_NEAR(vertices[3][1], 5400001.5225, 1e-6);
    EXPECT_NEAR(vertices[3][2], 0.25, 1e-7);
    // TIFF world file: the upper-left centre.
    std::istringstream tfw(multibin::worldFileText(g));
    std::vector<double> w{std::istream_iterator<double>(tfw), {}};
    ASSERT_EQ(w.size(), 6u);
    EXPECT_NEAR(w[4], 450000.0075, 1e-6);
    EXPECT_NEAR(w[5], 5400001.5225, 1e-6);
}

TEST(Georeferenced, MrptsLineIntersectionFindsTheTerrainAtUtmCoordinates) {
    // A flat 0.4 m x 0.4 m patch at z = 0.3 m; MRPT's intersectLine3D walks the DEM interface.
    Map map;
    for (int i = 0; i < 20; i++)
        for (int j = 0; j < 20; j++)
            map.insertIndividualPoint(450001.01 + 0.02 * i, 5400002.01 + 0.02 * j, 0.3);
    float zMin, zMax;
    ASSERT_TRUE(map.getMinMaxHeight(zMin, zMax));
    EXPECT_NEAR(zMin, 0.3, 1e-6);
    const mrpt::math::TLine3D ray(mrpt::math::TPoint3D(450001.2, 5400002.2, 2.0),
                                  mrpt::math::TPoint3D(450001.2, 5400002.2, -1.0));
    mrpt::math::TObject3D hit;
    ASSERT_TRUE(map.intersectLine3D(ray, hit));
    mrpt::math::TPoint3D p;
    ASSERT_TRUE(hit.getPoint(p));
    EXPECT_NEAR(p.x, 450001.2, 0.03);
    EXPECT_NEAR(p.y, 5400002.2, 0.03);
    EXPECT_NEAR(p.z, 0.3, 0.03);
}
