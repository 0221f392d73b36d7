/* Part of the multibin elevation-mapping library: a map's layers read tile by tile for the
 * outputs that must scale with the route (GeoTIFF, previews). */
#include "multibin/io/MapLayerFiles.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <tuple>
#include <unordered_map>

#include "multibin/grid/BinStore.h"
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

namespace {

/** A raster of the map's lattice in the frame of the robot poses, over `tiles`, without samples. */
TiledRaster rasterFrame(const CMultiBinElevationMap& map, std::vector<CellWindow> tiles) {
    TiledRaster t;
    t.cellSize_m = map.dem_get_resolution();
    const mrpt::math::TPoint2D origin = map.mapOrigin();
    t.originX_m = origin.x;
    t.originY_m = origin.y;
    t.tileCells = kGeoTiffTile;
    t.tiles = std::move(tiles);
    return t;
}

}  // namespace

std::vector<TiledRaster> tiledLayers(const CMultiBinElevationMap& map,
                                     const std::vector<MapLayer>& layers,
                                     const std::vector<CellWindow>* tiles) {
    const TiledRaster t = rasterFrame(map, tiles ? *tiles : map.occupiedTiles(kGeoTiffTile));
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

namespace {

/** Known cells grouped by raster tile (in the order of the tiles), each tile's row by row. */
struct SparseCells {
    std::vector<int32_t> ix, iy;
    std::vector<float> values;  // layers per cell
    size_t layers = 0;
    std::unordered_map<uint64_t, std::pair<size_t, size_t>> ofTile;  // (iy0, ix0) -> [first, end)
    static uint64_t key(const CellWindow& t) {
        return uint64_t(uint32_t(t.iy0)) << 32 | uint32_t(t.ix0);
    }
    /** Calls visit(cell index) for the cells of `tile` inside `window`, in order. */
    template <typename Visit>
    void forEach(const CellWindow& tile, const CellWindow& window, const Visit& visit) const {
        const auto it = ofTile.find(key(tile));
        if (it == ofTile.end()) return;
        for (size_t c = it->second.first; c < it->second.second; c++)
            if (window.contains(ix[c], iy[c])) visit(c);
    }
};

/** The cells of `layers` of the map's stored tiles where any layer is known, read one store tile
 * (BinStore::kTileCells a side) at a time, grouped by the rasters' tiles of `tileCells`. */
std::shared_ptr<const SparseCells> readSparseCells(const CMultiBinElevationMap& map,
                                                   const std::vector<MapLayer>& layers,
                                                   const std::vector<CellWindow>& storeTiles,
                                                   int tileCells) {
    auto cells = std::make_shared<SparseCells>();
    cells->layers = layers.size();
    struct Cell {
        CellWindow tile;
        int ix, iy;
        size_t at;  // index of its values
    };
    std::vector<Cell> found;
    std::vector<float> values;
    for (const CellWindow& w : storeTiles)
        map.forEachKnownCell(layers, w, [&](int ix, int iy, const float* v) {
            found.push_back({tileOfCell(ix, iy, tileCells), ix, iy, values.size()});
            values.insert(values.end(), v, v + layers.size());
        });
    // By raster tile (south to north, west to east, as occupiedTiles() lists them), then row by
    // row: the order of a dense read of each tile.
    std::sort(found.begin(), found.end(), [](const Cell& a, const Cell& b) {
        return std::tie(a.tile.iy0, a.tile.ix0, a.iy, a.ix) <
               std::tie(b.tile.iy0, b.tile.ix0, b.iy, b.ix);
    });
    for (size_t k = 0; k < found.size(); k++) {
        const Cell& c = found[k];
        cells->ix.push_back(c.ix);
        cells->iy.push_back(c.iy);
        cells->values.insert(cells->values.end(), values.begin() + std::ptrdiff_t(c.at),
                             values.begin() + std::ptrdiff_t(c.at + layers.size()));
        auto& range = cells->ofTile[SparseCells::key(c.tile)];
        if (range.second == 0) range.first = k;
        range.second = k + 1;
    }
    return cells;
}

}  // namespace

std::vector<TiledRaster> knownLayers(const CMultiBinElevationMap& map,
                                     const std::vector<MapLayer>& layers,
                                     const std::vector<CellWindow>* tiles) {
    // The store's tiles holding data, read; the rasters' tiles (those that hold one, as
    // occupiedTiles(kGeoTiffTile) lists them, south to north) found from them.
    const std::vector<CellWindow> store = map.occupiedTiles(BinStore::kTileCells);
    std::vector<CellWindow> rasterTiles;
    if (tiles) {
        rasterTiles = *tiles;
    } else {
        for (const CellWindow& w : store)
            rasterTiles.push_back(tileOfCell(w.ix0, w.iy0, kGeoTiffTile));
        std::sort(rasterTiles.begin(), rasterTiles.end(),
                  [](const CellWindow& a, const CellWindow& b) {
                      return std::tie(a.iy0, a.ix0) < std::tie(b.iy0, b.ix0);
                  });
        rasterTiles.erase(std::unique(rasterTiles.begin(), rasterTiles.end()), rasterTiles.end());
    }
    std::vector<TiledRaster> out(layers.size(), rasterFrame(map, rasterTiles));
    const auto cells = readSparseCells(map, layers, store, kGeoTiffTile);
    for (size_t k = 0; k < out.size(); k++) {
        TiledRaster& t = out[k];
        const double cs = t.cellSize_m, x0 = t.originX_m, y0 = t.originY_m;
        t.samples = [cells, k, cs, x0, y0](const CellWindow& w) {
            EsriAsciiGrid g = EsriAsciiGrid::onLattice(Lattice{cs, w});
            g.xllcenter_m += x0, g.yllcenter_m += y0;
            const CellWindow first = tileOfCell(w.ix0, w.iy0, kGeoTiffTile);
            for (int ty = first.iy0; ty < w.iy0 + w.ny; ty += kGeoTiffTile)
                for (int tx = first.ix0; tx < w.ix0 + w.nx; tx += kGeoTiffTile)
                    cells->forEach(tileOfCell(tx, ty, kGeoTiffTile), w, [&](size_t c) {
                        g.heights_m(cells->iy[c] - w.iy0, cells->ix[c] - w.ix0) =
                            cells->values[c * cells->layers + k];
                    });
            return g;
        };
        t.knownSamples = [cells, k](const CellWindow& tile, const CellWindow& window,
                                    const TiledRaster::SampleVisit& visit) {
            cells->forEach(tile, window, [&](size_t c) {
                visit(cells->ix[c], cells->iy[c], cells->values[c * cells->layers + k]);
            });
        };
    }
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
