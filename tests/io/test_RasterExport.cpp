/* Raster exports (RasterExport.h): the PLY mesh of a height raster. */
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "multibin/io/RasterExport.h"

TEST(Exports, PlyMeshHasOneVertexPerKnownCellAndTwoTrianglesPerKnownQuad) {
    multibin::EsriAsciiGrid g;
    g.cellsize_m = 0.1;
    g.heights_m.setConstant(3, 3, 0.5f);
    g.heights_m(2, 2) = NAN;  // 8 vertices; quads: 3 full (6 triangles) + 1 with 3 known (1)
    const auto path = std::filesystem::temp_directory_path() / "multibin_test_mesh.ply";
    multibin::saveMeshPly(g, path.string());
    std::ifstream f(path);
    std::string text((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find("element vertex 8\n"), std::string::npos);
    EXPECT_NE(text.find("element face 7\n"), std::string::npos);
    std::filesystem::remove(path);
}
