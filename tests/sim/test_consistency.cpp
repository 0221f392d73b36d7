/* End-to-end check of the shipped scenarios against the contract: the observations, converted
 * to points by MRPT itself (laser) or by the contract's stereo formulas (eqs 8-9), with the true
 * path, land on the terrain they were simulated from. A sign or frame error would show as
 * centimetres or more. */
#include <gtest/gtest.h>
#include <mrpt/maps/CSimplePointsMap.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationStereoImages.h>
#include <mrpt/obs/CRawlog.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include <opencv2/core.hpp>

#include "Terrain.h"

using terrain_sim::Terrain;

namespace {

struct Shipped {
    std::string name;
    std::vector<std::string> boards;
    int tilesX, tilesY;
};

std::vector<mrpt::poses::CPose3D> readTruePath(const std::string& path) {
    std::ifstream f(path);
    std::vector<mrpt::poses::CPose3D> poses;
    for (std::string line; std::getline(f, line);) {
        if (line.empty() || line[0] == '#') continue;
        std::istringstream s(line);
        double k, t, x, y, z, yaw, pitch, roll;
        s >> k >> t >> x >> y >> z >> yaw >> pitch >> roll;
        poses.emplace_back(x, y, z, yaw, pitch, roll);
    }
    return poses;
}

double quantile(std::vector<double> v, double q) {
    for (auto& x : v) x = std::abs(x);
    const size_t k = std::min(v.size() - 1, size_t(q * v.size()));
    std::nth_element(v.begin(), v.begin() + k, v.end());
    return v[k];
}

class ShippedConsistency : public ::testing::TestWithParam<Shipped> {};

}  // namespace

TEST_P(ShippedConsistency, ObservationsLandOnTheTerrainAlongTheTruePath) {
    const Shipped& s = GetParam();
    const std::string prefix = std::string(MULTIBIN_SOURCE_DIR) + "/rawlogs/" + s.name;
    std::vector<multibin::EsriAsciiGrid> boards;
    for (const auto& b : s.boards)
        boards.push_back(multibin::EsriAsciiGrid::load(std::string(MULTIBIN_REFERENCE_DATA_DIR) +
                                                       "/terrain/littledog/" + b + ".asc"));
    const Terrain terrain = Terrain::fromBoards(boards, s.tilesX, s.tilesY, 0.6);
    const auto truth = readTruePath(prefix + "_path.txt");
    mrpt::obs::CRawlog log;
    ASSERT_TRUE(log.loadFromRawLogFile(prefix + ".rawlog"));
    std::vector<double> laserDz, stereoDz;
    size_t frame = 0;
    for (size_t i = 0; i < log.size(); ++i) {
        if (log.getType(i) != mrpt::obs::CRawlog::etSensoryFrame) continue;
        ASSERT_LT(frame, truth.size());
        const mrpt::poses::CPose3D& robot = truth[frame++];
        for (const auto& o : *log.getAsObservations(i)) {
            if (auto scan = std::dynamic_pointer_cast<mrpt::obs::CObservation2DRangeScan>(o)) {
                mrpt::maps::CSimplePointsMap pts;
                pts.insertionOptions.minDistBetweenLaserPoints = 0;
                pts.loadFromRangeScan(*scan, robot);
                for (size_t k = 0; k < pts.size(); ++k) {
                    float x, y, z;
                    pts.getPoint(k, x, y, z);
                    laserDz.push_back(z - terrain.height(x, y));
                }
            } else if (auto st =
                           std::dynamic_pointer_cast<mrpt::obs::CObservationStereoImages>(o)) {
                ASSERT_TRUE(st->hasImageDisparity);
                const cv::Mat d = st->imageDisparity.asCvMat<cv::Mat>(mrpt::img::SHALLOW_COPY);
                const auto& c = st->leftCamera;
                const double B = st->rightCameraPose.x();
                const mrpt::poses::CPose3D cam = robot + mrpt::poses::CPose3D(st->cameraPose);
                for (int v = 0; v < d.rows; v += 3)
                    for (int u = 0; u < d.cols; u += 3) {
                        const uint16_t raw = d.at<uint16_t>(v, u);
                        if (raw == 0) continue;
                        const double zc = c.fx() * B / (raw / 16.0);  // eq 8
                        const mrpt::math::TPoint3D pc((u - c.cx()) * zc / c.fx(),
                                                      (v - c.cy()) * zc / c.fy(), zc);  // eq 9
                        const auto p = cam.composePoint(pc);
                        stereoDz.push_back(p.z - terrain.height(p.x, p.y));
                    }
            }
        }
    }
    EXPECT_EQ(frame, truth.size());
    ASSERT_GT(laserDz.size(), 10000u);
    ASSERT_GT(stereoDz.size(), 10000u);
    const double lMed = quantile(laserDz, 0.5), l90 = quantile(laserDz, 0.9);
    const double sMed = quantile(stereoDz, 0.5), s90 = quantile(stereoDz, 0.9);
    std::cout << s.name << ": |z - terrain| laser median " << lMed << " m, 90 % " << l90 << " m ("
              << laserDz.size() << " points); stereo median " << sMed << " m, 90 % " << s90
              << " m (" << stereoDz.size() << " points)\n";
    // Laser: sigma_r of 1-3 mm plus a +-4 mm surface bias, seen at 45 deg; a few mixed pixels.
    EXPECT_LT(lMed, 0.004);
    EXPECT_LT(l90, 0.012);
    // Stereo: 0.25 px matching noise is about 1 cm in depth at 1 m; halos and blobs are the tail.
    EXPECT_LT(sMed, 0.008);
    EXPECT_LT(s90, 0.04);
}

INSTANTIATE_TEST_SUITE_P(Rawlogs, ShippedConsistency,
                         ::testing::Values(Shipped{"mockup", {"B", "X1", "W", "AC"}, 3, 3},
                                           Shipped{
                                               "walk", {"B", "X1", "W", "AC", "CC", "CD"}, 4, 2}),
                         [](const auto& info) { return info.param.name; });
