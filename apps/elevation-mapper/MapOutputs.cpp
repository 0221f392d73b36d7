/* Part of the multibin elevation-mapping library: the elevation-mapper program. */
#include "MapOutputs.h"

#include <cmath>
#include <limits>

#include <mrpt/io/CMemoryStream.h>
#include <mrpt/maps/COccupancyGridMap2D.h>
#include <mrpt/opengl/COpenGLScene.h>
#include <mrpt/opengl/CSetOfObjects.h>
#include <mrpt/serialization/CArchive.h>

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>

#include "ProgressBar.h"
#include "multibin/io/ErrorMessage.h"
#include "multibin/io/Gzip.h"
#include "multibin/io/MapLayerFiles.h"
#include "multibin/io/NumberText.h"
#include "multibin/io/OutputFile.h"
#include "multibin/io/RasterExport.h"
#include "multibin/io/RunDeflate.h"

namespace fs = std::filesystem;
using mrpt::maps::CMultiBinElevationMap;

namespace {

struct Group {
    const char* name;
    bool OutputSelection::*flag;
    const char* files;
};
const Group kGroups[] = {
    {"map", &OutputSelection::map, "elevation_map.bin (the serialized map, gz)"},
    {"tif", &OutputSelection::tif,
     "elevation_height.tif + .tfw (GeoTIFF: float32 heights [m], NaN unknown, tiled,\n"
     "        compressed, only the tiles with data; world file)"},
    {"tif-layers", &OutputSelection::tifLayers,
     "elevation_{sigma,certainty,source}.tif (the other layers as GeoTIFF)"},
    {"scene", &OutputSelection::scene, "elevation.3Dscene (3D view, opens in SceneViewer3D)"},
    {"png", &OutputSelection::png,
     "elevation_{height,sigma,source}.png (previews: axes [m], scale, legend;\n"
     "        downsampled beyond 1024 cells a side)"},
    {"asc", &OutputSelection::asc,
     "elevation_{height,sigma,certainty,source}.asc (ESRI ASCII; dense: up to 4096 x 4096\n"
     "        known cells)"},
    {"ply", &OutputSelection::ply, "elevation.ply (triangle mesh [m]; up to 4096 x 4096 cells)"},
    {"gridmap", &OutputSelection::gridmap,
     "elevation_traversability.gridmap.gz (MRPT occupancy grid: P(untraversable), unknown 0.5)"
     " and elevation_untraversable.png"},
};

using Layer = CMultiBinElevationMap::RasterLayer;
const Layer kLayers[] = {Layer::Height, Layer::Sigma, Layer::Certainty, Layer::Source};
/** The traversability layers `asc` writes (doc/traversability.md), in TraversabilityLayer order. */
const char* const kTraversabilityNames[] = {"untraversable", "step", "slope", "roughness",
                                            "foothold"};

/** The map's traversability layer over the same cells as `like` (a cropped map raster): NODATA
 * where `like` reaches beyond the layers' window (its margin around the known cells may). */
multibin::EsriAsciiGrid traversabilityLike(const CMultiBinElevationMap& map, int layer,
                                           const multibin::EsriAsciiGrid& like) {
    const multibin::EsriAsciiGrid t =
        map.traversabilityRaster(static_cast<CMultiBinElevationMap::TraversabilityLayer>(layer));
    const int col0 = int(std::lround((like.xllcenter_m - t.xllcenter_m) / t.cellsize_m));
    const int row0 = int(std::lround((like.yllcenter_m - t.yllcenter_m) / t.cellsize_m));
    multibin::EsriAsciiGrid out = like;
    out.heights_m.setConstant(std::numeric_limits<float>::quiet_NaN());
    for (int r = 0; r < like.rows(); r++)
        for (int c = 0; c < like.cols(); c++) {
            const int tr = r + row0, tc = c + col0;
            if (tr >= 0 && tc >= 0 && tr < t.rows() && tc < t.cols())
                out.heights_m(r, c) = t.heights_m(tr, tc);
        }
    return out;
}

}  // namespace

