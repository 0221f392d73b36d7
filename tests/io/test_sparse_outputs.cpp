/* Outputs that grow with the route, not its bounding box (issue 35 item 5): the sparse tiled
 * GeoTIFF read back with libtiff (values at known cells, NaN elsewhere, the tiles without data
 * left out, georeferencing, compression), file sizes proportional to the data, memory while
 * writing bounded by one tile, block-reduced previews of a long route, and the dense formats
 * refused with a message naming the way out. */
#include <geotiff.h>
#include <geovalues.h>
#include <gtest/gtest.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/opengl/CMesh.h>
#include <mrpt/opengl/CSetOfObjects.h>
#include <tiffio.h>
#include <xtiffio.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <set>
#include <stdexcept>
#include <tuple>

#include "multibin/fill/SparseFill.h"
#include "multibin/grid/BinGrid.h"
#include "multibin/io/GeoTiff.h"
#include "multibin/io/MapLayerFiles.h"
#include "multibin/io/TiledRaster.h"
#include "multibin/map/MapInternals.h"
#include "multibin/map/TerrainView.h"

namespace fs = std::filesystem;
using multibin::CellWindow;
using multibin::TiledRaster;
using Map = mrpt::maps::CMultiBinElevationMap;

namespace {

fs::path scratchDir(const std::string& name) {
    const fs::path d = fs::path(MULTIBIN_BINARY_DIR) / "test_sparse_outputs" / name;
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

/** libtiff reads GDAL's nodata tag only once told its type. */
TIFFExtendProc previousExtender = nullptr;
void declareGdalNodata(TIFF* tif) {
    static const TIFFFieldInfo info[] = {{TIFFTAG_GDAL_NODATA, -1, -1, TIFF_ASCII, FIELD_CUSTOM, 1,
                                          0, const_cast<char*>("GDALNoDataValue")}};
    TIFFMergeFieldInfo(tif, info, 1);
    if (previousExtender) previousExtender(tif);
}

/** A GeoTIFF read back with libtiff and libgeotiff. */
struct ReadTiff {
    uint32_t width = 0, height = 0, tileWidth = 0, tileLength = 0;
    uint16_t compression = 0, predictor = 0, sampleFormat = 0, bits = 0;
    std::vector<uint64_t> byteCounts;  //!< per tile; 0 for a tile left out
    std::vector<double> pixelScale, tiepoint;
    std::string nodata;
    int epsg = 0;  //!< ProjectedCSTypeGeoKey (KvUserDefined: a local frame), 0 if absent
    int directories = 0;
    std::map<uint32_t, std::vector<float>> tiles;

    explicit ReadTiff(const fs::path& path) {
        static const bool once = [] {
            previousExtender = TIFFSetTagExtender(declareGdalNodata);
            return true;
        }();
        (void)once;
        std::unique_ptr<TIFF, void (*)(TIFF*)> tif(XTIFFOpen(path.c_str(), "r"), XTIFFClose);
        if (!tif) throw std::runtime_error("cannot open " + path.string());
        TIFF* t = tif.get();
        directories = TIFFNumberOfDirectories(t);
        TIFFGetField(t, TIFFTAG_IMAGEWIDTH, &width);
        TIFFGetField(t, TIFFTAG_IMAGELENGTH, &height);
        TIFFGetField(t, TIFFTAG_TILEWIDTH, &tileWidth);
        TIFFGetField(t, TIFFTAG_TILELENGTH, &tileLength);
        TIFFGetField(t, TIFFTAG_COMPRESSION, &compression);
        TIFFGetFieldDefaulted(t, TIFFTAG_PREDICTOR, &predictor);  // absent: none (1)
        TIFFGetField(t, TIFFTAG_SAMPLEFORMAT, &sampleFormat);
        TIFFGetField(t, TIFFTAG_BITSPERSAMPLE, &bits);
        const char* text = nullptr;
        if (TIFFGetField(t, TIFFTAG_GDAL_NODATA, &text) && text) nodata = text;
        uint16_t n = 0;
        double* values = nullptr;
        if (TIFFGetField(t, TIFFTAG_GEOPIXELSCALE, &n, &values))
            pixelScale.assign(values, values + n);
        if (TIFFGetField(t, TIFFTAG_GEOTIEPOINTS, &n, &values)) tiepoint.assign(values, values + n);
        uint64_t* counts = nullptr;
        TIFFGetField(t, TIFFTAG_TILEBYTECOUNTS, &counts);
        const uint32_t k = TIFFNumberOfTiles(t);
        byteCounts.assign(counts, counts + k);
        for (uint32_t i = 0; i < k; i++) {
            if (byteCounts[i] == 0) continue;
            std::vector<float> buf(size_t(tileWidth) * tileLength);
            if (TIFFReadEncodedTile(t, i, buf.data(), tmsize_t(buf.size() * 4)) < 0)
                throw std::runtime_error("tile " + std::to_string(i) + " unreadable");
            tiles[i] = std::move(buf);
        }
        std::unique_ptr<GTIF, void (*)(GTIF*)> gtif(GTIFNew(t), GTIFFree);
        uint16_t code = 0;
        if (gtif && GTIFKeyGet(gtif.get(), ProjectedCSTypeGeoKey, &code, 0, 1) == 1) epsg = code;
    }
    size_t tilesWritten() const { return tiles.size(); }
    /** The sample at image column `col`, row `row` (row 0 north); NaN in a tile left out. */
    float at(uint32_t col, uint32_t row) const {
        const uint32_t across = (width + tileWidth - 1) / tileWidth;
        const uint32_t k = (row / tileLength) * across + col / tileWidth;
        const auto it = tiles.find(k);
        if (it == tiles.end()) return NAN;
        return it->second[size_t(row % tileLength) * tileWidth + col % tileWidth];
    }
    /** The sample whose pixel holds (x, y) [m], by the file's own georeferencing. */
    float atPoint(double x_m, double y_m) const {
        const double col = (x_m - tiepoint[3]) / pixelScale[0];
        const double row = (tiepoint[4] - y_m) / pixelScale[1];
        if (col < 0 || row < 0 || col >= width || row >= height) return NAN;
        return at(uint32_t(col), uint32_t(row));
    }
};

/** A synthetic layer: known only on cells where known(ix, iy), value 0.001 ix - 0.002 iy [m];
 * records the largest window asked for (the memory the writer holds at once). */
struct FormulaLayer {
    std::function<bool(int, int)> known;
    size_t largestRequest_cells = 0;
    static float value(int ix, int iy) { return float(0.001 * ix - 0.002 * iy); }
    TiledRaster raster(double cell_m, double x0_m, double y0_m,
                       const std::vector<CellWindow>& tiles) {
        TiledRaster t;
        t.cellSize_m = cell_m;
        t.originX_m = x0_m;
        t.originY_m = y0_m;
        t.tileCells = multibin::kGeoTiffTile;
        t.tiles = tiles;
        t.samples = [this, cell_m, x0_m, y0_m](const CellWindow& w) {
            largestRequest_cells = std::max(largestRequest_cells, w.cellCount());
            multibin::EsriAsciiGrid g = multibin::EsriAsciiGrid::onLattice({cell_m, w});
            g.xllcenter_m += x0_m;
            g.yllcenter_m += y0_m;
            for (int r = 0; r < w.ny; r++)
                for (int c = 0; c < w.nx; c++)
                    if (known(w.ix0 + c, w.iy0 + r))
                        g.heights_m(r, c) = value(w.ix0 + c, w.iy0 + r);
            return g;
        };
        return t;
    }
};

/** The aligned tiles holding the cells of a diagonal strip (|ix - iy| <= halfWidth, 0 <= ix <
 * length). */
std::vector<CellWindow> stripTiles(int length, int halfWidth) {
    std::vector<CellWindow> tiles;
    for (int i = 0; i < length; i++)
        for (const int d : {-halfWidth, halfWidth, 0}) {
            const CellWindow t = multibin::tileOfCell(i, i + d, multibin::kGeoTiffTile);
            if (std::find(tiles.begin(), tiles.end(), t) == tiles.end()) tiles.push_back(t);
        }
    return tiles;
}

}  // namespace

// A 300 m diagonal strip at 5 cm (a 6000 x 6000 cell box, 36 M cells): the file holds only the
// strip's tiles, every sample reads back, unknown cells are NaN, the placement is the frame's.
TEST(SparseGeoTiff, ALongDiagonalStripReadsBackWithOnlyItsTiles) {
    FormulaLayer f;
    const int length = 6000, half = 40;  // a 4 m wide swath
    f.known = [&](int ix, int iy) { return ix >= 0 && ix < length && std::abs(ix - iy) <= half; };
    const std::vector<CellWindow> tiles = stripTiles(length, half);
    const TiledRaster raster = f.raster(0.05, 1000.0, 2000.0, tiles);
    const fs::path file = scratchDir("strip") / "strip.tif";
    multibin::GeoTiffOptions options;
    options.description = "height [m]";
    const size_t written = multibin::saveSparseGeoTiff(raster, file.string(), options);
    EXPECT_EQ(written, tiles.size());
    // Memory: the writer asked for one tile at a time, never the box.
    EXPECT_EQ(f.largestRequest_cells, size_t(256 * 256));

    const ReadTiff t(file);
    const CellWindow b = raster.tileBounds();
    EXPECT_EQ(b.iy0, -256);  // the strip's edge reaches into the tiles south of cell 0
    EXPECT_EQ(t.width, uint32_t(b.nx));
    EXPECT_EQ(t.height, uint32_t(b.ny));
    EXPECT_EQ(t.tileWidth, 256u);
    EXPECT_EQ(t.tileLength, 256u);
    EXPECT_EQ(t.compression, COMPRESSION_ADOBE_DEFLATE);
    EXPECT_EQ(t.predictor, PREDICTOR_NONE);
    EXPECT_EQ(t.sampleFormat, SAMPLEFORMAT_IEEEFP);
    EXPECT_EQ(t.bits, 32);
    EXPECT_EQ(t.nodata, "nan");
    EXPECT_EQ(t.epsg, KvUserDefined);  // no CRS: a local frame in metres
    EXPECT_EQ(t.directories, 1);       // one image, no empty second directory
    // Of the box's tiles only the strip's hold bytes: about 3 per 256 cells of route.
    const size_t withBytes = size_t(
        std::count_if(t.byteCounts.begin(), t.byteCounts.end(), [](uint64_t n) { return n > 0; }));
    EXPECT_EQ(withBytes, tiles.size());
    EXPECT_EQ(t.byteCounts.size(), size_t(b.nx / 256) * size_t(b.ny / 256));
    EXPECT_LT(tiles.size() * 5, t.byteCounts.size());
    // Georeferencing: pixel (0, 0)'s outer corner is the box's north-west corner.
    ASSERT_EQ(t.pixelScale.size(), 3u);
    ASSERT_EQ(t.tiepoint.size(), 6u);
    EXPECT_DOUBLE_EQ(t.pixelScale[0], 0.05);
    EXPECT_DOUBLE_EQ(t.tiepoint[3], 1000.0 + b.ix0 * 0.05);
    EXPECT_DOUBLE_EQ(t.tiepoint[4], 2000.0 + (b.iy0 + b.ny) * 0.05);
    // Values at known cells, by the file's own georeferencing; NaN beside the strip, both in a
    // written tile and in one left out.
    for (const int i : {0, 1, 255, 256, 3001, 5999})
        for (const int d : {-half, 0, half}) {
            const double x = raster.cellCenterX_m(i), y = raster.cellCenterY_m(i + d);
            EXPECT_EQ(t.atPoint(x, y), FormulaLayer::value(i, i + d)) << i << " " << d;
        }
    EXPECT_TRUE(
        std::isnan(t.atPoint(raster.cellCenterX_m(3000), raster.cellCenterY_m(3000 + half + 1))));
    EXPECT_TRUE(std::isnan(t.atPoint(raster.cellCenterX_m(5000), raster.cellCenterY_m(100))));
    // A dense float raster of the box would be 4 bytes a cell.
    EXPECT_LT(fs::file_size(file) * 50, uint64_t(b.cellCount()) * 4) << fs::file_size(file);
}

TEST(SparseGeoTiff, AnEpsgCodeIsWrittenAndAGeographicOneRefused) {
    FormulaLayer f;
    f.known = [](int ix, int iy) { return ix == 3 && iy == 4; };
    const TiledRaster raster = f.raster(0.1, 450000.0, 5400000.0, {CellWindow{0, 0, 256, 256}});
    const fs::path dir = scratchDir("epsg");
    multibin::GeoTiffOptions options;
    options.epsg = 32633;
    multibin::saveSparseGeoTiff(raster, (dir / "utm.tif").string(), options);
    const ReadTiff t(dir / "utm.tif");
    EXPECT_EQ(t.epsg, 32633);
    EXPECT_EQ(t.atPoint(450000.35, 5400000.45), FormulaLayer::value(3, 4));
    options.epsg = 4326;
    try {
        multibin::saveSparseGeoTiff(raster, (dir / "deg.tif").string(), options);
        FAIL() << "EPSG 4326 accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("geographic"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(dir / "deg.tif"));
}

// Block means and maxima by hand, and a long route's preview within kPreviewMaxSide_px.
TEST(TiledRaster, BlockReductionAndPreviewOfALongRoute) {
    FormulaLayer f;
    f.known = [](int ix, int iy) { return ix >= 0 && iy >= 0 && ix < 3 && iy < 2 && ix != 1; };
    const TiledRaster small = f.raster(0.1, 0, 0, {CellWindow{0, 0, 256, 256}});
    // Block (0, 0) of 4 x 4 cells holds (0,0), (2,0), (0,1), (2,1).
    const multibin::EsriAsciiGrid mean =
        multibin::blockReduced(small, CellWindow{0, 0, 8, 8}, 4, multibin::BlockReduce::Mean);
    ASSERT_EQ(mean.rows(), 2);
    const float v00 = FormulaLayer::value(0, 0), v20 = FormulaLayer::value(2, 0),
                v01 = FormulaLayer::value(0, 1), v21 = FormulaLayer::value(2, 1);
    EXPECT_NEAR(mean.heights_m(0, 0), (v00 + v20 + v01 + v21) / 4, 1e-7);
    EXPECT_TRUE(std::isnan(mean.heights_m(1, 1)));
    EXPECT_DOUBLE_EQ(mean.cellsize_m, 0.4);
    EXPECT_DOUBLE_EQ(mean.xllcenter_m, 0.2);
    const multibin::EsriAsciiGrid max =
        multibin::blockReduced(small, CellWindow{0, 0, 8, 8}, 4, multibin::BlockReduce::Max);
    EXPECT_EQ(max.heights_m(0, 0), std::max({v00, v20, v01, v21}));

    FormulaLayer strip;
    strip.known = [](int ix, int iy) { return ix >= 0 && ix < 6000 && std::abs(ix - iy) <= 40; };
    const TiledRaster route = strip.raster(0.05, 0, 0, stripTiles(6000, 40));
    const CellWindow box = multibin::knownWindow(route, 5);
    // x 0 .. 5999, y -40 .. 6039, plus 5 cells; found from the tiles at the extremes.
    EXPECT_EQ(box, (CellWindow{-5, -45, 6010, 6090}));
    // Two layers in one loop over the tiles give what each gives alone (blocks span tiles).
    FormulaLayer other;
    other.known = [](int ix, int iy) { return ix >= 0 && ix < 6000 && std::abs(ix - iy) <= 20; };
    const TiledRaster narrow = other.raster(0.05, 0, 0, route.tiles);
    const auto both = multibin::blockReduced(
        {route, narrow}, box, 7, {multibin::BlockReduce::Mean, multibin::BlockReduce::Mean});
    const auto alone = multibin::blockReduced(narrow, box, 7, multibin::BlockReduce::Mean);
    EXPECT_TRUE((both[1].heights_m.array().isNaN() == alone.heights_m.array().isNaN()).all());
    int compared = 0;
    for (int r = 0; r < alone.rows(); r++)
        for (int c = 0; c < alone.cols(); c++)
            if (std::isfinite(alone.heights_m(r, c))) {
                EXPECT_FLOAT_EQ(both[1].heights_m(r, c), alone.heights_m(r, c)) << r << " " << c;
                compared++;
            }
    EXPECT_GT(compared, 800);
    const multibin::EsriAsciiGrid p =
        multibin::previewRasters({route}, {multibin::MapLayer::Height}, box).front();
    EXPECT_EQ(p.cols(), (6010 + 5) / 6);  // k = 6 brings 6010 cells within 1024
    EXPECT_LE(std::max(p.rows(), p.cols()), multibin::kPreviewMaxSide_px);
    EXPECT_EQ(strip.largestRequest_cells, size_t(256 * 256));
    // The route stays visible along the whole diagonal.
    for (const int k : {5, 500, 995}) EXPECT_TRUE(std::isfinite(p.heights_m(k, k))) << k;
    EXPECT_FALSE(
        multibin::layerPreviewPngs({route}, {multibin::MapLayer::Height}, box).front().empty());
}

TEST(TiledRaster, DenseOutputsRefuseALongRouteNamingTheAlternative) {
    EXPECT_NO_THROW(multibin::checkDenseOutputFits(CellWindow{0, 0, 4096, 4096}, 0.05, "x", "y"));
    try {
        multibin::checkDenseOutputFits(CellWindow{0, 0, 14000, 14000}, 0.05, "--outputs asc",
                                       "choose --outputs tif");
        FAIL() << "a 14000 x 14000 cell raster accepted";
    } catch (const std::invalid_argument& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("--outputs asc"), std::string::npos) << m;
        EXPECT_NE(m.find("14000 x 14000 cells (700 m x 700 m)"), std::string::npos) << m;
        EXPECT_NE(m.find("choose --outputs tif"), std::string::npos) << m;
    }
}

namespace {
/** A map of 0.25 m cells with a 10 m x 10 m patch (one point a cell, height a plane) at each of
 * `corners` [m]. */
std::unique_ptr<Map> patchMap(const std::vector<std::pair<double, double>>& corners) {
    auto map = std::make_unique<Map>();
    map->creationOptions.resolution_m = 0.25;
    map->setCreationOptions(map->creationOptions);
    for (const auto& [x0, y0] : corners)
        for (int i = 0; i < 40; i++)
            for (int j = 0; j < 40; j++)
                map->insertIndividualPoint(x0 + 0.125 + 0.25 * i, y0 + 0.125 + 0.25 * j,
                                           0.3 + 0.01 * i - 0.005 * j);
    map->dem_update_map();
    return map;
}
}  // namespace

// The must-show of issue 35 item 5 with the map itself: two patches 300 m apart write files
// within 2x of one patch's (the bounding box grows 900-fold), and the GeoTIFF holds the map's
// heights at the patches and NaN between.
TEST(SparseMapOutputs, FilesGrowWithThePatchesNotTheirBoundingBox) {
    const double d = 300 / std::sqrt(2.0);
    const auto one = patchMap({{0, 0}});
    const auto two = patchMap({{0, 0}, {d, d}});
    std::map<std::string, uintmax_t> bytes[2];
    const Map* maps[2] = {one.get(), two.get()};
    for (int m = 0; m < 2; m++) {
        const fs::path dir = scratchDir(m ? "two" : "one");
        maps[m]->saveMetricMapRepresentationToFile((dir / "o").string());
        for (const auto& e : fs::directory_iterator(dir))
            bytes[m][e.path().filename().string()] = fs::file_size(e.path());
    }
    const std::vector<std::string> expected{"o_height.tif", "o_sigma.tif",  "o_certainty.tif",
                                            "o_source.tif", "o_height.tfw", "o_height.png",
                                            "o_sigma.png",  "o_source.png", "o.3Dscene"};
    EXPECT_EQ(bytes[1].size(), expected.size());
    for (const std::string& name : expected) {
        ASSERT_TRUE(bytes[0].count(name) && bytes[1].count(name)) << name;
        if (name.find(".tif") != std::string::npos)
            EXPECT_LE(bytes[1][name], 2 * bytes[0][name]) << name;
    }
    const CellWindow window{0, 0, int(two->dem_get_size_x()), int(two->dem_get_size_y())};
    EXPECT_GT(window.cellCount(), 750000u);  // the dense window of the two patches
    EXPECT_LT(bytes[1]["o_height.tif"] * 100, window.cellCount() * 4);

    const ReadTiff t(fs::path(MULTIBIN_BINARY_DIR) / "test_sparse_outputs" / "two" /
                     "o_height.tif");
    EXPECT_EQ(t.tilesWritten(), 2u);
    double h = 0, s = 0;
    // (patch corner, cell i along x, cell j along y): the inserted height 0.3 + 0.01 i - 0.005 j.
    for (const auto& [x0, i, j] : std::vector<std::tuple<double, int, int>>{
             {0, 0, 0}, {0, 20, 29}, {0, 39, 39}, {d, 0, 39}}) {
        const double x = x0 + 0.125 + 0.25 * i, y = x0 + 0.125 + 0.25 * j;
        ASSERT_TRUE(two->cellHeight(x, y, h, s)) << x << " " << y;
        EXPECT_EQ(t.atPoint(x, y), float(h)) << x << " " << y;
        EXPECT_NEAR(h, 0.3 + 0.01 * i - 0.005 * j, 1e-4) << x << " " << y;
    }
    for (const auto& [x, y] : std::vector<std::pair<double, double>>{
             {10.5, 5}, {-0.5, 5}, {d / 2, d / 2}, {d - 0.5, d + 5}})
        EXPECT_TRUE(std::isnan(t.atPoint(x, y))) << x << " " << y;
}

// getAsImage() of a window longer than 4096 cells: one pixel per 2 x 2 block, both ends drawn.
TEST(SparseMapOutputs, GetAsImageOfALongWindowIsDownsampled) {
    Map map;
    map.creationOptions.resolution_m = 1.0;
    map.setCreationOptions(map.creationOptions);
    for (const double x : {0.5, 5000.5}) map.insertIndividualPoint(x, 0.5, 0.25);
    ASSERT_GT(map.dem_get_size_x(), 4096u);
    mrpt::img::CImage img;
    map.getAsImage(img);
    EXPECT_EQ(img.getWidth(), (map.dem_get_size_x() + 1) / 2);
    EXPECT_EQ(img.getHeight(), (map.dem_get_size_y() + 1) / 2);
    // The two known cells' blocks are coloured, the rest black.
    size_t coloured = 0;
    for (size_t y = 0; y < img.getHeight(); y++)
        for (size_t x = 0; x < img.getWidth(); x++) {
            const auto* p = img.ptr<uint8_t>(int(x), int(y));
            coloured += (p[0] | p[1] | p[2]) != 0;
        }
    EXPECT_EQ(coloured, 2u);
}

namespace {
/** The cells of the map's stored tiles and of the filled cells' tiles: what an output that
 * follows the data reads at most once. */
size_t storedTileCells(const Map& map) {
    return (multibin::MapInternals::grid(map).store().tileCount() +
            map.lastFilledCells().cells.tileCount()) *
           multibin::BinStore::kTileSlots;
}
}  // namespace

// Issue 35, "no stage costs more than insertion on a sparse map": each output reads the cells of
// the map's stored 64 x 64 tiles once (the 3D view twice: its box, then its raster), not the
// 256 x 256 tiles it writes nor the window. Counted (rasterReadCounters()), not timed; reading
// every cell of the tiles written, as before, visits 4 to 16 x more here.
TEST(SparseMapOutputs, EachOutputReadsTheStoredTilesNotTheWindow) {
    const double d = 300 / std::sqrt(2.0);
    const auto map = patchMap({{0, 0}, {d, d}});
    const size_t stored = storedTileCells(*map);
    EXPECT_LE(stored, size_t(8 * 4096));  // two 40 x 40-cell patches: at most 4 tiles each
    auto& visited = multibin::rasterReadCounters().cellsVisited;
    const auto layers = multibin::tiledLayers(
        *map, {multibin::MapLayer::Height, multibin::MapLayer::Sigma, multibin::MapLayer::Source});
    EXPECT_EQ(layers[0].tiles.size(), 2u);  // two 256 x 256 tiles written: 131 072 cells
    visited = 0;
    const CellWindow box = multibin::knownWindow(layers[0], 5);
    EXPECT_GT(visited, 0u);
    EXPECT_LE(visited, stored) << "the known box";
    visited = 0;
    multibin::saveSparseGeoTiff(layers[0], (scratchDir("counts") / "h.tif").string(), {});
    EXPECT_GT(visited, 0u);
    EXPECT_LE(visited, stored) << "the GeoTIFF";
    visited = 0;
    multibin::layerPreviewPngs(
        layers, {multibin::MapLayer::Height, multibin::MapLayer::Sigma, multibin::MapLayer::Source},
        box);
    EXPECT_LE(visited, stored) << "three previews";
    visited = 0;
    mrpt::opengl::CSetOfObjects view;
    multibin::buildTerrainView(*map, multibin::SceneColouring::Height, view);
    EXPECT_LE(visited, 2 * stored) << "the 3D view";
}

// The 3D view's meshes cover the tiles of its raster holding data: every known cell is a vertex
// (masked in) at its centre with its height, as in one mesh over the raster; two patches 200 m
// apart take a few tiles of vertices, not their box (606 x 606 vertices).
TEST(SparseMapOutputs, TheSceneMeshesHoldEveryKnownCellAndOnlyTilesAroundTheData) {
    const double d = 200 / std::sqrt(2.0);
    const auto map = patchMap({{0, 0}, {d, d}});
    mrpt::opengl::CSetOfObjects view;
    multibin::buildTerrainView(*map, multibin::SceneColouring::Height, view);
    size_t vertices = 0, meshes = 0;
    std::set<std::pair<long, long>> known;  // cells, once (neighbouring meshes share a row)
    for (const auto& o : view) {
        const auto m = std::dynamic_pointer_cast<mrpt::opengl::CMesh>(o);
        if (!m || m->getName() != "CMultiBinElevationMap") continue;
        meshes++;
        mrpt::math::CMatrixFloat Z, mask;
        m->getZ(Z);
        m->getMask(mask);
        vertices += size_t(Z.rows() * Z.cols());
        const double dx = (m->getxMax() - m->getxMin()) / (Z.rows() - 1),
                     dy = (m->getyMax() - m->getyMin()) / (Z.cols() - 1);
        for (int i = 0; i < Z.rows(); i++)
            for (int j = 0; j < Z.cols(); j++) {
                if (mask(i, j) == 0.f) continue;
                const double x = m->getxMin() + i * dx, y = m->getyMin() + j * dy;
                double h = 0, s = 0;
                ASSERT_TRUE(map->cellHeight(x, y, h, s)) << x << " " << y;
                EXPECT_EQ(Z(i, j), float(h)) << x << " " << y;
                known.emplace(std::lround(x / 0.25 - 0.5), std::lround(y / 0.25 - 0.5));
            }
    }
    EXPECT_EQ(known.size(), 2u * 40 * 40);
    EXPECT_GE(meshes, 2u);
    EXPECT_LE(vertices, size_t(8 * 65 * 65));
}

// The rasters read tile by tile hold, at every cell of the window, what the map's cell query
// answers: height, sigma, source, and a certainty where measured (0 where filled).
TEST(SparseMapOutputs, RastersOfTheWindowAreTheCellQueriesCellForCell) {
    Map map;
    map.creationOptions.resolution_m = 0.25;
    map.setCreationOptions(map.creationOptions);
    for (const double x0 : {0.0, 40.0})
        for (int i = 0; i < 40; i++)
            for (int j = 0; j < 40; j++)
                if (std::abs(i - 20) > 1 || std::abs(j - 20) > 1)  // a hole to fill
                    map.insertIndividualPoint(x0 + 0.125 + 0.25 * i, 0.125 + 0.25 * j,
                                              0.3 + 0.01 * i - 0.005 * j);
    map.dem_update_map();
    using L = Map::RasterLayer;
    const std::vector<multibin::EsriAsciiGrid> g = map.toRasters(
        {L::Height, L::Sigma, L::Source, L::Certainty}, multibin::MapInternals::grid(map).window());
    size_t knownCells = 0, filled = 0;
    for (int r = 0; r < g[0].rows(); r++)
        for (int c = 0; c < g[0].cols(); c++) {
            const double x = g[0].xllcenter_m + c * g[0].cellsize_m,
                         y = g[0].yllcenter_m + r * g[0].cellsize_m;
            double h = 0, s = 0;
            const Map::HeightSource src = map.cellElevation(x, y, h, s, true);
            if (src == Map::HeightSource::Unknown) {
                for (int k = 0; k < 4; k++) ASSERT_TRUE(std::isnan(g[k].heights_m(r, c)));
                continue;
            }
            knownCells++;
            filled += src != Map::HeightSource::Measured;
            ASSERT_EQ(g[0].heights_m(r, c), float(h)) << x << " " << y;
            ASSERT_EQ(g[1].heights_m(r, c), float(s));
            ASSERT_EQ(g[2].heights_m(r, c), float(int(src)));
            ASSERT_EQ(g[3].heights_m(r, c) > 0, src == Map::HeightSource::Measured);
        }
    EXPECT_EQ(knownCells, 2u * 40 * 40);
    EXPECT_EQ(filled, 2u * 9);
}
