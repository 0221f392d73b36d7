/* Disparity images (StereoDisparity.h): the 16-bit format's round trip, and the artefact
 * filters (halos, textureless pixels, small near clusters). */
#include <gtest/gtest.h>
#include <mrpt/img/CImage.h>

#include <cmath>
#include <limits>
#include <opencv2/core.hpp>
#include <stdexcept>

#include "multibin/sensors/StereoDisparity.h"
#include "multibin/sensors/StereoModel.h"

using namespace multibin;
using namespace multibin::sensors;

TEST(StereoModel, DisparityImageFormatRoundTrip) {
    DisparityImage d(4, 2);
    d.at(0, 0) = 12.5f;
    d.at(3, 1) = 0.0625f;
    const mrpt::img::CImage img = encodeDisparityImage(d);
    EXPECT_EQ(img.asCvMatRef().type(), CV_16UC1);
    EXPECT_EQ(img.asCvMatRef().at<uint16_t>(0, 0), 200);  // 12.5 * 16
    const DisparityImage back = decodeDisparityImage(img);
    EXPECT_FLOAT_EQ(back.at(0, 0), 12.5f);
    EXPECT_FLOAT_EQ(back.at(3, 1), 0.0625f);
    EXPECT_FALSE(back.valid(1, 0));  // 0 = invalid
    mrpt::img::CImage grey(4, 2, mrpt::img::CH_GRAY);
    EXPECT_THROW(decodeDisparityImage(grey), std::invalid_argument);
}

TEST(StereoArtefacts, HaloOnTheNearSideOfAnEdgeIsRemovedFarSideKept) {
    // Background 10 px; a foreground square (30 px) whose matching window fattened it by 2 px:
    // the halo ring carries the foreground disparity over the background.
    DisparityImage d(60, 60);
    for (auto& x : d.disparity_px) x = 10.f;
    for (int v = 18; v < 42; v++)
        for (int u = 18; u < 42; u++)
            d.at(u, v) = 30.f;  // true square: 20..39, halo 18..19, 40..41
    StereoModelOptions o;
    o.halo.radius_px = 2;
    const size_t removed = removeHalos(d, o);
    EXPECT_FALSE(d.valid(18, 30));  // halo pixel: reject
    EXPECT_FALSE(d.valid(41, 30));
    EXPECT_TRUE(d.valid(30, 30));  // foreground interior: keep
    EXPECT_TRUE(d.valid(17, 30));  // background next to the edge: keep
    EXPECT_TRUE(d.valid(5, 5));
    EXPECT_EQ(removed, size_t(24 * 24 - 20 * 20));  // a 2 px band inside the edge
    // A smooth slope (1 px per pixel) is not an edge.
    DisparityImage slope(40, 10);
    for (int v = 0; v < 10; v++)
        for (int u = 0; u < 40; u++) slope.at(u, v) = 5.f + 1.f * float(u);
    EXPECT_EQ(removeHalos(slope, o), 0u);
}

TEST(StereoArtefacts, TexturelessPixelsRemovedTexturedKept) {
    // Left half: alternating 0/255 columns (grey std 127.5); right half: uniform 100 with a
    // +-1 checkerboard (std exactly 1 in any 5 x 5 window: 13 of one sign and 12 of the other
    // give a variance of 1 - (1/25)^2 = 0.9984).
    const int W = 40, H = 20;
    cv::Mat img(H, W, CV_8UC1);
    for (int v = 0; v < H; v++)
        for (int u = 0; u < W; u++)
            img.at<uint8_t>(v, u) =
                u < W / 2 ? uint8_t(u % 2 ? 255 : 0) : uint8_t((u + v) % 2 ? 101 : 99);
    const mrpt::img::CImage left(img, mrpt::img::SHALLOW_COPY);
    DisparityImage d(W, H);
    for (float& x : d.disparity_px) x = 10.f;
    d.at(35, 10) = std::numeric_limits<float>::quiet_NaN();  // already invalid: not counted
    StereoModelOptions o;
    o.texture.minStd_grey = 1.5;
    DisparityImage out = d;
    // Windows reaching a textured column (u <= W/2 - 1 + 2) keep their pixels.
    const size_t expected = size_t(H) * size_t(W / 2 - 2) - 1;
    EXPECT_EQ(removeTextureless(out, left, o), expected);
    for (int v = 0; v < H; v++)
        for (int u = 0; u < W; u++) EXPECT_EQ(out.valid(u, v), u < W / 2 + 2) << u << "," << v;
    o.texture.minStd_grey = 0.9;  // below the checkerboard's std: nothing removed
    out = d;
    EXPECT_EQ(removeTextureless(out, left, o), 0u);
    o.texture.minStd_grey = 0;  // off
    EXPECT_EQ(removeTextureless(out, left, o), 0u);
    o.texture.minStd_grey = 1.5;
    DisparityImage small(W - 1, H);
    EXPECT_THROW(removeTextureless(small, left, o), std::invalid_argument);
}

TEST(StereoArtefacts, SmallNearClusterRemovedLargeOrFarKept) {
    StereoModelOptions o;
    o.nearCluster.maxArea_px = 50;
    DisparityImage d(80, 80);
    for (auto& x : d.disparity_px) x = 10.f;
    for (int v = 5; v < 10; v++)
        for (int u = 5; u < 10; u++) d.at(u, v) = 40.f;  // 25 px blob floating near: reject
    for (int v = 30; v < 40; v++)
        for (int u = 30; u < 40; u++) d.at(u, v) = 40.f;  // 100 px near object: keep
    for (int v = 60; v < 65; v++)
        for (int u = 60; u < 65; u++) d.at(u, v) = 4.f;  // 25 px farther than around: keep
    const size_t removed = removeNearClusters(d, o);
    EXPECT_EQ(removed, 25u);
    EXPECT_FALSE(d.valid(7, 7));
    EXPECT_TRUE(d.valid(35, 35));
    EXPECT_TRUE(d.valid(62, 62));
    EXPECT_TRUE(d.valid(20, 20));
    // An isolated speck in an invalid area is removed too.
    DisparityImage e(20, 20);
    for (int v = 2; v < 4; v++)
        for (int u = 2; u < 4; u++) e.at(u, v) = 12.f;
    EXPECT_EQ(removeNearClusters(e, o), 4u);
}
