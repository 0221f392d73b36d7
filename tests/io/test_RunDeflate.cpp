/* Part of the multibin elevation-mapping library's tests: the DEFLATE coder of runs
 * (RunDeflate.h) against zlib's decoder, and its PNG against OpenCV's. */
#include <gtest/gtest.h>

#include <cstring>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <stdexcept>
#include <vector>

#include "../common/byte_streams.h"
#include "multibin/io/RunDeflate.h"

namespace {

/** Runs of random pixels of `period` bytes (lengths 1 to 700 pixels, so matches of 3 to 258
 * bytes and their remainders), random literals, and rows repeated. */
std::vector<uint8_t> runsOf(size_t size, int period, size_t rowBytes, uint32_t seed) {
    std::mt19937 rng(seed);
    std::vector<uint8_t> d;
    while (d.size() < size) {
        const int kind = int(rng() % 4);
        if (kind == 0 && rowBytes && d.size() >= rowBytes) {  // a row (or part) repeated
            const size_t n = 1 + rng() % rowBytes;
            for (size_t k = 0; k < n; k++) d.push_back(d[d.size() - rowBytes]);
        } else if (kind == 1) {  // literals
            for (size_t k = 1 + rng() % 40; k > 0; k--) d.push_back(uint8_t(rng()));
        } else {  // one pixel repeated
            uint8_t px[8];
            for (int b = 0; b < period; b++) px[b] = uint8_t(rng() % 3 == 0 ? 255 : rng());
            for (size_t k = 1 + rng() % 700; k > 0; k--) d.insert(d.end(), px, px + period);
        }
    }
    d.resize(size);
    return d;
}

}  // namespace

// Every byte comes back through zlib (which checks the codes, the distances and the Adler-32
// computed in closed form over the runs), for pixels of 1 to 8 bytes, with and without row
// matches, and the edge cases: empty, shorter than a match, runs of exactly 3, 258 and 259 bytes
// (a remainder under 3), one long run, and no run at all.
TEST(RunDeflate, ZlibReadsBackEveryByte) {
    std::vector<std::vector<uint8_t>> cases{{}, {7}, {7, 7}, {1, 2, 3, 1, 2, 3}};
    for (const size_t run : {3u, 258u, 259u, 260u, 517u, 100000u})
        cases.push_back(std::vector<uint8_t>(run + 1, 42));
    std::vector<uint8_t> noise(5000);
    std::mt19937 rng(7);
    for (uint8_t& b : noise) b = uint8_t(rng());
    cases.push_back(noise);
    for (const auto& d : cases)
        for (const int period : {1, 3, 4}) {
            const auto z = multibin::runDeflateZlib(d.data(), d.size(), period);
            EXPECT_EQ(test_bytes::inflated(z, d.size(), 15), d)
                << d.size() << " bytes, period " << period;
        }
    for (uint32_t seed = 1; seed <= 40; seed++) {
        const int period = 1 + int(seed % 8);
        const size_t row = seed % 3 == 0 ? 0 : 300 + 97 * seed;
        const auto d = runsOf(20000 + 3000 * seed, period, row, seed);
        const auto z = multibin::runDeflateZlib(d.data(), d.size(), period, row);
        EXPECT_EQ(test_bytes::inflated(z, d.size(), 15), d) << "seed " << seed;
        EXPECT_LT(z.size(), d.size() / 2) << "runs are coded as matches";
        const auto gz = multibin::runDeflateGzip(d.data(), d.size(), period);
        EXPECT_EQ(test_bytes::inflated(gz, d.size(), 15 + 16), d) << "gzip, seed " << seed;
    }
    EXPECT_THROW(multibin::runDeflateZlib(noise.data(), noise.size(), 9), std::invalid_argument);
}

// A preview-like image (a grey panel, coloured strokes, text-like noise, white margins) as PNG:
// OpenCV's decoder gives back every pixel, and the file is no larger than OpenCV's own PNG of it.
TEST(RunDeflate, PngDecodesToTheSamePixelsAsOpenCvsOwn) {
    cv::Mat bgr(300, 420, CV_8UC3, cv::Scalar(255, 255, 255));
    bgr(cv::Rect(60, 30, 300, 240)).setTo(cv::Scalar(200, 200, 200));
    std::mt19937 rng(3);
    for (int k = 0; k < 400; k++)  // strokes of map colours
        bgr.at<cv::Vec3b>(30 + int(rng() % 240), 60 + int(rng() % 300)) =
            cv::Vec3b(uint8_t(rng()), uint8_t(rng()), uint8_t(rng()));
    for (int y = 5; y < 20; y++)  // anti-aliased text: greys
        for (int x = 60; x < 200; x++) bgr.at<cv::Vec3b>(y, x) = cv::Vec3b::all(uint8_t(rng()));
    cv::Mat rgb;
    cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
    const std::vector<uint8_t> png = multibin::rgbPng(rgb.ptr<uint8_t>(0), rgb.cols, rgb.rows);
    const cv::Mat back = cv::imdecode(png, cv::IMREAD_UNCHANGED);
    ASSERT_EQ(back.type(), CV_8UC3);
    ASSERT_EQ(back.size(), bgr.size());
    EXPECT_EQ(cv::norm(back, bgr, cv::NORM_INF), 0);
    std::vector<uint8_t> opencv;
    ASSERT_TRUE(cv::imencode(".png", bgr, opencv));
    EXPECT_LE(png.size(), opencv.size());
    EXPECT_THROW(multibin::rgbPng(rgb.ptr<uint8_t>(0), 0, 5), std::invalid_argument);
}
