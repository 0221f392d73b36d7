/* Part of the multibin elevation-mapping library. */
#pragma once

#include <mrpt/maps/CMultiBinElevationMap.h>

#include <cstdint>
#include <string>
#include <vector>

#include "multibin/io/GeoTiff.h"
#include "multibin/io/RasterExport.h"
#include "multibin/io/TiledRaster.h"
#include "multibin/map/TerrainView.h"

namespace multibin {

using MapLayer = mrpt::maps::CMultiBinElevationMap::RasterLayer;

/** The layer a 3D view coloured so shows (TerrainView.h). */
MapLayer layerShownBy(SceneColouring colouring);

/** "height", "sigma", "certainty" or "source". */
const char* mapLayerName(MapLayer layer);

/** Layers of `map` as TiledRasters in the frame of the robot poses, over `tiles` (default: the
 * map's occupiedTiles(kGeoTiffTile)); samples are read from the map when asked (the map must
 * outlive them and stay unchanged meanwhile). The rasters share the last window read: asked for
 * the same window one after the other (a loop over tiles that reads every layer of a tile), the
 * map answers all of them from one query per cell. Not for use from several threads. */
std::vector<TiledRaster> tiledLayers(const mrpt::maps::CMultiBinElevationMap& map,
                                     const std::vector<MapLayer>& layers,
                                     const std::vector<CellWindow>* tiles = nullptr);
/** The same layers read from the map once, over its tiles holding data (one query per cell), and
 * kept sparse (8 B per known cell and 4 B per layer): their samples() and knownSamples() read
 * these cells, not the map, so the known box, the GeoTIFFs, the previews and the 3D view of one
 * run query each cell once, and readers of known samples cost the known cells, not the tiles'.
 * The rasters hold what the map held when read; `tiles` as in tiledLayers(). */
std::vector<TiledRaster> knownLayers(const mrpt::maps::CMultiBinElevationMap& map,
                                     const std::vector<MapLayer>& layers,
                                     const std::vector<CellWindow>* tiles = nullptr);
/** One layer: tiledLayers(map, {layer}, tiles)[0]. */
TiledRaster tiledLayer(const mrpt::maps::CMultiBinElevationMap& map, MapLayer layer,
                       const std::vector<CellWindow>* tiles = nullptr);

/** The known cells of the map (its height layer, tile by tile) grown by margin_cells on every
 * side; empty when no cell is known. What previews and the dense outputs cover. */
CellWindow knownWindow(const TiledRaster& height, int margin_cells);

/** How a preview of a layer is drawn (title, colours, legend) and how its blocks merge when
 * downsampled: height and certainty by their mean, sigma and source by their maximum. */
PreviewStyle layerPreviewStyle(MapLayer layer);
BlockReduce layerBlockReduce(MapLayer layer);

/** The layers over `window` as preview rasters, in one loop over the tiles: one sample per cell
 * up to kPreviewMaxSide_px cells a side, else per k x k block (layerBlockReduce()). */
std::vector<EsriAsciiGrid> previewRasters(const std::vector<TiledRaster>& layers,
                                          const std::vector<MapLayer>& which,
                                          const CellWindow& window);

/** PNG previews (encodePreviewPng()) of previewRasters(), titled, and noted "1 pixel = k x k
 * cells (mean)" when downsampled. Throws std::invalid_argument for an empty window. */
std::vector<std::vector<uint8_t>> layerPreviewPngs(const std::vector<TiledRaster>& layers,
                                                   const std::vector<MapLayer>& which,
                                                   const CellWindow& window);

}  // namespace multibin
