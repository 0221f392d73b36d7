/* Raster exports by hand-computed cases: the known-area crop and its georeference, the PNG
 * preview's colours (unknown cells in a grey no known cell gets, categories in their colours), and
 * files written whole (writeFileAtomically). */
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <set>

#include "multibin/io/OutputFile.h"
#include "multibin/io/RasterExport.h"

namespace fs = std::filesystem;
using multibin::EsriAsciiGrid;

namespace {
EsriAsciiGrid unknownRaster(int rows, int cols) {
    EsriAsciiGrid g;
    g.cellsize_m = 0.5;
    g.xllcenter_m = 10.25;
    g.yllcenter_m = -3.75;
    g.heights_m.setConstant(rows, cols, NAN);
    return g;
}

/** The colour (B, G, R) of sample (row, col) of `raster` in a preview: the preview's pixel that
 * shows it, found as the map panel's pixel at the sample's centre. */
cv::Vec3b previewColourAt(const cv::Mat& img, const EsriAsciiGrid& raster, int row, int col) {
    // The panel: 70 px left margin, 34 px top margin, whole pixels per cell (600 / long side, at
    // most 20).
    const int scale = std::min(20, 600 / std::max(raster.rows(), raster.cols()));
    const int x = 70 + col * scale + scale / 2;
    const int y = 34 + (raster.rows() - 1 - row) * scale + scale / 2;  // north up
    return img.at<cv::Vec3b>(y, x);
}
}  // namespace

// Two known samples: the box is their bounding box grown by the margin and clipped to the
// raster; the crop keeps each sample at its map position.
TEST(RasterExport, KnownBoxAndCropKeepThePlace) {
    EsriAsciiGrid g = unknownRaster(10, 12);
    g.heights_m(2, 3) = 1.f;
    g.heights_m(4, 5) = 2.f;
    const multibin::RasterBox b = multibin::knownBox(g, 1);
    EXPECT_EQ(b.row0, 1);
    EXPECT_EQ(b.col0, 2);
    EXPECT_EQ(b.rows, 5);
    EXPECT_EQ(b.cols, 5);
    const EsriAsciiGrid c = multibin::cropRaster(g, b);
    EXPECT_EQ(c.rows(), 5);
    EXPECT_EQ(c.cols(), 5);
    EXPECT_DOUBLE_EQ(c.xllcenter_m, 10.25 + 2 * 0.5);
    EXPECT_DOUBLE_EQ(c.yllcenter_m, -3.75 + 1 * 0.5);
    // Sample (2, 3) at x = 11.75, y = -2.75 m in both.
    EXPECT_EQ(c.heights_m(2 - 1, 3 - 2), 1.f);
    EXPECT_DOUBLE_EQ(c.xllcenter_m + (3 - 2) * c.cellsize_m, 11.75);
    EXPECT_DOUBLE_EQ(c.yllcenter_m + (2 - 1) * c.cellsize_m, -2.75);
    EXPECT_EQ(c.heights_m(4 - 1, 5 - 2), 2.f);
    // Clipped at the raster's edge; empty when nothing is known.
    EXPECT_EQ(multibin::knownBox(g, 50).rows, 10);
    EXPECT_TRUE(multibin::knownBox(unknownRaster(4, 4), 2).empty());
}

// A ramp with a hole: the hole is drawn in the unknown grey, which no known sample gets; the two
// ends of the ramp get different colours.
TEST(RasterExport, PreviewDrawsUnknownInADistinctGrey) {
    EsriAsciiGrid g = unknownRaster(20, 30);
    for (int r = 0; r < 20; r++)
        for (int c = 0; c < 30; c++) g.heights_m(r, c) = 0.01f * c;
    g.heights_m.block(8, 10, 4, 4).setConstant(NAN);
    multibin::PreviewStyle style;
    style.title = "height [m]";
    const cv::Mat img = cv::imdecode(multibin::encodePreviewPng(g, style), cv::IMREAD_COLOR);
    ASSERT_FALSE(img.empty());
    const cv::Vec3b grey(multibin::kUnknownGrey[2], multibin::kUnknownGrey[1],
                         multibin::kUnknownGrey[0]);
    EXPECT_EQ(previewColourAt(img, g, 9, 11), grey);
    for (int r = 0; r < 20; r++)
        for (int c = 0; c < 30; c++)
            if (std::isfinite(g.heights_m(r, c))) {
                EXPECT_NE(previewColourAt(img, g, r, c), grey) << r << ", " << c;
            }
    EXPECT_NE(previewColourAt(img, g, 0, 0), previewColourAt(img, g, 0, 29));
}

// Categorical layers: each category in its own colour; other values as unknown.
TEST(RasterExport, PreviewDrawsCategoriesInTheirColours) {
    EsriAsciiGrid g = unknownRaster(3, 3);
    g.heights_m << 1, 2, 3, 1, 2, 3, 7, 7, 7;
    multibin::PreviewStyle style;
    style.categories = {{1, "a", {10, 20, 30}}, {2, "b", {200, 100, 0}}, {3, "c", {0, 250, 5}}};
    const cv::Mat img = cv::imdecode(multibin::encodePreviewPng(g, style), cv::IMREAD_COLOR);
    EXPECT_EQ(previewColourAt(img, g, 0, 0), cv::Vec3b(30, 20, 10));
    EXPECT_EQ(previewColourAt(img, g, 1, 1), cv::Vec3b(0, 100, 200));
    EXPECT_EQ(previewColourAt(img, g, 0, 2), cv::Vec3b(5, 250, 0));
    EXPECT_EQ(
        previewColourAt(img, g, 2, 1),
        cv::Vec3b(multibin::kUnknownGrey[2], multibin::kUnknownGrey[1], multibin::kUnknownGrey[0]));
}

// A file is replaced whole; a write that cannot happen names the file and leaves no temporary.
TEST(OutputFile, ReplacesWholeOrFailsNamingTheFile) {
    const fs::path d = fs::path(MULTIBIN_BINARY_DIR) / "test_output_file";
    fs::remove_all(d);
    fs::create_directories(d);
    const fs::path f = d / "a.txt";
    multibin::writeFileAtomically(f.string(), std::string("first version, longer"));
    multibin::writeFileAtomically(f.string(), std::string("second"));
    std::ifstream in(f);
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), "second");
    std::set<std::string> names;
    for (const auto& e : fs::directory_iterator(d)) names.insert(e.path().filename().string());
    EXPECT_EQ(names, std::set<std::string>{"a.txt"});

    const std::string missing = (d / "no" / "such" / "b.txt").string();
    try {
        multibin::writeFileAtomically(missing, std::string("x"));
        FAIL() << "no error";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
    }
    // A writer that fails: its error names the file asked for, not the temporary.
    try {
        multibin::writeFileAtomically((d / "c.asc").string(), [](const std::string& tmp) {
            throw std::runtime_error("grid '" + tmp + "': disk full");
            return true;
        });
        FAIL() << "no error";
    } catch (const std::runtime_error& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find((d / "c.asc").string()), std::string::npos) << m;
        EXPECT_EQ(m.find("partial"), std::string::npos) << m;
    }
    names.clear();
    for (const auto& e : fs::directory_iterator(d)) names.insert(e.path().filename().string());
    EXPECT_EQ(names, std::set<std::string>{"a.txt"});
}