std::string OutputSelection::help() {
    std::string s;
    for (const Group& g : kGroups) s += std::string("      ") + g.name + ": " + g.files + "\n";
    return s;
}

OutputSelection OutputSelection::parse(const std::string& list) {
    OutputSelection sel;
    for (const Group& g : kGroups) sel.*g.flag = false;
    std::istringstream is(list);
    std::string item;
    bool any = false;
    while (std::getline(is, item, ',')) {
        if (item.empty()) continue;
        any = true;
        if (item == "all") {
            for (const Group& g : kGroups) sel.*g.flag = true;
            continue;
        }
        bool known = false;
        for (const Group& g : kGroups)
            if (item == g.name) sel.*g.flag = known = true;
        if (!known) {
            std::string names;
            for (const Group& g : kGroups) names += std::string(names.empty() ? "" : ", ") + g.name;
            throw std::invalid_argument("--outputs: unknown output '" + item +
                                        "' (known: " + names + ", all)");
        }
    }
    if (!any) throw std::invalid_argument("--outputs: the list is empty");
    return sel;
}

int OutputSelection::parseEpsg(const std::string& text) {
    if (text.empty()) return 0;
    double v = 0;
    if (!multibin::parseFiniteNumber(text, v) || v != std::floor(v) || std::abs(v) > 1e6)
        throw std::invalid_argument("--epsg: '" + text + "' is not an EPSG code");
    multibin::checkGeoTiffEpsg(int(v), "--epsg");
    return int(v);
}

std::vector<std::string> OutputSelection::fileNames() const {
    std::vector<std::string> f;
    if (map) f.push_back("elevation_map.bin");
    if (tif) f.insert(f.end(), {"elevation_height.tif", "elevation_height.tfw"});
    if (tifLayers)
        for (const char* l : {"sigma", "certainty", "source"})
            f.push_back(std::string("elevation_") + l + ".tif");
    if (scene) f.push_back("elevation.3Dscene");
    if (png)
        for (const char* l : {"height", "sigma", "source"})
            f.push_back(std::string("elevation_") + l + ".png");
    if (asc)
        for (const Layer l : kLayers)
            f.push_back(std::string("elevation_") + multibin::mapLayerName(l) + ".asc");
    if (asc)
        for (const char* l : kTraversabilityNames)
            f.push_back(std::string("elevation_") + l + ".asc");
    if (gridmap)
        f.insert(f.end(), {"elevation_traversability.gridmap.gz", "elevation_untraversable.png"});
    if (ply) f.push_back("elevation.ply");
    return f;
}

OutputFolder::OutputFolder(const fs::path& dir,
                           std::vector<std::pair<std::string, std::string>> inputs)
    : m_dir(dir), m_inputs(std::move(inputs)) {
    if (fs::exists(dir) && !fs::is_directory(dir))
        throw std::invalid_argument("--out '" + dir.string() + "' exists and is not a folder");
}

void OutputFolder::create() const {
    // Created at the first file, so a run that fails before writing leaves no empty folder.
    std::error_code ec;
    fs::create_directories(m_dir, ec);
    if (ec)
        throw std::runtime_error("cannot create the output folder '" + m_dir.string() +
                                 "': " + ec.message());
    // Another user could plant files or symlinks in a folder of theirs (or a shared one).
    struct stat st {};
    if (::stat(m_dir.c_str(), &st) != 0 || st.st_uid != ::geteuid())
        throw std::runtime_error("the output folder '" + m_dir.string() +
                                 "' does not belong to the user running elevation-mapper: choose "
                                 "a folder of your own with --out");
}

