/* The real Middlebury "Aloe" pair (rawlogs/stereo, README there): OpenCV SGBM with the shipped
 * default options against the ground-truth disparity, and what the artefact filters remove. The
 * figures printed here are the ones quoted in doc/sensor-models.md. */
#include <gtest/gtest.h>
#include <mrpt/img/CImage.h>

#include <cmath>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>

#include "multibin/sensors/StereoDisparity.h"

using namespace multibin::sensors;

namespace {
const std::string kDir = MULTIBIN_REFERENCE_DATA_DIR "/stereo/middlebury-aloe/";

struct Scores {
    size_t known = 0;  //!< pixels with ground truth
    size_t valid = 0;  //!< ... and a disparity
    size_t bad = 0;    //!< ... off by more than 2 px
    double badShareOfValid() const { return double(bad) / double(valid); }
    double badShareOfKnown() const { return double(bad + known - valid) / double(known); }
};

Scores score(const DisparityImage& d, const cv::Mat& gt, std::vector<uint8_t>* badMask = nullptr) {
    Scores s;
    if (badMask) badMask->assign(size_t(d.width) * size_t(d.height), 0);
    for (int v = 0; v < d.height; v++)
        for (int u = 0; u < d.width; u++) {
            const int t = gt.at<uint8_t>(v, u);
            if (t == 0) continue;
            s.known++;
            if (!d.valid(u, v)) continue;
            s.valid++;
            const bool bad = std::abs(d.at(u, v) - float(t)) > 2.f;
            if (bad) s.bad++;
            if (badMask) (*badMask)[size_t(v) * size_t(d.width) + size_t(u)] = bad ? 2 : 1;
        }
    return s;
}
}  // namespace

TEST(StereoAloe, SgbmAndArtefactFiltersAgainstGroundTruth) {
    const cv::Mat left = cv::imread(kDir + "aloeL.jpg", cv::IMREAD_GRAYSCALE);
    const cv::Mat right = cv::imread(kDir + "aloeR.jpg", cv::IMREAD_GRAYSCALE);
    const cv::Mat gt = cv::imread(kDir + "aloeGT.png", cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(left.empty() || right.empty() || gt.empty()) << "missing " << kDir;
    ASSERT_EQ(left.size(), gt.size());

    const StereoModelOptions opts;  // the shipped defaults
    DisparityImage d =
        computeDisparitySGBM(mrpt::img::CImage(left, mrpt::img::SHALLOW_COPY),
                             mrpt::img::CImage(right, mrpt::img::SHALLOW_COPY), opts);
    std::vector<uint8_t> before;
    const Scores raw = score(d, gt, &before);
    std::printf(
        "SGBM: %zu px with ground truth, %zu with a disparity (%.1f %%), %.2f %% of those "
        "off by > 2 px (%.2f %% counting missing ones as off)\n",
        raw.known, raw.valid, 100.0 * double(raw.valid) / double(raw.known),
        100.0 * raw.badShareOfValid(), 100.0 * raw.badShareOfKnown());
    EXPECT_LE(raw.badShareOfValid(), 0.04);

    const size_t halo = removeHalos(d, opts);
    const size_t near = removeNearClusters(d, opts);
    size_t badRemoved = 0, goodKept = 0, good = 0;
    for (size_t i = 0; i < before.size(); i++) {
        if (before[i] == 2 && !std::isfinite(d.disparity_px[i])) badRemoved++;
        if (before[i] == 1) {
            good++;
            if (std::isfinite(d.disparity_px[i])) goodKept++;
        }
    }
    const Scores after = score(d, gt);
    const double removedShare = double(badRemoved) / double(raw.bad);
    const double keptShare = double(goodKept) / double(good);
    std::printf(
        "filters: halo removed %zu px, near clusters %zu px; %.1f %% of bad pixels "
        "removed, %.1f %% of good pixels kept; bad share %.2f %% -> %.2f %%\n",
        halo, near, 100.0 * removedShare, 100.0 * keptShare, 100.0 * raw.badShareOfValid(),
        100.0 * after.badShareOfValid());
    EXPECT_GE(keptShare, 0.90);
    EXPECT_GT(removedShare, 0.2);  // removes a real share of the errors
    EXPECT_LT(after.badShareOfValid(), raw.badShareOfValid());
}
