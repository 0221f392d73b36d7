/* Part of the multibin elevation-mapping library.
 * CMultiBinElevationMap: rasters, images and files. */
#include <mrpt/opengl/COpenGLScene.h>

#include "CMultiBinElevationMap_impl.h"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <utility>
#include <vector>

#include "multibin/grid/CellSurface.h"
#include "multibin/io/MapLayerFiles.h"
#include "multibin/io/OutputFile.h"
#include "multibin/map/TerrainView.h"

using namespace mrpt::maps;

multibin::EsriAsciiGrid CMultiBinElevationMap::toRaster(RasterLayer layer) const {
    return toRaster(layer, m_impl->grid.window());
}

multibin::EsriAsciiGrid CMultiBinElevationMap::toRaster(RasterLayer layer,
                                                        const multibin::CellWindow& w) const {
    return std::move(toRasters({layer}, w).front());
}

std::vector<multibin::EsriAsciiGrid> CMultiBinElevationMap::toRasters(
    const std::vector<RasterLayer>& layers, const multibin::CellWindow& w) const {
    prepareForReading();
    const multibin::MapLock::Shared lock(m_impl->lock);  // a writer may grow or move the grid
    multibin::EsriAsciiGrid g = multibin::EsriAsciiGrid::onLattice(
        multibin::Lattice{m_impl->grid.cellSize_m(), w});  // NaN: unknown
    g.xllcenter_m += m_impl->origin_m.x();                 // the raster is in the pose frame
    g.yllcenter_m += m_impl->origin_m.y();
    std::vector<multibin::EsriAsciiGrid> out(layers.size(), g);
    forEachKnownCell(layers, w, [&](int ix, int iy, const float* values) {
        for (size_t k = 0; k < layers.size(); k++)
            out[k].heights_m(iy - w.iy0, ix - w.ix0) = values[k];
    });
    return out;
}

void CMultiBinElevationMap::forEachKnownCell(
    const std::vector<RasterLayer>& layers, const multibin::CellWindow& w,
    const std::function<void(int ix, int iy, const float* values)>& visit) const {
    prepareForReading();  // a loaded map's rasters hold its filled cells, as the writer's did
    const multibin::MapLock::Shared lock(m_impl->lock);
    const multibin::BinGrid& grid = m_impl->grid;
    const Eigen::Vector2d& o = m_impl->origin_m;
    // A cell without a bin in either grid and without a filled value is unknown: most cells of
    // a sparse route's tiles, skipped without a query; and a tile of the grid's store with
    // neither (most of a long route's window) skipped whole, so the cost follows the tiles that
    // hold data, not the window.
    const multibin::fill::FilledCells& f = m_impl->filled;
    const multibin::CellWindow& fw = m_impl->fillWindow;
    const bool withFill = insertionOptions.query.dem_return_filled;
    using Store = multibin::BinStore;
    static_assert(Store::kTileCells == multibin::fill::TiledCells<int>::kSide,
                  "the filled cells' tiles are the store's");
    std::vector<float> values(layers.size());
    const auto readCell = [&](int ix, int iy) {
        // cellElevation() without its per-cell preparation (the lock is held here already).
        double h, s;
        const HeightSource src = elevationQuery(false, o.x() + grid.cellCenter_m(ix),
                                                o.y() + grid.cellCenter_m(iy), h, s, withFill);
        if (src == HeightSource::Unknown) return;
        for (size_t k = 0; k < layers.size(); k++) {
            float& v = values[k];
            switch (layers[k]) {
                case RasterLayer::Height:
                    v = float(h);
                    break;
                case RasterLayer::Sigma:
                    v = float(s);
                    break;
                case RasterLayer::Source:
                    v = float(static_cast<int>(src));
                    break;
                case RasterLayer::Certainty: {
                    // The certainty of the surface the height layer reports (0 where
                    // filled).
                    multibin::CellSurface cs;
                    v = src == HeightSource::Measured &&
                                multibin::surfaceAt(grid, isDualGrid() ? &m_impl->local : nullptr,
                                                    grid.cellCenter_m(ix), grid.cellCenter_m(iy),
                                                    binUpdateParams(), false, cs)
                            ? float(cs.certainty)
                            : 0.f;
                } break;
            }
        }
        visit(ix, iy, values.data());
    };
    for (int ty = Store::tileOf(w.iy0); w.nx > 0 && ty <= Store::tileOf(w.iy0 + w.ny - 1); ty++)
        for (int tx = Store::tileOf(w.ix0); tx <= Store::tileOf(w.ix0 + w.nx - 1); tx++) {
            // The store's tile and its filled cells' tile, found once per tile (not per cell).
            const multibin::fill::FilledCell* filledTile =
                withFill ? f.cells.findTile(tx, ty) : nullptr;
            const Impl::TileBins bins(*m_impl, tx, ty, isDualGrid());
            if (bins.empty() && !filledTile) continue;
            const bool filledInside = filledTile && Impl::TileBins::wholeInside(fw, tx, ty);
            const auto filledAt = [&](int ix, int iy) {
                return filledTile && (filledInside || fw.contains(ix, iy)) &&
                       filledTile[multibin::fill::TiledCells<int>::inTile(ix, iy)].source !=
                           multibin::HeightSource::Unknown;
            };
            // Multiplied, not shifted: tile indices are negative left of the origin.
            const int xa = std::max(tx * Store::kTileCells, w.ix0),
                      xb = std::min((tx + 1) * Store::kTileCells, w.ix0 + w.nx);
            const int ya = std::max(ty * Store::kTileCells, w.iy0),
                      yb = std::min((ty + 1) * Store::kTileCells, w.iy0 + w.ny);
            multibin::rasterReadCounters().cellsVisited += size_t(xb - xa) * size_t(yb - ya);
            bins.forEachHeld(xa, xb, ya, yb, filledTile != nullptr, filledAt, readCell);
        }
}