void OutputFolder::checkNotAnInput(const std::string& name) const {
    const bool prefix = !name.empty() && name.back() == '*';
    const std::string stem = prefix ? name.substr(0, name.size() - 1) : name;
    for (const auto& [what, input] : m_inputs) {
        if (input.empty()) continue;
        std::error_code ec;
        const fs::path in(input);
        bool clash = false;
        if (prefix) {
            const std::string base = in.filename().string();
            clash = base.compare(0, stem.size(), stem) == 0 &&
                    fs::equivalent(in.parent_path().empty() ? fs::path(".") : in.parent_path(),
                                   m_dir, ec);
        } else {
            clash = fs::equivalent(in, m_dir / name, ec);
        }
        if (clash)
            throw std::invalid_argument("the output '" + (m_dir / name).string() +
                                        "' would overwrite the input " + what + " '" + input +
                                        "': choose another --out folder or move the input");
    }
}

void OutputFolder::write(const std::string& name, const std::vector<uint8_t>& bytes) const {
    checkNotAnInput(name);
    create();
    multibin::writeFileAtomically((m_dir / name).string(), bytes);
}

void OutputFolder::write(const std::string& name, const std::string& text) const {
    checkNotAnInput(name);
    create();
    multibin::writeFileAtomically((m_dir / name).string(), text);
}

void OutputFolder::writeWith(const std::string& name,
                             const std::function<bool(const std::string&)>& writer) const {
    checkNotAnInput(name);
    create();
    multibin::writeFileAtomically((m_dir / name).string(), writer);
}

void OutputFolder::moveIn(const std::string& name, const std::string& file) const {
    checkNotAnInput(name);
    create();
    multibin::moveIntoPlace(file, (m_dir / name).string());
}

MapLayers MapLayers::of(const CMultiBinElevationMap& map, bool sparse) {
    MapLayers m;
    m.m_map = &map;
    if (sparse) {
        // Height, sigma and source read once (one query per known cell) for every output that
        // scales with the route; the certainty (a surface per cell more) only if one asks.
        const std::vector<multibin::TiledRaster> read =
            multibin::knownLayers(map, {Layer::Height, Layer::Sigma, Layer::Source});
        m.tiled[0] = read[0], m.tiled[1] = read[1], m.tiled[3] = read[2];
    } else {  // read when asked (the box below, the dense outputs)
        m.tiled[0] = multibin::tiledLayer(map, Layer::Height);
        m.tiled[1] = multibin::tiledLayer(map, Layer::Sigma, &m.tiled[0].tiles);
        m.tiled[3] = multibin::tiledLayer(map, Layer::Source, &m.tiled[0].tiles);
    }
    m.tiled[2] = multibin::tiledLayer(map, Layer::Certainty, &m.tiled[0].tiles);
    m.cells = multibin::knownWindow(m.tiled[0], kMargin_cells);
    return m;
}

void MapLayers::requireDense(const std::string& output) const {
    if (cells.nx == 0) throw std::invalid_argument(output + ": the map knows no cell");
    multibin::checkDenseOutputFits(cells, tiled[0].cellSize_m, output,
                                   "choose --outputs tif,tif-layers,png (GeoTIFF and previews "
                                   "read tile by tile, any size)");
}

const multibin::EsriAsciiGrid& MapLayers::dense(int i) const {
    if (!m_computed[i]) {
        requireDense(std::string("the ") + multibin::mapLayerName(kLayers[i]) + " raster");
        m_dense[i] = m_map->toRaster(kLayers[i], cells);
        m_computed[i] = true;
    }
    return m_dense[i];
}

void MapLayers::saveAsc(const OutputFolder& folder) const {
    requireDense("--outputs asc");
    for (int i = 0; i < 4; i++)
        folder.writeWith(std::string("elevation_") + multibin::mapLayerName(kLayers[i]) + ".asc",
                         [&](const std::string& path) {
                             dense(i).save(path);
                             return true;
                         });
}

