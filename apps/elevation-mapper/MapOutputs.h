/* Part of the multibin elevation-mapping library: the elevation-mapper program. */
#pragma once

#include <mrpt/maps/CMultiBinElevationMap.h>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "multibin/io/EsriAsciiGrid.h"
#include "multibin/io/TiledRaster.h"
#include "multibin/map/TerrainView.h"

/** What elevation-mapper writes (--outputs): a comma-separated list of groups. */
struct OutputSelection {
    bool map = true;  //!< elevation_map.bin: the serialized map (gz)
    /** elevation_height.tif + .tfw: float32 GeoTIFF of the heights [m], tiled, compressed,
     * only the tiles with data (doc/user-guide.md), with a world file */
    bool tif = true;
    /** elevation_{sigma,certainty,source}.tif: the other layers as the same GeoTIFF */
    bool tifLayers = false;
    bool scene = true;  //!< elevation.3Dscene: the 3D view (SceneViewer3D)
    bool png = true;    //!< elevation_{height,sigma,source}.png: previews with legends
    bool asc = false;   //!< elevation_{height,sigma,certainty,source}.asc: ESRI ASCII rasters
    bool ply = false;   //!< elevation.ply: triangle mesh [m]
    /** elevation_traversability.gridmap.gz: MRPT COccupancyGridMap2D, occupancy =
     * P(untraversable), unknown 0.5; and elevation_untraversable.png */
    bool gridmap = false;
    /** EPSG code of the projected CRS of the robot poses (--epsg), written into the GeoTIFFs;
     * 0: none. */
    int epsg = 0;
    /** What colours the scene (--scene-colour). */
    multibin::SceneColouring sceneColouring = multibin::SceneColouring::Height;

    static constexpr const char* kDefault = "map,tif,scene,png";
    /** One line per group for --help. */
    static std::string help();
    /** Parses "map,tif,asc" or "all"; throws std::invalid_argument naming an unknown group. */
    static OutputSelection parse(const std::string& list);
    /** Parses --epsg: empty for none, else a projected CRS's code (checkGeoTiffEpsg()). */
    static int parseEpsg(const std::string& text);
    /** The file names the selection writes. */
    std::vector<std::string> fileNames() const;
};

/** The run's output folder. Every file is checked against the run's inputs (an input is never
 * overwritten) and written whole through a temporary file created exclusively and a rename (a
 * full disk leaves no truncated file, a symlink planted in the folder is never followed); the
 * folder must belong to the user running the program. Every error names its file. */
class OutputFolder {
public:
    /** inputs: (what, path), e.g. ("--ground-truth", "gt.asc"). The folder is created when the
     * first file is written. */
    OutputFolder(const std::filesystem::path& dir,
                 std::vector<std::pair<std::string, std::string>> inputs);
    const std::filesystem::path& dir() const { return m_dir; }
    /** Throws std::invalid_argument if writing `name` (a file name, or a prefix ending in '*')
     * would overwrite one of the inputs. Called for every planned file before mapping starts. */
    void checkNotAnInput(const std::string& name) const;
    void write(const std::string& name, const std::vector<uint8_t>& bytes) const;
    void write(const std::string& name, const std::string& text) const;
    /** For writers that take a path: writer(temporaryPath) returns false or throws on failure. */
    void writeWith(const std::string& name,
                   const std::function<bool(const std::string& path)>& writer) const;
    /** Moves `file` (written by another program into a private folder) into place as `name`. */
    void moveIn(const std::string& name, const std::string& file) const;

private:
    void create() const;
    std::filesystem::path m_dir;
    std::vector<std::pair<std::string, std::string>> m_inputs;
};

/** The map's layers, read tile by tile (multibin::TiledRaster over the map's occupied tiles),
 * and the area of the previews and dense outputs: the bounding box of its known cells plus a
 * margin. The dense rasters over that box (ESRI ASCII, PLY, the figures) are computed on first
 * use, and only when the box holds at most multibin::kMaxDenseOutputCells cells: a long route's
 * box is mostly empty. */
struct MapLayers {
    multibin::TiledRaster tiled[4];  //!< height, sigma, certainty, source (RasterLayer order)
    multibin::CellWindow cells;      //!< known cells plus kMargin_cells; empty if none known
    static constexpr int kMargin_cells = 5;
    /** sparse: read height, sigma and source once and keep their known cells (knownLayers()),
     * for outputs that read them all (GeoTIFF, previews, scene); else read when asked. */
    static MapLayers of(const mrpt::maps::CMultiBinElevationMap& map, bool sparse = true);
    /** Throws std::invalid_argument naming `output` unless the box fits a dense raster. */
    void requireDense(const std::string& output) const;
    /** Layer i (RasterLayer order) over `cells`, NaN where unknown; requireDense() first. */
    const multibin::EsriAsciiGrid& dense(int i) const;
    /** Writes elevation_{height,sigma,certainty,source}.asc into `dir` (any folder). */
    void saveAsc(const OutputFolder& folder) const;

private:
    const mrpt::maps::CMultiBinElevationMap* m_map = nullptr;
    mutable multibin::EsriAsciiGrid m_dense[4];
    mutable bool m_computed[4] = {false, false, false, false};
};

/** The sub-cell surface (heightAt) sampled every `cell_m` over the box of `layers` (--export-
 * resolution): elevation_{height,sigma}_supersampled.asc. Where a cell has no measurement the
 * sample takes the cell's filled value (as the rasters at the map's resolution). */
struct SupersampledLayers {
    multibin::EsriAsciiGrid height, sigma;
    static constexpr const char* kFiles[2] = {"elevation_height_supersampled.asc",
                                              "elevation_sigma_supersampled.asc"};
    static SupersampledLayers of(const mrpt::maps::CMultiBinElevationMap& map,
                                 const MapLayers& layers, double cell_m);
    void saveAsc(const OutputFolder& folder) const;
};

/** Writes the selected outputs of `map` (filled already) into the folder, with a progress bar on
 * a terminal. Returns the names of the files written. */
std::vector<std::string> writeMapOutputs(const mrpt::maps::CMultiBinElevationMap& map,
                                         const MapLayers& layers, const OutputSelection& selection,
                                         const OutputFolder& folder);