std::vector<multibin::CellWindow> CMultiBinElevationMap::occupiedTiles(int tileCells) const {
    if (tileCells < 1)
        throw std::invalid_argument("occupiedTiles: tileCells " + std::to_string(tileCells) +
                                    " must be at least 1");
    prepareForReading();
    const multibin::MapLock::Shared lock(m_impl->lock);
    // (iy0, ix0), sorted row by row from the south below. The cells come tile by tile: a
    // corner equal to the last one added is skipped without a search.
    std::vector<std::pair<int, int>> corners;
    const auto add = [&](int ix, int iy) {
        const multibin::CellWindow t = multibin::tileOfCell(ix, iy, tileCells);
        if (corners.empty() || corners.back() != std::make_pair(t.iy0, t.ix0))
            corners.emplace_back(t.iy0, t.ix0);
    };
    // The stored bins, tile by tile (BinStore): the cost follows the data, not the window.
    using Store = multibin::BinStore;
    const Store& store = m_impl->grid.store();
    if (tileCells % Store::kTileCells == 0) {
        // A store tile lies in one of these tiles: its first slot holding a bin adds it.
        store.forEachTileNumber([&](uint32_t t, int tx, int ty) {
            for (int r = 0; r < Store::kTileCells; r++)
                if (store.rowHoldingBins(t, r) != 0) {
                    add(tx * Store::kTileCells, ty * Store::kTileCells);
                    break;
                }
        });
    } else {
        store.forEachStoredBin([&](int ix, int iy, const multibin::Bin&) { add(ix, iy); });
    }
    if (isDualGrid()) {  // local cells not yet written back, at the global cell of their centre
        const multibin::BinGrid& l = m_impl->local;
        l.store().forEachStoredBin([&](int ix, int iy, const multibin::Bin&) {
            add(m_impl->grid.cellIndex(l.cellCenter_m(ix)),
                m_impl->grid.cellIndex(l.cellCenter_m(iy)));
        });
    }
    if (insertionOptions.query.dem_return_filled)  // the filled cells, tile by tile
        m_impl->filled.forEachFilled(
            [&](int ix, int iy, const multibin::fill::FilledCell&) { add(ix, iy); });
    std::sort(corners.begin(), corners.end());
    corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
    std::vector<multibin::CellWindow> tiles;
    tiles.reserve(corners.size());
    for (const auto& [iy0, ix0] : corners)
        tiles.push_back(multibin::CellWindow{ix0, iy0, tileCells, tileCells});
    return tiles;
}

