/* Part of the multibin elevation-mapping library: a map's layers read tile by tile for the
 * outputs that must scale with the route (GeoTIFF, previews). */
#include "multibin/io/MapLayerFiles.h"

#include <opencv2/imgproc.hpp>

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

TiledRaster tiledLayer(const CMultiBinElevationMap& map, MapLayer layer,
                       const std::vector<CellWindow>* tiles) {
    TiledRaster t;
    t.cellSize_m = map.dem_get_resolution();
    const mrpt::math::TPoint2D origin = map.mapOrigin();
    t.originX_m = origin.x;
    t.originY_m = origin.y;
    t.tileCells = kGeoTiffTile;
    t.tiles = tiles ? *tiles : map.occupiedTiles(kGeoTiffTile);
    const CMultiBinElevationMap* m = &map;
    t.samples = [m, layer](const CellWindow& w) { return m->toRaster(layer, w); };
    return t;
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

EsriAsciiGrid previewRaster(const TiledRaster& layer, MapLayer which, const CellWindow& window,
                            std::string* note) {
    const int k = blockFactorFor(window, kPreviewMaxSide_px);
    const BlockReduce how = layerBlockReduce(which);
    if (note)
        *note = k == 1 ? std::string()
                       : "1 pixel = " + std::to_string(k) + " x " + std::to_string(k) + " cells (" +
                             (how == BlockReduce::Mean ? "mean" : "max") + ")";
    return blockReduced(layer, window, k, how);
}

std::vector<uint8_t> layerPreviewPng(const TiledRaster& layer, MapLayer which,
                                     const CellWindow& window) {
    if (window.nx == 0 || window.ny == 0)
        throw std::invalid_argument(std::string("the ") + mapLayerName(which) +
                                    " preview: the map knows no cell");
    PreviewStyle style = layerPreviewStyle(which);
    const EsriAsciiGrid raster = previewRaster(layer, which, window, &style.note);
    return encodePreviewPng(raster, style);
}

}  // namespace multibin
