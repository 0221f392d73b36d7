/* Part of the multibin elevation-mapping library: raster exports (crop to the known area, float
 * TIFF with world file, PLY mesh, PNG previews). */
#include "multibin/io/RasterExport.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iomanip>
#include <limits>
#include <map>
#include <mutex>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>

#include "multibin/io/FiniteSamples.h"
#include "multibin/io/OutputFile.h"
#include "multibin/io/RunDeflate.h"

namespace multibin {

ColourLut colourLut(int colormap) {
    // OpenCV builds a colour map's table by interpolation on each call (0.6 M instructions):
    // each map's table is made once.
    static std::mutex mutex;
    static std::map<int, ColourLut> made;
    const std::lock_guard<std::mutex> lock(mutex);
    if (const auto it = made.find(colormap); it != made.end()) return it->second;
    cv::Mat ramp(1, 256, CV_8UC1), bgr;
    for (int i = 0; i < 256; i++) ramp.at<uint8_t>(0, i) = uint8_t(i);
    cv::applyColorMap(ramp, bgr, colormap);
    ColourLut lut;
    for (int i = 0; i < 256; i++) {
        const cv::Vec3b c = bgr.at<cv::Vec3b>(0, i);
        lut[size_t(i)] = {c[2], c[1], c[0]};
    }
    return made[colormap] = lut;
}

RasterBox knownBox(const EsriAsciiGrid& raster, int margin_cells) {
    int r0 = raster.rows(), r1 = -1, c0 = raster.cols(), c1 = -1;
    for (int r = 0; r < raster.rows(); r++)
        for (int c = 0; c < raster.cols(); c++)
            if (std::isfinite(raster.heights_m(r, c))) {
                r0 = std::min(r0, r);
                r1 = std::max(r1, r);
                c0 = std::min(c0, c);
                c1 = std::max(c1, c);
            }
    RasterBox b;
    if (r1 < 0) return b;
    const int m = std::max(0, margin_cells);
    b.row0 = std::max(0, r0 - m);
    b.col0 = std::max(0, c0 - m);
    b.rows = std::min(raster.rows() - 1, r1 + m) - b.row0 + 1;
    b.cols = std::min(raster.cols() - 1, c1 + m) - b.col0 + 1;
    return b;
}

EsriAsciiGrid cropRaster(const EsriAsciiGrid& raster, const RasterBox& box) {
    EsriAsciiGrid g = raster;
    if (box.empty()) {
        g.heights_m.resize(0, 0);
        return g;
    }
    if (box.row0 < 0 || box.col0 < 0 || box.row0 + box.rows > raster.rows() ||
        box.col0 + box.cols > raster.cols())
        throw std::invalid_argument("cropRaster: the box reaches outside the raster");
    g.heights_m = raster.heights_m.block(box.row0, box.col0, box.rows, box.cols);
    g.xllcenter_m = raster.xllcenter_m + box.col0 * raster.cellsize_m;
    g.yllcenter_m = raster.yllcenter_m + box.row0 * raster.cellsize_m;
    return g;
}

std::string worldFileText(double pixel_m, double upperLeftCenterX_m, double upperLeftCenterY_m) {
    // Pixel size in x, rotation terms, pixel size in y (negative: rows go south), centre of the
    // upper-left pixel.
    std::ostringstream w;
    w.precision(12);
    w << pixel_m << "\n0\n0\n"
      << -pixel_m << "\n"
      << upperLeftCenterX_m << "\n"
      << upperLeftCenterY_m << "\n";
    return w.str();
}

std::string worldFileText(const EsriAsciiGrid& raster) {
    return worldFileText(raster.cellsize_m, raster.xllcenter_m, raster.yMax_m());
}

std::string meshPlyText(const EsriAsciiGrid& raster) {
    const int rows = raster.rows(), cols = raster.cols();
    std::vector<int> vertexOf(size_t(rows) * size_t(cols), -1);
    int vertices = 0;
    for (int r = 0; r < rows; r++)
        for (int c = 0; c < cols; c++)
            if (std::isfinite(raster.heights_m(r, c))) vertexOf[size_t(r) * cols + c] = vertices++;

    std::vector<std::array<int, 3>> faces;
    for (int r = 0; r + 1 < rows; r++)
        for (int c = 0; c + 1 < cols; c++) {
            // Counter-clockwise seen from above: (r,c) (r,c+1) (r+1,c+1) (r+1,c).
            const int q[4] = {vertexOf[size_t(r) * cols + c], vertexOf[size_t(r) * cols + c + 1],
                              vertexOf[size_t(r + 1) * cols + c + 1],
                              vertexOf[size_t(r + 1) * cols + c]};
            const int known = (q[0] >= 0) + (q[1] >= 0) + (q[2] >= 0) + (q[3] >= 0);
            if (known == 4) {
                faces.push_back({q[0], q[1], q[2]});
                faces.push_back({q[0], q[2], q[3]});
            } else if (known == 3) {
                std::array<int, 3> f{};
                int k = 0;
                for (int i = 0; i < 4; i++)
                    if (q[i] >= 0) f[size_t(k++)] = q[i];
                faces.push_back(f);
            }
        }

    std::ostringstream out;
    out << "ply\nformat ascii 1.0\ncomment multibin elevation map, map frame [m]\n"
        << "element vertex " << vertices << "\nproperty double x\nproperty double y\n"
        << "property float z\nelement face " << faces.size()
        << "\nproperty list uchar int vertex_indices\nend_header\n";
    // x, y in double with 12 digits: 10 um at UTM northings (a float would round to 0.5 m).
    for (int r = 0; r < rows; r++)
        for (int c = 0; c < cols; c++)
            if (vertexOf[size_t(r) * cols + c] >= 0)
                out << std::setprecision(12) << raster.xllcenter_m + c * raster.cellsize_m << ' '
                    << raster.yllcenter_m + r * raster.cellsize_m << ' ' << std::setprecision(7)
                    << raster.heights_m(r, c) << '\n';
    for (const auto& f : faces) out << "3 " << f[0] << ' ' << f[1] << ' ' << f[2] << '\n';
    return out.str();
}

double niceStep(double rough) {
    if (!(rough > 0) || !std::isfinite(rough)) return 1;
    const double p = std::pow(10.0, std::floor(std::log10(rough)));
    for (const double m : {1.0, 2.0, 5.0})
        if (m * p >= rough) return m * p;
    return 10 * p;
}

namespace {

std::string formatted(const char* format, double v) {
    if (std::abs(v) < 1e-9) v = 0;  // no "-0"
    char buf[64];
    std::snprintf(buf, sizeof buf, format, v);
    return buf;
}

/** Decimals that show `step` [m] exactly enough ("%.2f" for 0.25). */
std::string metreFormat(double step) {
    const int decimals = std::clamp(int(std::ceil(-std::log10(step) - 1e-9)), 0, 6);
    return "%." + std::to_string(decimals) + "f";
}

const cv::Scalar kBlack(0, 0, 0);
// The preview is drawn in R, G, B order (the PNG's), straight into its scanlines.
const cv::Scalar kUnknown(kUnknownGrey[0], kUnknownGrey[1], kUnknownGrey[2]);

void text(cv::Mat& img, const std::string& s, cv::Point at, double size = 0.4) {
    cv::putText(img, s, at, cv::FONT_HERSHEY_SIMPLEX, size, kBlack, 1, cv::LINE_AA);
}

int textWidth(const std::string& s, double size = 0.4) {
    int base = 0;
    return cv::getTextSize(s, cv::FONT_HERSHEY_SIMPLEX, size, 1, &base).width;
}

/** The map panel of a preview: pixel (px, py) of rectangle `panel` shows sample
 * (rows - 1 - py / scale, px / scale) (north up) in colourOf(value). `known`: the indices of the
 * raster's finite samples, ascending. */
template <typename ColourOf>
void drawPanel(cv::Mat& img, const EsriAsciiGrid& raster, const std::vector<uint32_t>& known,
               double scale, const cv::Rect& panel, const ColourOf& colourOf) {
    const int rows = raster.rows(), cols = raster.cols();
    if (panel.width == cols) {  // one pixel per sample (large rasters): coloured in place,
        // the unknown grey first (most of a sparse map's panel), then the known samples in the
        // raster's memory order (column-major: a walk along a row would miss the cache per sample)
        cv::Vec3b* first = img.ptr<cv::Vec3b>(panel.y) + panel.x;
        std::fill(first, first + cols, colourOf(std::numeric_limits<float>::quiet_NaN()));
        const uint8_t* firstBytes = img.ptr<uint8_t>(panel.y) + 3 * panel.x;
        for (int py = 1; py < panel.height; py++)  // the other rows copied from the first
            std::memcpy(img.ptr<uint8_t>(panel.y + py) + 3 * panel.x, firstBytes, 3 * size_t(cols));
        for (const uint32_t i : known) {
            const int c = int(i / uint32_t(rows)), r = int(i % uint32_t(rows));
            img.ptr<cv::Vec3b>(panel.y + rows - 1 - r)[panel.x + c] =  // north up
                colourOf(raster.heights_m.data()[i]);
        }
        return;
    }
    // Enlarged (scale > 1): each sample's colour once, row by row (the raster is column-major),
    // then copied to its pixels through the column of each pixel, found once: the panel is the
    // preview's largest part, and a row of samples drawn again is a copy of the row above.
    std::vector<int> columnOf(static_cast<size_t>(panel.width));
    for (int px = 0; px < panel.width; px++)
        columnOf[size_t(px)] = std::min(cols - 1, int(px / scale));
    std::vector<cv::Vec3b> rowColours(static_cast<size_t>(cols));
    int colouredRow = -1;
    for (int py = 0; py < panel.height; py++) {
        const int r = rows - 1 - std::min(rows - 1, int(py / scale));  // north up
        cv::Vec3b* pixel = img.ptr<cv::Vec3b>(panel.y + py) + panel.x;
        if (r == colouredRow) {
            const cv::Vec3b* above = img.ptr<cv::Vec3b>(panel.y + py - 1) + panel.x;
            std::copy(above, above + panel.width, pixel);
            continue;
        }
        colouredRow = r;
        for (int c = 0; c < cols; c++) rowColours[size_t(c)] = colourOf(raster.heights_m(r, c));
        for (int px = 0; px < panel.width; px++)
            pixel[px] = rowColours[size_t(columnOf[size_t(px)])];
    }
}

}  // namespace

std::vector<uint8_t> encodePreviewPng(const EsriAsciiGrid& raster, const PreviewStyle& style) {
    const int rows = raster.rows(), cols = raster.cols();
    if (rows == 0 || cols == 0) throw std::invalid_argument("the raster is empty");
    const bool categorical = !style.categories.empty();

    if (std::max(rows, cols) > kPreviewMaxSide_px)
        throw std::invalid_argument("a preview of " + std::to_string(cols) + " x " +
                                    std::to_string(rows) + " samples: more than " +
                                    std::to_string(kPreviewMaxSide_px) +
                                    " on a side; downsample it first (blockReduced)");
    // Small rasters enlarged to about 600 px (whole pixels per cell), larger ones one pixel per
    // sample: shrinking by skipping samples would drop a thin route.
    const double scale = std::clamp(std::floor(600.0 / std::max(rows, cols)), 1.0, 20.0);
    const int W = std::max(1, int(std::lround(cols * scale)));
    const int H = std::max(1, int(std::lround(rows * scale)));
    const int L = 70, T = 34, R = 170, B = 70;
    const int panelH = std::max(H, 280);
    // Drawn in place in the PNG's scanlines (a filter byte, then R, G, B per pixel): no copy.
    PngScanlines png(W + L + R, panelH + T + B);
    cv::Mat img = png.image();  // white

    // The finite samples and their range, in one pass (a sparse map's raster is mostly NaN:
    // skipped by blocks).
    float lo = std::numeric_limits<float>::infinity(), hi = -lo;
    std::vector<uint32_t> known;
    forEachFinite(raster.heights_m.data(), size_t(raster.heights_m.size()), [&](size_t i) {
        const float v = raster.heights_m.data()[i];
        lo = std::min(lo, v), hi = std::max(hi, v);
        known.push_back(uint32_t(i));
    });
    if (!(lo <= hi)) lo = hi = 0;
    const float span = hi > lo ? hi - lo : 1.f;
    const ColourLut lut = colourLut(style.colormap);

    auto colourOf = [&](float v) -> cv::Vec3b {  // R, G, B
        if (!std::isfinite(v)) return {kUnknownGrey[0], kUnknownGrey[1], kUnknownGrey[2]};
        if (categorical) {
            for (const RasterCategory& k : style.categories)
                if (int(std::lround(v)) == k.value) return {k.rgb[0], k.rgb[1], k.rgb[2]};
            return {kUnknownGrey[0], kUnknownGrey[1], kUnknownGrey[2]};
        }
        const auto& rgb = colourAt(lut, (v - lo) / span);
        return {rgb[0], rgb[1], rgb[2]};
    };
    drawPanel(img, raster, known, scale, {L, T, W, H}, colourOf);
    cv::rectangle(img, {L - 1, T - 1}, {L + W, T + H}, kBlack);

    // Axes in metres: ticks at cell edges' coordinates, nice steps.
    const double cs = raster.cellsize_m, x0 = raster.xllcenter_m - cs / 2,
                 y0 = raster.yllcenter_m - cs / 2;
    const double pxPerM = scale / cs;
    const double xSpan = cols * cs, ySpan = rows * cs;
    const double step = niceStep(std::max(xSpan, ySpan) / 6);
    const std::string fmt = metreFormat(step);
    for (double x = std::ceil(x0 / step) * step; x <= x0 + xSpan + 1e-9; x += step) {
        const int px = L + int(std::lround((x - x0) * pxPerM));
        cv::line(img, {px, T + H}, {px, T + H + 4}, kBlack);
        const std::string s = formatted(fmt.c_str(), x);
        text(img, s, {px - textWidth(s) / 2, T + H + 17});
    }
    for (double y = std::ceil(y0 / step) * step; y <= y0 + ySpan + 1e-9; y += step) {
        const int py = T + H - int(std::lround((y - y0) * pxPerM));
        cv::line(img, {L - 5, py}, {L - 1, py}, kBlack);
        const std::string s = formatted(fmt.c_str(), y);
        text(img, s, {L - 8 - textWidth(s), py + 4});
    }
    text(img, "x [m]", {L + W / 2 - 15, T + H + 33});
    text(img, "y [m]", {4, T - 8});
    text(img, style.title, {L, 22}, 0.55);
    if (!style.note.empty()) text(img, style.note, {L + textWidth(style.title, 0.55) + 16, 22});

    // Scale bar under the axis.
    const double barM = niceStep(xSpan / 4);
    const int barPx = std::max(1, int(std::lround(barM * pxPerM)));
    const int sy = T + H + 52;
    cv::rectangle(img, {L, sy - 3}, {L + barPx, sy + 3}, kBlack, cv::FILLED);
    text(img, formatted(metreFormat(barM).c_str(), barM) + " m", {L + barPx + 8, sy + 5});

    // Colour bar or categorical legend, then the unknown swatch.
    const int bx = L + W + 24;
    int legendBottom = T;
    if (categorical) {
        for (size_t i = 0; i < style.categories.size(); i++) {
            const int y = T + int(i) * 24;
            const RasterCategory& k = style.categories[i];
            cv::rectangle(img, {bx, y}, {bx + 16, y + 16}, cv::Scalar(k.rgb[0], k.rgb[1], k.rgb[2]),
                          cv::FILLED);
            cv::rectangle(img, {bx, y}, {bx + 16, y + 16}, kBlack);
            text(img, k.name, {bx + 24, y + 13});
            legendBottom = y + 24;
        }
    } else {
        const int barH = 200;
        for (int i = 0; i < barH; i++) {
            const auto& c = lut[size_t(std::clamp(255 - i * 255 / (barH - 1), 0, 255))];
            cv::line(img, {bx, T + i}, {bx + 18, T + i}, cv::Scalar(c[0], c[1], c[2]));
        }
        cv::rectangle(img, {bx, T}, {bx + 18, T + barH - 1}, kBlack);
        for (int k = 0; k <= 4; k++) {
            const double v = hi - (hi - lo) * k / 4.0;
            const int y = T + (barH - 1) * k / 4;
            cv::line(img, {bx + 18, y}, {bx + 22, y}, kBlack);
            text(img, formatted(style.valueFormat.c_str(), v), {bx + 26, y + 4});
        }
        legendBottom = T + barH + 8;
    }
    cv::rectangle(img, {bx, legendBottom}, {bx + 16, legendBottom + 16}, kUnknown, cv::FILLED);
    cv::rectangle(img, {bx, legendBottom}, {bx + 16, legendBottom + 16}, kBlack);
    text(img, "unknown", {bx + 24, legendBottom + 13});

    // The same pixels as cv::imencode's PNG, coded by their runs (RunDeflate.h): the previews
    // are mostly runs of one colour, which zlib scans byte by byte.
    return png.encode();
}

void saveMeshPly(const EsriAsciiGrid& raster, const std::string& path) {
    writeFileAtomically(path, meshPlyText(raster));
}

}  // namespace multibin