SupersampledLayers SupersampledLayers::of(const CMultiBinElevationMap& map, const MapLayers& layers,
                                          double cell_m) {
    layers.requireDense("--export-resolution");
    SupersampledLayers out;
    const multibin::EsriAsciiGrid& box = layers.dense(0);
    // The same area as the map-resolution rasters: their cells' outer edges.
    const double x0 = box.xllcenter_m - 0.5 * box.cellsize_m;
    const double y0 = box.yllcenter_m - 0.5 * box.cellsize_m;
    const int cols = int(std::ceil(box.cols() * box.cellsize_m / cell_m - 1e-9));
    const int rows = int(std::ceil(box.rows() * box.cellsize_m / cell_m - 1e-9));
    // Each sample is a surface query and about 20 bytes in each of two text files: 2e7 samples
    // take seconds and 400 MB; more would take minutes and gigabytes.
    constexpr double kMaxSamples = 2e7;
    if (!(double(cols) * double(rows) <= kMaxSamples))
        throw std::invalid_argument("--export-resolution " + std::to_string(cell_m) +
                                    " m: " + std::to_string(cols) + " x " + std::to_string(rows) +
                                    " samples over the rasters' area, more than 2e7; choose a "
                                    "coarser resolution");
    for (multibin::EsriAsciiGrid* g : {&out.height, &out.sigma}) {
        g->heights_m.setConstant(rows, cols, NAN);
        g->xllcenter_m = x0 + 0.5 * cell_m;
        g->yllcenter_m = y0 + 0.5 * cell_m;
        g->cellsize_m = cell_m;
    }
    const bool filled = map.insertionOptions.query.dem_return_filled;
    for (int r = 0; r < rows; r++)
        for (int c = 0; c < cols; c++) {
            const double x = out.height.xllcenter_m + c * cell_m;
            const double y = out.height.yllcenter_m + r * cell_m;
            double h, s;
            if (map.heightAt(x, y, h, s) || map.cellElevation(x, y, h, s, filled) !=
                                                CMultiBinElevationMap::HeightSource::Unknown) {
                out.height.heights_m(r, c) = float(h);
                out.sigma.heights_m(r, c) = float(s);
            }
        }
    return out;
}

void SupersampledLayers::saveAsc(const OutputFolder& folder) const {
    const multibin::EsriAsciiGrid* grids[] = {&height, &sigma};
    for (int i = 0; i < 2; i++)
        folder.writeWith(kFiles[i], [&](const std::string& path) {
            grids[i]->save(path);
            return true;
        });
}

