/* Part of the multibin elevation-mapping library: tiled, compressed, sparse float GeoTIFF with
 * Debian's libtiff and libgeotiff. */
#include "multibin/io/GeoTiff.h"

#include <geotiff.h>
#include <geovalues.h>
#include <tiffio.h>
#include <xtiffio.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "multibin/io/OutputFile.h"
#include "multibin/io/RasterExport.h"
#include "multibin/io/RunDeflate.h"

namespace multibin {

namespace {

[[noreturn]] void fail(const std::string& path, const std::string& what) {
    throw std::runtime_error("GeoTIFF '" + path + "': " + what);
}

/** The image row (from the north) and column of the tile whose lower-left cell is (ix0, iy0). */
struct TilePlace {
    uint32_t x_px, y_px;
};
TilePlace placeOf(const CellWindow& tile, const CellWindow& bounds) {
    return {uint32_t(tile.ix0 - bounds.ix0), uint32_t(bounds.iy0 + bounds.ny - tile.iy0 - tile.ny)};
}

void setTags(TIFF* tif, const TiledRaster& raster, const CellWindow& bounds,
             const GeoTiffOptions& options, const std::string& path) {
    // libtiff 4.5 does not know GDAL's nodata tag: declared on this handle only.
    static const TIFFFieldInfo kNodata[] = {{TIFFTAG_GDAL_NODATA, -1, -1, TIFF_ASCII, FIELD_CUSTOM,
                                             1, 0, const_cast<char*>("GDALNoDataValue")}};
    if (TIFFMergeFieldInfo(tif, kNodata, 1) != 0) fail(path, "libtiff refused the GDAL_NODATA tag");
    const auto need = [&](int ok, const char* tag) {
        if (!ok) fail(path, std::string("libtiff refused the tag ") + tag);
    };
    need(TIFFSetField(tif, TIFFTAG_IMAGEWIDTH, uint32_t(bounds.nx)), "ImageWidth");
    need(TIFFSetField(tif, TIFFTAG_IMAGELENGTH, uint32_t(bounds.ny)), "ImageLength");
    need(TIFFSetField(tif, TIFFTAG_BITSPERSAMPLE, 32), "BitsPerSample");
    need(TIFFSetField(tif, TIFFTAG_SAMPLESPERPIXEL, 1), "SamplesPerPixel");
    need(TIFFSetField(tif, TIFFTAG_SAMPLEFORMAT, SAMPLEFORMAT_IEEEFP), "SampleFormat");
    need(TIFFSetField(tif, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_MINISBLACK), "Photometric");
    need(TIFFSetField(tif, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG), "PlanarConfig");
    need(TIFFSetField(tif, TIFFTAG_TILEWIDTH, uint32_t(kGeoTiffTile)), "TileWidth");
    need(TIFFSetField(tif, TIFFTAG_TILELENGTH, uint32_t(kGeoTiffTile)), "TileLength");
    need(TIFFSetField(tif, TIFFTAG_COMPRESSION, COMPRESSION_ADOBE_DEFLATE), "Compression");
    // No predictor: the tiles are mostly NaN (a route's thin strip), which DEFLATE alone packs
    // to almost nothing, while the floating-point predictor (a byte shuffle and differences over
    // every pixel) took most of the writing (doc/results/2026-11-27-route-scale-outputs.md).
    // The tiles are coded by runDeflateZlib() (writeTiles()); the level is libtiff's if it
    // codes them (a byte-swapped file).
    need(TIFFSetField(tif, TIFFTAG_ZIPQUALITY, 1), "ZipQuality");
    need(TIFFSetField(tif, TIFFTAG_GDAL_NODATA, "nan"), "GDAL_NODATA");
    if (!options.description.empty())
        need(TIFFSetField(tif, TIFFTAG_IMAGEDESCRIPTION, options.description.c_str()),
             "ImageDescription");
    // Pixel-is-area: the tie point is the outer upper-left corner of the upper-left pixel.
    double scale[3] = {raster.cellSize_m, raster.cellSize_m, 0};
    double tie[6] = {0,
                     0,
                     0,
                     raster.originX_m + bounds.ix0 * raster.cellSize_m,
                     raster.originY_m + (bounds.iy0 + bounds.ny) * raster.cellSize_m,
                     0};
    need(TIFFSetField(tif, TIFFTAG_GEOPIXELSCALE, 3, scale), "ModelPixelScale");
    need(TIFFSetField(tif, TIFFTAG_GEOTIEPOINTS, 6, tie), "ModelTiepoint");
    std::unique_ptr<GTIF, void (*)(GTIF*)> gtif(GTIFNew(tif), GTIFFree);
    if (!gtif) fail(path, "libgeotiff could not start");
    GTIFKeySet(gtif.get(), GTRasterTypeGeoKey, TYPE_SHORT, 1, RasterPixelIsArea);
    if (options.epsg > 0) {
        GTIFKeySet(gtif.get(), GTModelTypeGeoKey, TYPE_SHORT, 1, ModelTypeProjected);
        GTIFKeySet(gtif.get(), ProjectedCSTypeGeoKey, TYPE_SHORT, 1, options.epsg);
    } else {  // a user-defined projected frame in metres: GDAL reads a local CRS in metres
        GTIFKeySet(gtif.get(), GTModelTypeGeoKey, TYPE_SHORT, 1, ModelTypeProjected);
        GTIFKeySet(gtif.get(), ProjectedCSTypeGeoKey, TYPE_SHORT, 1, KvUserDefined);
        GTIFKeySet(gtif.get(), ProjLinearUnitsGeoKey, TYPE_SHORT, 1, Linear_Meter);
    }
    if (!GTIFWriteKeys(gtif.get())) fail(path, "libgeotiff could not write the geo keys");
}

using TiffHandle = std::unique_ptr<TIFF, void (*)(TIFF*)>;

/** The samples of `tile` into `buffer` (kGeoTiffTile rows from the north, west to east), NaN
 * where unknown; false when none is known. A sparse raster's known samples only are visited. */
bool tileSamples(const TiledRaster& raster, const CellWindow& tile, std::vector<float>& buffer) {
    const auto at = [&](int ix, int iy) -> float& {  // north up
        return buffer[size_t(kGeoTiffTile - 1 - (iy - tile.iy0)) * kGeoTiffTile +
                      size_t(ix - tile.ix0)];
    };
    std::fill(buffer.begin(), buffer.end(), std::numeric_limits<float>::quiet_NaN());
    bool any = false;
    if (raster.knownSamples) {
        raster.knownSamples(tile, tile, [&](int ix, int iy, float v) {
            at(ix, iy) = v;
            any = any || std::isfinite(v);
        });
        return any;
    }
    const EsriAsciiGrid g = raster.samples(tile);
    for (int c = 0; c < kGeoTiffTile; c++)  // column-major: down the columns
        for (int r = 0; r < kGeoTiffTile; r++) {
            const float v = g.heights_m(r, c);
            if (std::isnan(v)) continue;
            at(tile.ix0 + c, tile.iy0 + r) = v;
            any = any || std::isfinite(v);
        }
    return any;
}

/** Writes rasters[k] (all over the same tiles) to paths[k] (private temporaries) in one loop over
 * the tiles, so rasters that share a tile read (tiledLayers()) query the map once; one tile of
 * each in memory. Returns the tiles written of rasters[0]. */
size_t writeTiles(const std::vector<TiledRaster>& rasters, const std::vector<std::string>& paths,
                  const std::vector<GeoTiffOptions>& options) {
    const CellWindow bounds = rasters.front().tileBounds();
    std::vector<TiffHandle> tifs;
    for (size_t k = 0; k < rasters.size(); k++) {
        tifs.emplace_back(XTIFFOpen(paths[k].c_str(), "w"), XTIFFClose);
        if (!tifs.back()) fail(paths[k], "cannot open for writing");
        setTags(tifs.back().get(), rasters[k], bounds, options[k], paths[k]);
    }
    // Tiles in file order (north to south, west to east): readers seek less.
    std::vector<CellWindow> tiles = rasters.front().tiles;
    std::sort(tiles.begin(), tiles.end(), [&](const CellWindow& a, const CellWindow& b) {
        const TilePlace pa = placeOf(a, bounds), pb = placeOf(b, bounds);
        return std::make_pair(pa.y_px, pa.x_px) < std::make_pair(pb.y_px, pb.x_px);
    });
    std::vector<float> buffer(size_t(kGeoTiffTile) * kGeoTiffTile);
    size_t written = 0;
    for (const CellWindow& t : tiles)
        for (size_t k = 0; k < rasters.size(); k++) {
            if (!tileSamples(rasters[k], t, buffer)) continue;  // left sparse: nodata
            const TilePlace p = placeOf(t, bounds);
            TIFF* tif = tifs[k].get();
            const uint32_t i = TIFFComputeTile(tif, p.x_px, p.y_px, 0, 0);
            // The tile's DEFLATE stream made here from its runs (a tile is mostly NaN: the
            // samples' runs, not its bytes, set the cost), written as is; the file's byte
            // order is the machine's unless libtiff swaps, then libtiff encodes it.
            const auto* bytes = reinterpret_cast<const uint8_t*>(buffer.data());
            const tmsize_t n = tmsize_t(buffer.size() * sizeof(float));
            const bool ok =
                TIFFIsByteSwapped(tif) ? TIFFWriteEncodedTile(tif, i, buffer.data(), n) >= 0 : [&] {
                    const std::vector<uint8_t> z = runDeflateZlib(bytes, size_t(n), sizeof(float),
                                                                  kGeoTiffTile * sizeof(float));
                    return TIFFWriteRawTile(tif, i, const_cast<uint8_t*>(z.data()),
                                            tmsize_t(z.size())) >= 0;
                }();
            if (!ok) fail(paths[k], "writing tile " + std::to_string(i) + " failed");
            written += k == 0;
        }
    for (size_t k = 0; k < rasters.size(); k++)
        if (!TIFFWriteDirectory(tifs[k].get())) fail(paths[k], "writing the directory failed");
    return written;
}

void checkWritable(const TiledRaster& raster, const std::string& path,
                   const GeoTiffOptions& options) {
    checkGeoTiffEpsg(options.epsg, "GeoTIFF '" + path + "': EPSG");
    if (raster.tileCells != kGeoTiffTile)
        fail(path, "tiles of " + std::to_string(raster.tileCells) + " cells, the file's are " +
                       std::to_string(kGeoTiffTile));
    if (raster.tiles.empty()) fail(path, "the raster has no known sample");
}

}  // namespace

void checkGeoTiffEpsg(int epsg, const std::string& what) {
    if (epsg == 0) return;
    if (epsg < 1024 || epsg > 32766)
        throw std::invalid_argument(what + " " + std::to_string(epsg) +
                                    ": not an EPSG code of a projected CRS (1024 .. 32766)");
    if (epsg >= 4000 && epsg <= 4999)
        throw std::invalid_argument(
            what + " " + std::to_string(epsg) +
            ": a geographic CRS (degrees); the map's coordinates are metres: give a projected "
            "CRS, e.g. a UTM zone (EPSG 326ZZ north, 327ZZ south)");
}

size_t writeSparseGeoTiffs(const std::vector<TiledRaster>& rasters,
                           const std::vector<std::string>& names,
                           const std::vector<GeoTiffOptions>& options, const CommitFile& commit) {
    if (rasters.empty() || names.size() != rasters.size() || options.size() != rasters.size())
        throw std::invalid_argument("writeSparseGeoTiffs: one name and one options per raster");
    for (size_t k = 0; k < rasters.size(); k++) {
        checkWritable(rasters[k], names[k], options[k]);  // errors name the file, before any exists
        if (!(rasters[k].tiles == rasters[0].tiles) ||
            rasters[k].cellSize_m != rasters[0].cellSize_m)
            fail(names[k], "its tiles differ from those of '" + names[0] + "'");
    }
    // Each file is committed by its own writer; the innermost writes them all at once, and each
    // is closed before its writer returns.
    std::vector<std::string> temporaries(rasters.size());
    size_t written = 0;
    std::function<void(size_t)> open = [&](size_t k) {
        if (k == rasters.size()) {
            written = writeTiles(rasters, temporaries, options);
            return;
        }
        commit(k, [&, k](const std::string& temporary) {
            temporaries[k] = temporary;
            open(k + 1);
            return true;
        });
    };
    open(0);
    return written;
}

size_t saveSparseGeoTiff(const TiledRaster& raster, const std::string& path,
                         const GeoTiffOptions& options) {
    return writeSparseGeoTiffs({raster}, {path}, {options},
                               [&](size_t, const std::function<bool(const std::string&)>& write) {
                                   writeFileAtomically(path, write);
                               });
}

std::string geoTiffWorldFileText(const TiledRaster& raster) {
    const CellWindow b = raster.tileBounds();
    return worldFileText(raster.cellSize_m, raster.cellCenterX_m(b.ix0),
                         raster.cellCenterY_m(b.iy0 + b.ny - 1));
}

}  // namespace multibin
