/* Part of the multibin elevation-mapping library. */
#pragma once

#include <mrpt/maps/CMultiBinElevationMap.h>

#include <cstdint>
#include <string>
#include <vector>

#include "multibin/io/GeoTiff.h"
#include "multibin/io/RasterExport.h"
#include "multibin/io/TiledRaster.h"

namespace multibin {

using MapLayer = mrpt::maps::CMultiBinElevationMap::RasterLayer;

/** "height", "sigma", "certainty" or "source". */
const char* mapLayerName(MapLayer layer);

/** A layer of `map` as a TiledRaster in the frame of the robot poses, over `tiles` (default:
 * the map's occupiedTiles(kGeoTiffTile)); its samples are read from the map when asked (the map
 * must outlive it and stay unchanged meanwhile). */
TiledRaster tiledLayer(const mrpt::maps::CMultiBinElevationMap& map, MapLayer layer,
                       const std::vector<CellWindow>* tiles = nullptr);

/** The known cells of the map (its height layer, tile by tile) grown by margin_cells on every
 * side; empty when no cell is known. What previews and the dense outputs cover. */
CellWindow knownWindow(const TiledRaster& height, int margin_cells);

/** How a preview of a layer is drawn (title, colours, legend) and how its blocks merge when
 * downsampled: height and certainty by their mean, sigma and source by their maximum. */
PreviewStyle layerPreviewStyle(MapLayer layer);
BlockReduce layerBlockReduce(MapLayer layer);

/** The layer over `window` as the preview raster: one sample per cell up to kPreviewMaxSide_px
 * cells a side, else per k x k block (layerBlockReduce()); `note` gets "1 pixel = k x k cells
 * (mean)" when k > 1. Built tile by tile. */
EsriAsciiGrid previewRaster(const TiledRaster& layer, MapLayer which, const CellWindow& window,
                            std::string* note);

/** encodePreviewPng() of previewRaster(), titled and noted. Throws std::invalid_argument for an
 * empty window. */
std::vector<uint8_t> layerPreviewPng(const TiledRaster& layer, MapLayer which,
                                     const CellWindow& window);

}  // namespace multibin