std::vector<std::string> writeMapOutputs(const CMultiBinElevationMap& map, const MapLayers& layers,
                                         const OutputSelection& sel, const OutputFolder& folder) {
    // The dense outputs refuse a long route's box before any file is written.
    if (sel.asc) layers.requireDense("--outputs asc");
    if (sel.ply) layers.requireDense("--outputs ply");
    if (sel.gridmap) layers.requireDense("--outputs gridmap");
    // Each step writes one or more files; the bar counts steps.
    std::vector<std::pair<std::string, std::function<void()>>> steps;
    if (sel.map)
        steps.emplace_back("elevation_map.bin", [&] {
            folder.write("elevation_map.bin", multibin::gzipSerialized(map));
        });
    if (sel.tif || sel.tifLayers)
        steps.emplace_back("elevation_*.tif", [&] {
            // Every GeoTIFF asked for in one loop over the tiles (one query per cell).
            std::vector<Layer> chosen;
            std::vector<std::string> names;
            std::vector<multibin::GeoTiffOptions> options;
            for (int i = 0; i < 4; i++)
                if (i == 0 ? sel.tif : sel.tifLayers) {
                    chosen.push_back(kLayers[i]);
                    names.push_back(std::string("elevation_") + multibin::mapLayerName(kLayers[i]) +
                                    ".tif");
                    options.emplace_back();
                    options.back().epsg = sel.epsg;
                    options.back().description = multibin::layerPreviewStyle(kLayers[i]).title;
                }
            std::vector<multibin::TiledRaster> rasters;
            for (const Layer l : chosen) rasters.push_back(layers.tiled[int(l)]);
            multibin::writeSparseGeoTiffs(
                rasters, names, options,
                [&](size_t k, const std::function<bool(const std::string&)>& write) {
                    folder.writeWith(names[k], write);
                });
            if (sel.tif)
                folder.write("elevation_height.tfw",
                             multibin::geoTiffWorldFileText(layers.tiled[0]));
        });
    if (sel.scene)
        steps.emplace_back("elevation.3Dscene", [&] {
            mrpt::opengl::COpenGLScene scene;
            auto obj = mrpt::opengl::CSetOfObjects::Create();
            multibin::buildTerrainView(
                layers.tiled[0], layers.tiled[int(multibin::layerShownBy(sel.sceneColouring))],
                map.mapOrigin(), sel.sceneColouring, *obj);
            scene.insert(obj);
            multibin::frameTerrainScene(scene);  // opens framed in SceneViewer3D
            // Serialized, then gzip-coded by its runs (RunDeflate.h): the meshes' masked
            // vertices and unknown texels are runs of one float or byte, which zlib scans
            // byte by byte (3.3 MB on Malaga); CFileGZInputStream reads it as any gzip file.
            mrpt::io::CMemoryStream mem;
            auto arch = mrpt::serialization::archiveFrom(mem);
            arch << scene;
            folder.write(
                "elevation.3Dscene",
                multibin::runDeflateGzip(static_cast<const uint8_t*>(mem.getRawBufferData()),
                                         size_t(mem.getTotalBytesCount()), sizeof(float)));
        });
    if (sel.png)
        steps.emplace_back("elevation_{height,sigma,source}.png", [&] {
            const std::vector<Layer> shown{Layer::Height, Layer::Sigma, Layer::Source};
            std::vector<multibin::TiledRaster> rasters;
            for (const Layer l : shown) rasters.push_back(layers.tiled[int(l)]);
            const auto png = multibin::layerPreviewPngs(rasters, shown, layers.cells);
            for (size_t i = 0; i < shown.size(); i++)
                folder.write(std::string("elevation_") + multibin::mapLayerName(shown[i]) + ".png",
                             png[i]);
        });
    if (sel.asc) steps.emplace_back("elevation_*.asc", [&] { layers.saveAsc(folder); });
    if (sel.asc)
        steps.emplace_back("traversability *.asc", [&] {
            for (int i = 0; i < 5; i++)
                folder.writeWith(std::string("elevation_") + kTraversabilityNames[i] + ".asc",
                                 [&](const std::string& path) {
                                     traversabilityLike(map, i, layers.dense(0)).save(path);
                                     return true;
                                 });
        });
    if (sel.gridmap)
        steps.emplace_back("elevation_traversability.gridmap.gz", [&] {
            mrpt::maps::COccupancyGridMap2D grid;
            map.getAsOccupancyGrid(grid);
            folder.write("elevation_traversability.gridmap.gz", multibin::gzipSerialized(grid));
            multibin::PreviewStyle u;
            u.title = "P(untraversable)";
            u.colormap = cv::COLORMAP_INFERNO;
            u.valueFormat = "%.2f";
            folder.write(
                "elevation_untraversable.png",
                multibin::encodePreviewPng(traversabilityLike(map, 0, layers.dense(0)), u));
        });
    if (sel.ply)
        steps.emplace_back("elevation.ply", [&] {
            folder.write("elevation.ply", multibin::meshPlyText(layers.dense(0)));
        });

    ProgressBar bar("writing");
    for (size_t i = 0; i < steps.size(); i++) {
        bar.update(double(i) / double(steps.size()), steps[i].first);
        steps[i].second();
    }
    bar.finish("done");
    return sel.fileNames();
}
