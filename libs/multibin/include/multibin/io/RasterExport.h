/* Part of the multibin elevation-mapping library. */
#pragma once

#include <string>

#include "multibin/io/EsriAsciiGrid.h"

namespace multibin {

/** Writes a raster as a single-band float32 TIFF, north up, NaN where unknown, with an ESRI world
 * file beside it (PATH with extension .tfw) so GIS tools (GDAL, QGIS) place it in the map frame
 * [m]. Throws std::runtime_error naming the file if it cannot be written. */
void saveFloatTiff(const EsriAsciiGrid& raster, const std::string& path);

/** Writes the raster as a triangle mesh in ASCII PLY: one vertex per known sample at its cell
 * centre (x, y, height) [m], two triangles per 2x2 block of known samples (one where exactly three
 * are known). Throws std::runtime_error naming the file if it cannot be written. */
void saveMeshPly(const EsriAsciiGrid& raster, const std::string& path);

}  // namespace multibin