void CMultiBinElevationMap::getAsImage(mrpt::img::CImage& img, bool sigma) const {
    prepareForReading();
    const multibin::MapLock::Shared lock(m_impl->lock);
    const RasterLayer layer = sigma ? RasterLayer::Sigma : RasterLayer::Height;
    // A long route's window is drawn in blocks, each read tile by tile.
    constexpr int kMaxSide_px = 4096;
    const multibin::CellWindow& w = m_impl->grid.window();
    const int k = multibin::blockFactorFor(w, kMaxSide_px);
    const multibin::EsriAsciiGrid g =
        k == 1 ? toRaster(layer, w)
               : multibin::blockReduced(multibin::tiledLayer(*this, layer), w, k,
                                        multibin::BlockReduce::Mean);
    const int rows = g.rows(), cols = g.cols();
    img.resize(std::max(cols, 1), std::max(rows, 1), mrpt::img::CH_RGB);
    img.filledRectangle(0, 0, std::max(cols, 1) - 1, std::max(rows, 1) - 1,
                        mrpt::img::TColor(0, 0, 0));
    float lo = std::numeric_limits<float>::infinity(), hi = -lo;
    for (int r = 0; r < rows; r++)
        for (int c = 0; c < cols; c++) {
            const float v = g.heights_m(r, c);
            if (std::isnan(v)) continue;
            lo = std::min(lo, v);
            hi = std::max(hi, v);
        }
    if (!(lo <= hi)) return;
    const float span = hi > lo ? hi - lo : 1.f;
    for (int r = 0; r < rows; r++)
        for (int c = 0; c < cols; c++) {
            const float v = g.heights_m(r, c);
            if (std::isnan(v)) continue;
            float R, G, B;
            mrpt::img::colormap(insertionOptions.render.colormap, (v - lo) / span, R, G, B);
            img.setPixel(c, rows - 1 - r,
                         mrpt::img::TColor(uint8_t(255 * R), uint8_t(255 * G), uint8_t(255 * B)));
        }
}

void CMultiBinElevationMap::saveMetricMapRepresentationToFile(
    const std::string& filNamePrefix) const {
    prepareForReading();
    const multibin::MapLock::Shared lock(m_impl->lock);
    // What elevation-mapper writes by default (doc/user-guide.md), read tile by tile: sparse
    // GeoTIFF layers, downsampled previews, the 3D view. ESRI ASCII and PLY are dense over the
    // known area: elevation-mapper --outputs asc,ply writes them for maps that fit.
    using L = RasterLayer;
    const multibin::TiledRaster height = multibin::tiledLayer(*this, L::Height);
    if (!height.tiles.empty()) {
        const std::vector<L> all{L::Height, L::Sigma, L::Certainty, L::Source};
        std::vector<std::string> paths;
        std::vector<multibin::GeoTiffOptions> options(all.size());
        for (size_t i = 0; i < all.size(); i++) {
            paths.push_back(filNamePrefix + "_" + multibin::mapLayerName(all[i]) + ".tif");
            options[i].description = multibin::layerPreviewStyle(all[i]).title;
        }
        multibin::writeSparseGeoTiffs(
            multibin::tiledLayers(*this, all, &height.tiles), paths, options,
            [&](size_t k, const std::function<bool(const std::string&)>& write) {
                multibin::writeFileAtomically(paths[k], write);
            });
        multibin::writeFileAtomically(filNamePrefix + "_height.tfw",
                                      multibin::geoTiffWorldFileText(height));
        const std::vector<L> shown{L::Height, L::Sigma, L::Source};
        const auto png =
            multibin::layerPreviewPngs(multibin::tiledLayers(*this, shown, &height.tiles), shown,
                                       multibin::knownWindow(height, 5));
        for (size_t i = 0; i < shown.size(); i++)
            multibin::writeFileAtomically(
                filNamePrefix + "_" + multibin::mapLayerName(shown[i]) + ".png", png[i]);
    }
    mrpt::opengl::COpenGLScene scene;
    auto obj = mrpt::opengl::CSetOfObjects::Create();
    getVisualizationInto(*obj);
    scene.insert(obj);
    multibin::frameTerrainScene(scene);
    if (!scene.saveToFile(filNamePrefix + ".3Dscene"))
        throw std::runtime_error("CMultiBinElevationMap: cannot write " + filNamePrefix +
                                 ".3Dscene");
}
