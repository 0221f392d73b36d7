/* Part of the multibin elevation-mapping library: a map's layers read tile by tile for the
 * outputs that must scale with the route (GeoTIFF, previews). */
#include "multibin/io/MapLayerFiles.h"

#include <opencv2/imgproc.hpp>

#include <memory>
#include <stdexcept>

#include "multibin/map/TerrainView.h"

namespace multibin {

using mrpt::maps::CMultiBinElevationMap;

const char* mapLayerName(MapLayer layer) {
    switch (layer) {
        case MapLayer::Sigma:
            return "sigma";
        case MapLayer::Certainty:
            return "certainty";
        case MapLayer::Source:
            return "source";
        default:
            return "height";
    }
}

std::vector<TiledRaster> tiledLayers(const CMultiBinElevationMap& map,
                                     const std::vector<MapLayer>& layers,
                                     const std::vector<CellWindow>* tiles) {
    TiledRaster t;
    t.cellSize_m = map.dem_get_resolution();
    const mrpt::math::TPoint2D origin = map.mapOrigin();
    t.originX_m = origin.x;
    t.originY_m = origin.y;
    t.tileCells = kGeoTiffTile;
    t.tiles = tiles ? *tiles : map.occupiedTiles(kGeoTiffTile);
    struct LastWindow {
        CellWindow window;
        std::vector<EsriAsciiGrid> rasters;  // empty until the first read
        std::vector<bool> taken;             // rasters[k] moved out to its caller
    };
    const auto last = std::make_shared<LastWindow>();
    std::vector<TiledRaster> out(layers.size(), t);
    for (size_t k = 0; k < layers.size(); k++)
        out[k].samples = [m = &map, layers, last, k](const CellWindow& w) {
            // Each layer's raster is handed over, not copied (a 256 x 256 tile is 256 kB): the
            // callers ask every layer once per window; a second ask reads the map again.
            if (last->rasters.empty() || !(last->window == w) || last->taken[k]) {
                last->rasters = m->toRasters(layers, w);
                last->window = w;
                last->taken.assign(layers.size(), false);
            }
            last->taken[k] = true;
            return std::move(last->rasters[k]);
        };
    return out;
}

TiledRaster tiledLayer(const CMultiBinElevationMap& map, MapLayer layer,
                       const std::vector<CellWindow>* tiles) {
    return std::move(tiledLayers(map, {layer}, tiles).front());
}

CellWindow knownWindow(const TiledRaster& height, int margin_cells) {
    CellWindow w = height.knownCells();
    if (w.nx == 0) return w;
    return CellWindow{w.ix0 - margin_cells, w.iy0 - margin_cells, w.nx + 2 * margin_cells,
                      w.ny + 2 * margin_cells};
}

PreviewStyle layerPreviewStyle(MapLayer layer) {
    PreviewStyle s;
    switch (layer) {
        case MapLayer::Height:
            s.title = "height [m]";
            s.colormap = cv::COLORMAP_VIRIDIS;
            break;
        case MapLayer::Sigma:
            s.title = "sigma [m]";
            s.colormap = cv::COLORMAP_INFERNO;
            s.valueFormat = "%.4f";
            break;
        case MapLayer::Certainty:
            s.title = "certainty c [-]";
            s.colormap = cv::COLORMAP_VIRIDIS;
            s.valueFormat = "%.0f";
            break;
        case MapLayer::Source:
            s.title = "source of the height";
            s.categories = heightSourceCategories();
            break;
    }
    return s;
}

BlockReduce layerBlockReduce(MapLayer layer) {
    // Sigma: a block is as uncertain as its worst cell. Source: a block shows "filled" when any
    // of its cells is (codes grow from measured to filled).
    return layer == MapLayer::Sigma || layer == MapLayer::Source ? BlockReduce::Max
                                                                 : BlockReduce::Mean;
}

std::vector<EsriAsciiGrid> previewRasters(const std::vector<TiledRaster>& layers,
                                          const std::vector<MapLayer>& which,
                                          const CellWindow& window) {
    std::vector<BlockReduce> how;
    for (const MapLayer l : which) how.push_back(layerBlockReduce(l));
    return blockReduced(layers, window, blockFactorFor(window, kPreviewMaxSide_px), how);
}

std::vector<std::vector<uint8_t>> layerPreviewPngs(const std::vector<TiledRaster>& layers,
                                                   const std::vector<MapLayer>& which,
                                                   const CellWindow& window) {
    if (window.nx == 0 || window.ny == 0)
        throw std::invalid_argument("previews: the map knows no cell");
    const std::vector<EsriAsciiGrid> rasters = previewRasters(layers, which, window);
    const int k = blockFactorFor(window, kPreviewMaxSide_px);
    std::vector<std::vector<uint8_t>> png;
    for (size_t i = 0; i < which.size(); i++) {
        PreviewStyle style = layerPreviewStyle(which[i]);
        if (k > 1)
            style.note = "1 pixel = " + std::to_string(k) + " x " + std::to_string(k) + " cells (" +
                         (layerBlockReduce(which[i]) == BlockReduce::Mean ? "mean" : "max") + ")";
        png.push_back(encodePreviewPng(rasters[i], style));
    }
    return png;
}

}  // namespace multibin
