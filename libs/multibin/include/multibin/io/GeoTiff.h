/* Part of the multibin elevation-mapping library. */
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "multibin/io/TiledRaster.h"

namespace multibin {

/** What saveSparseGeoTiff() writes besides the samples. */
struct GeoTiffOptions {
    /** EPSG code of the projected CRS (metres) the output frame is in, e.g. 32633 for UTM zone
     * 33N; 0: none (a user-defined frame in metres: GDAL reads a local CRS). */
    int epsg = 0;
    std::string description;  //!< TIFF ImageDescription, e.g. "height [m]"
};

/** GeoTIFF tile side [pixels]: TiledRaster tiles of this many cells are the file's tiles. */
constexpr int kGeoTiffTile = 256;

/** Throws std::invalid_argument naming `what` unless `epsg` is 0 or a plausible EPSG code of a
 * projected CRS in metres (1024 .. 32766, outside the geographic codes 4000 .. 4999). */
void checkGeoTiffEpsg(int epsg, const std::string& what);

/** Writes `raster` (tileCells must be kGeoTiffTile) as a single-band float32 GeoTIFF over its
 * tileBounds(): north up, 256 x 256 tiles, DEFLATE (fastest level, no predictor), NaN as
 * nodata (GDAL_NODATA tag), placed by ModelPixelScale and ModelTiepoint (pixel-is-area) in the
 * raster's frame, ProjectedCSTypeGeoKey options.epsg (or user-defined, in metres). Only the tiles
 * of raster.tiles that hold a known sample are written; the others keep offset and byte count 0,
 * which GDAL reads as nodata (its SPARSE_OK convention). Memory: one tile. Written through
 * writeFileAtomically(); errors name `path`. Returns the number of tiles written. */
size_t saveSparseGeoTiff(const TiledRaster& raster, const std::string& path,
                         const GeoTiffOptions& options);
/** Commits file k: calls write(temporaryPath), which fills that file, then puts it in place
 * (writeFileAtomically(path, write), OutputFolder::writeWith(name, write)). */
using CommitFile =
    std::function<void(size_t k, const std::function<bool(const std::string& temporary)>& write)>;

/** saveSparseGeoTiff() of several rasters over the same tiles (tiledLayers()), in one loop over
 * the tiles: each tile is read once for all files. names[k] names file k in errors; commit puts
 * each in place. Returns the tiles written of rasters[0]. */
size_t writeSparseGeoTiffs(const std::vector<TiledRaster>& rasters,
                           const std::vector<std::string>& names,
                           const std::vector<GeoTiffOptions>& options, const CommitFile& commit);

/** The ESRI world file (.tfw) of saveSparseGeoTiff()'s image: the same placement, for programs
 * that read world files and not GeoTIFF tags. */
std::string geoTiffWorldFileText(const TiledRaster& raster);

}  // namespace multibin
