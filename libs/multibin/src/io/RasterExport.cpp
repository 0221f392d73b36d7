/* Part of the multibin elevation-mapping library: raster exports (float TIFF, PLY mesh). */
#include "multibin/io/RasterExport.h"

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>
#include <vector>

namespace multibin {

void saveFloatTiff(const EsriAsciiGrid& raster, const std::string& path) {
    const int rows = raster.rows(), cols = raster.cols();
    if (rows == 0 || cols == 0)
        throw std::runtime_error("cannot write '" + path + "': the raster is empty");
    cv::Mat img(rows, cols, CV_32FC1);
    for (int r = 0; r < rows; r++)  // image row 0 is the northernmost
        for (int c = 0; c < cols; c++) img.at<float>(rows - 1 - r, c) = raster.heights_m(r, c);
    bool ok = false;
    try {
        ok = cv::imwrite(path, img);
    } catch (const cv::Exception& e) {
        throw std::runtime_error("cannot write '" + path + "': " + e.what());
    }
    if (!ok) throw std::runtime_error("cannot write '" + path + "'");

    // World file: pixel size in x, rotation terms, pixel size in y (negative: rows go south),
    // centre of the upper-left pixel.
    const std::string worldPath = std::filesystem::path(path).replace_extension(".tfw").string();
    std::ofstream w(worldPath);
    w.precision(12);
    w << raster.cellsize_m << "\n0\n0\n"
      << -raster.cellsize_m << "\n"
      << raster.xllcenter_m << "\n"
      << raster.yMax_m() << "\n";
    if (!w) throw std::runtime_error("cannot write '" + worldPath + "'");
}

void saveMeshPly(const EsriAsciiGrid& raster, const std::string& path) {
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

    std::ofstream out(path);
    if (!out) throw std::runtime_error("cannot write '" + path + "'");
    out << "ply\nformat ascii 1.0\ncomment multibin elevation map, map frame [m]\n"
        << "element vertex " << vertices << "\nproperty float x\nproperty float y\n"
        << "property float z\nelement face " << faces.size()
        << "\nproperty list uchar int vertex_indices\nend_header\n";
    out.precision(7);
    for (int r = 0; r < rows; r++)
        for (int c = 0; c < cols; c++)
            if (vertexOf[size_t(r) * cols + c] >= 0)
                out << raster.xllcenter_m + c * raster.cellsize_m << ' '
                    << raster.yllcenter_m + r * raster.cellsize_m << ' ' << raster.heights_m(r, c)
                    << '\n';
    for (const auto& f : faces) out << "3 " << f[0] << ' ' << f[1] << ' ' << f[2] << '\n';
    if (!out) throw std::runtime_error("cannot write '" + path + "'");
}

}  // namespace multibin
