/* Part of the multibin elevation-mapping library. */
#pragma once

#include <mrpt/config/CLoadableOptions.h>
#include <mrpt/img/CImage.h>
#include <mrpt/img/color_maps.h>
#include <mrpt/maps/CHeightGridMap2D_Base.h>
#include <mrpt/maps/CMetricMap.h>
#include <mrpt/maps/CSimpleMap.h>
#include <mrpt/obs/obs_frwds.h>
#include <mrpt/poses/CPose3DPDFGaussian.h>
#include <mrpt/serialization/CSerializable.h>

#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "multibin/fill/FillOptions.h"
#include "multibin/fill/HeightSource.h"
#include "multibin/geometry/PointsWithCovariance.h"
#include "multibin/grid/InsertStats.h"
#include "multibin/grid/VisibilityParams.h"
#include "multibin/sensors/SensorModelOptions.h"
#include "multibin/traversability/TraversabilityOptions.h"

// The library's internals stay out of this header: these are only named here. Include
// multibin/io/EsriAsciiGrid.h to use toRaster(), multibin/fill/SparseFill.h for fillInput() and
// lastFilledCells(), multibin/map/MapStatistics.h for statistics(); tests and tools reach the
// grids and the fill's raster through multibin/map/MapInternals.h.
namespace multibin {
class BinGrid;
struct BinUpdateParams;
struct MapInternals;
struct CellWindow;
struct MapStatistics;
class PosePropagator;
struct PoseVariances;
struct EsriAsciiGrid;
namespace fill {
struct FillResult;
struct FilledCells;
struct SparseHeights;
}  // namespace fill
namespace sensors {
struct SensorModelStats;
}
namespace traversability {
struct TraversabilityLayers;
}
}  // namespace multibin
namespace mrpt::maps {
class COccupancyGridMap2D;
class CSimplePointsMap;
}  // namespace mrpt::maps

namespace mrpt::maps {

/** Multi-bin terrain elevation map (Belter, Labecki, Skrzypczynski, ROBIO 2012).
 *
 * A 2.5D grid whose cells hold vertical bins (default 50 mm). Each bin keeps a certainty counter
 * and a Kalman height with its variance; the cell's elevation is its most certain bin. Every
 * sensor path ends in one insertion core fed with map-frame points that carry full 3x3
 * covariances, propagated from the sensor model and the robot's 6-DoF pose PDF:
 * C = J_R C_R J_R^T + J_S C_S J_S^T.
 *
 * Observations accepted by insertObservation() (the sensor model of each: its class's, or per
 * sensor label with the key `sensor_models`):
 * - mrpt::obs::CObservation2DRangeScan (laser; eq 14 continuity gate between consecutive scans;
 *   or the lidar model),
 * - mrpt::obs::CObservationStereoImages (stereo, eqs 4-10; OpenCV SGBM without a disparity),
 * - mrpt::obs::CObservation3DRangeScan (depth camera: its points, or its depth image unprojected),
 * - mrpt::obs::CObservationPointCloud (depth camera by default; lidar or stereo by label),
 * - mrpt::obs::CObservationVelodyneScan (lidar, MRPT's calibrated point generation),
 * - mrpt::obs::CObservationRotatingScan (lidar; single-row scans only),
 * - mrpt::obs::CObservationRobotPose: not inserted; the map keeps it and uses its covariance for
 *   the observations that follow while it is younger than TInsertionOptions::robot_pose_max_dt_s.
 *
 * Pose uncertainty: insertObservation(obs, CPose3DPDFGaussian) uses the given PDF; a plain
 * insertObservation(obs, pose) uses the latest CObservationRobotPose's covariance, or else
 * TInsertionOptions::default_pose_sigmas (and counts a warning, see statistics().poseFallbacks).
 *
 * Extent: by default one grid that grows to cover the data it receives (every point within
 * TInsertionOptions::max_range_m of its sensor that passes the eq 13 gate), with no size limit:
 * cells are stored in tiles of 64 x 64 allocated when first written, so memory follows the
 * ground seen, not the window. With `grow = false` the extent is fixed by min_x .. max_y and
 * points outside it are counted and dropped.
 *
 * Coordinates: every x, y the map takes or returns is in the frame of the robot poses, which may
 * be georeferenced (UTM: |x|, |y| up to 1e7 m). Inside, the map keeps them relative to an origin
 * held in double (mapOrigin(), TCreationOptions::origin_auto), so its single-precision geometry
 * stays exact within 2 km of it (doc/frames.md).
 *
 * In a CMultiMetricMap ini file:
 * \code
 * [map]
 * multiBinElevationMap_count = 1
 * [map_multiBinElevationMap_00_creationOpts]
 * resolution_m = 0.02      ; all keys optional (doc/options.md)
 * [map_multiBinElevationMap_00_insertOpts]
 * max_elevation_uncertainty_m = 0.1
 * \endcode
 * Unknown keys and malformed values are errors that name the section and the key.
 *
 * Threads: one writer and any number of concurrent readers may share a map. Every public entry
 * point takes a reader-writer lock (insertions, recenter(), dem_update_map() and clear() write;
 * queries, rasters, images and the 3D view read). The accessors that return references into the
 * map (lastFilledCells(), MapInternals) and the public option structs are not covered: use
 * them from the writer thread or while no one writes. See doc/reliability.md.
 *
 * Observation likelihood is not implemented: canComputeObservationLikelihood() returns false.
 */
class CMultiBinElevationMap : public CMetricMap, public CHeightGridMap2D_Base {
    DEFINE_SERIALIZABLE(CMultiBinElevationMap, mrpt::maps)

public:
    /** Grid geometry, fixed at creation (ini section `..._creationOpts`). */
    struct TCreationOptions : public mrpt::config::CLoadableOptions {
        double resolution_m = 0.02;  //!< cell size [m] (key `resolution`)
        double bin_height_m = 0.05;  //!< vertical bin size [m] (key `bin_height`)
        bool grow = true;            //!< grow to cover the data (key `grow`)
        /** Initial extent [m] (keys `min_x`, `max_x`, `min_y`, `max_y`); the fixed extent when
         * grow = false. An empty range starts with no cells. */
        double min_x = 0, max_x = 0, min_y = 0, max_y = 0;

        /** Dual grid (key `dual_grid`): a precise local grid and a large global grid, both
         * centred on the robot: the local one moves with it, the global one grows along the
         * route (it keeps everything seen). When on, the keys below replace `resolution`,
         * `grow` and the extent. */
        bool dual_grid = false;
        double local_size_m = 2.0;          //!< side of the local grid [m] (key `local_size_m`)
        double local_resolution_m = 0.015;  //!< local cell size [m] (key `local_resolution`)
        /** Side of the square around the robot the global grid covers at least [m] (key
         * `global_size_m`): the grid grows to the union of these squares along the route. */
        double global_size_m = 10.0;
        double global_resolution_m = 0.05;  //!< global cell size [m] (key `global_resolution`)

        /** The map origin (keys `origin_auto`, `origin_x_m`, `origin_y_m`): the point of the pose
         * frame, held in double, that cells, bins and the single-precision geometry are relative
         * to (doc/frames.md). With origin_auto, originNear() of the extent's centre when an extent
         * is given, else of the first pose (or point) inserted; otherwise (origin_x_m, origin_y_m)
         * [m] as given. Every coordinate that enters or leaves the map is in the pose frame. */
        bool origin_auto = true;
        double origin_x_m = 0, origin_y_m = 0;
        /** Memory budget of the grid's tiles and bins [MB] (key `memory_budget_mb`; 0: none).
         * Beyond it, after an insertion, the tiles farthest from the sensor and beyond
         * `max_range_m` of it are written to a scratch file in `tile_store_dir` and freed; one
         * comes back when an insertion reaches it, and all come back before the map is read
         * (queries, filling, outputs, saving). The same bins as without a budget
         * (doc/route-scale.md). */
        double memory_budget_mb = 0;
        /** Directory of that scratch file (key `tile_store_dir`; empty: $TMPDIR, else /tmp). It
         * has no name there: no other process can open it, and it goes with the process. */
        std::string tile_store_dir;
        /** The automatic origin for data at (x, y) [m]: the nearest whole kilometre, rounded to
         * whole cells of the (global) grid so the cells stay on multiples of the cell size. */
        mrpt::math::TPoint2D originNear(double x_m, double y_m) const;
        /** The origin these options fix before any data arrive: the explicit one, or
         * originNear() of a single grid's extent centre; none when it waits for the first
         * insertion. */
        std::optional<mrpt::math::TPoint2D> originBeforeData() const;

        void loadFromConfigFile(const mrpt::config::CConfigFileBase& source,
                                const std::string& section) override;
        void saveToConfigFile(mrpt::config::CConfigFileBase& target,
                              const std::string& section) const override;
        /** Throws std::invalid_argument if a value is out of range or the map would be too big. */
        void validate() const;
    } creationOptions;

    /** How observations update the map (ini section `..._insertOpts`). */
    struct TInsertionOptions : public mrpt::config::CLoadableOptions {
        float certainty_increment = 1.0f;  //!< `a` of eqs 13-14
        double max_elevation_uncertainty_m =
            0.1;                              //!< Delta_max [m]: a point counts if 3 sigma_z <= it
        double height_sigma_floor_m = 0.002;  //!< a bin's sigma never falls below this [m]
        /** Pose sigmas (x, y, z [m], yaw, pitch, roll [rad]) used when no pose PDF is known. */
        std::vector<double> default_pose_sigmas{0.01, 0.01, 0.01, 0.005, 0.005, 0.005};
        double robot_pose_max_dt_s = 0.5;  //!< a CObservationRobotPose stays valid this long [s]
        double range_sigma_m = 0.01;       //!< default height sigma of insertIndividualPoint [m]
        double min_range_m = 0.02, max_range_m = 20.0;  //!< accepted ranges [m]
        /** Only observations with these sensor labels are inserted; empty = all. */
        std::vector<std::string> sensor_labels;
        /** Dual grid only: observations with these labels (and every CObservationStereoImages)
         * update the global grid; all others update the local grid. */
        std::vector<std::string> global_sensor_labels{"STEREO"};
        /** Visibility constraint after each observation (keys `visibility_constraint`,
         * `visibility_margin`, `visibility_certainty_decrement`, `visibility_certainty_share`). */
        multibin::VisibilityParams visibility;
        /** Sensor models: laser, stereo, depth camera (keys `laser_*`, `stereo_*`, `depth_*`). */
        multibin::sensors::SensorModelOptions sensors;
        /** Gap filling (keys `fill_*`, see multibin::fill::FillOptions); it runs lazily in
         * dem_update_map(). */
        multibin::fill::FillOptions fill;
        /** What the height queries answer (keys `dem_return_filled`, `relief_sigma`,
         * `height_query`, in this section). */
        struct TQueryOptions {
            /** DEM queries (dem_get_z, dem_get_z_by_cell) and rasters also return filled heights
             * (key `dem_return_filled`). MRPT documents dem_get_z as false for unobserved cells;
             * set false for that behaviour. */
            bool dem_return_filled = true;
            /** The reported sigma of a cell includes its relief (key `relief_sigma`): (g s)^2 / 12
             * with g the local slope from the neighbours and s the cell size (the cell's one height
             * stands for a sloped patch), plus the certainty-weighted spread of the cell's other
             * certain bins around the reported height (a cell holding a step holds surfaces at
             * several heights). Off: the bins' Kalman sigma alone (the paper's). */
            bool relief_sigma = true;
            /** What getHeight(), dem_get_z() (and so intersectLine3D()) answer at a point (key
             * `height_query`): `plane` (default) the sub-cell surface of heightAt(); `nearest` the
             * value of the cell containing the point (cellHeight(), the answer before the sub-cell
             * surface). Rasters and gap filling always use the cell values. */
            enum class HeightQuery { Plane, Nearest } height_query = HeightQuery::Plane;
        } query;
        /** How the map is drawn (keys `colormap`, `color_by_sigma`, in this section). */
        struct TRenderOptions {
            mrpt::img::TColormap colormap = mrpt::img::cmJET;  //!< getAsImage() only
            bool color_by_sigma = false;  //!< 3D view coloured by sigma instead of height
        } render;
        /** Threads of the insertion (key `insertion_threads`, 1 or 2): with 2, a large
         * observation (a lidar revolution, a stereo or depth frame: 4 096 points or more) is
         * propagated and classified on a helper thread while the calling thread updates the
         * bins, and the helper computes half of a stereo pair's rows; the map is the same bit
         * for bit. 1: everything on the calling thread. */
        int insertion_threads = 1;

        void loadFromConfigFile(const mrpt::config::CConfigFileBase& source,
                                const std::string& section) override;
        void saveToConfigFile(mrpt::config::CConfigFileBase& target,
                              const std::string& section) const override;
        void validate() const;
        /** The default pose covariance built from default_pose_sigmas. */
        mrpt::math::CMatrixDouble66 defaultPoseCovariance() const;
    } insertionOptions;

    CMultiBinElevationMap();
    explicit CMultiBinElevationMap(const TCreationOptions& creation);
    CMultiBinElevationMap(const CMultiBinElevationMap& other);
    CMultiBinElevationMap& operator=(const CMultiBinElevationMap& other);
    ~CMultiBinElevationMap() override;

    /** Rebuilds an empty grid with new creation options. */
    void setCreationOptions(const TCreationOptions& creation);

    using CMetricMap::insertObservation;
    /** Inserts an observation taken at a robot pose known with uncertainty. Publishes MRPT's
     * insertion event like the base insertObservation(). */
    bool insertObservation(const mrpt::obs::CObservation& obs,
                           const mrpt::poses::CPose3DPDFGaussian& robotPose);

    /** Inserts every observation of a simplemap with its keyframe's own pose PDF (mean and 6x6
     * covariance from getCovarianceAndMean()). MRPT's stock loadFromSimpleMap() passes only the
     * mean pose. Returns the number of observations inserted. Does not clear the map.
     * `progress(keyframesDone, keyframesTotal)` is called after each keyframe, if given. */
    size_t insertSimpleMapWithPosePdfs(const mrpt::maps::CSimpleMap& simplemap,
                                       const std::function<void(size_t, size_t)>& progress = {});
    /** Calls visit(obs, pdf) for every observation of a simplemap with its keyframe's pose PDF
     * (mean and 6x6 covariance from getCovarianceAndMean()), and progress(done, total) after each
     * keyframe, if given. */
    static void forEachObservationWithPosePdf(
        const mrpt::maps::CSimpleMap& simplemap,
        const std::function<void(const mrpt::obs::CObservation&,
                                 const mrpt::poses::CPose3DPDFGaussian&)>& visit,
        const std::function<void(size_t, size_t)>& progress = {});

    /** Inserts points already in the map frame with their covariance (the shared insertion core,
     * for sensors the map does not model): one update cycle. The points and the sensor origin are
     * relative to mapOrigin() (single precision; the first call fixes an automatic origin where
     * it is). `continuityBound_m` is eq 14's Delta_zmax. With a sensor origin the visibility
     * constraint follows. The grid does not grow here (see insertObservation). `pose`: the
     * pose's part of each point's variances (PosePropagator::apply's), which the reported sigma
     * keeps (CellSurface.h); without it none is known. */
    multibin::InsertStats insertPoints(
        const multibin::PointsWithCov& mapPoints,
        double continuityBound_m = std::numeric_limits<double>::infinity(),
        const std::optional<Eigen::Vector3d>& sensorOrigin_m = std::nullopt,
        const multibin::PoseVariances* pose = nullptr);
    /** Grows the window as an observation's insertion does (TCreationOptions::grow) to cover
     * those of `mapPoints` within TInsertionOptions::max_range_m of `sensor_m` that pass the
     * eq 13 gate; both relative to mapOrigin(). For callers of insertPoints(), which does not
     * grow (the Python module's insert_points). */
    void growToCoverPoints(const multibin::PointsWithCov& mapPoints,
                           const Eigen::Vector3d& sensor_m);

    /** @name Queries @{ */
    /** Where a height comes from: Unknown (0), Measured (1), FilledMedian (2), FilledSurface (3),
     * FilledHarmonic (4); the number is the `source` raster layer's value. */
    using HeightSource = multibin::HeightSource;
    /** The answer of height(): NaN and HeightSource::Unknown where nothing is known. */
    struct HeightAnswer {
        double height_m = std::numeric_limits<double>::quiet_NaN();  //!< [m]
        double sigma_m = std::numeric_limits<double>::quiet_NaN();   //!< one sigma [m]
        HeightSource source = HeightSource::Unknown;
        bool known() const { return source != HeightSource::Unknown; }
    };
    /** The recommended query: the terrain's height at (x, y) [m, pose frame] with its sigma and
     * where it comes from. Measured places answer the map's surface (`height_query`: the
     * sub-cell plane by default, heightAt()); unobserved ones the gap filling's height when
     * `dem_return_filled` (the last dem_update_map(); a map read from a file fills on its first
     * query). dem_get_z() and getHeight() answer through it; the other queries are variants
     * (doc/user-guide.md, "Height queries"). */
    HeightAnswer height(double x_m, double y_m) const;
    /** height() at n points: out[i] is height(x_m[i], y_m[i]) bit for bit, under one read lock;
     * the work of a cell is done once for the points near it (points sorted or on a grid share
     * most; the answers keep the points' order). */
    void heights(const double* x_m, const double* y_m, size_t n, HeightAnswer* out) const;

    /** The memory budget's work so far (TCreationOptions::memory_budget_mb). */
    struct TileStoreStats {
        size_t tilesWritten = 0;       //!< tiles written to the scratch file
        size_t tilesRead = 0;          //!< tiles read back
        size_t tilesOnDisk = 0;        //!< tiles there now
        size_t peakResidentBytes = 0;  //!< the most the grid's tiles and bins took [bytes]
    };
    TileStoreStats tileStoreStats() const;
    multibin::BinUpdateParams binUpdateParams() const;
    /** Variant of height(): height [m] and sigma [m] at (x, y): measured (the cell surface, as
     * getHeight()) or, with includeFilled, the result of the last gap filling (dem_update_map())
     * for a cell that is still unobserved. Filled cells keep certainty 0. */
    HeightSource getElevation(double x_m, double y_m, double& height_m, double& sigma_m,
                              bool includeFilled = true) const;
    /** The same with the cell's value (cellHeight()) where measured: one value per cell, what
     * the rasters export. */
    HeightSource cellElevation(double x_m, double y_m, double& height_m, double& sigma_m,
                               bool includeFilled = true) const;
    /** The last gap filling's filled cells, tile by tile (absolute cell indices of grid()). */
    const multibin::fill::FilledCells& lastFilledCells() const;
    /** The input of gap filling: each measured cell's surface (without the pose part the cells
     * share), tile by tile, over grid()'s window. dem_update_map() fills its gaps. */
    multibin::fill::SparseHeights fillInput() const;

    /** height() where measured: height [m] and sigma [m] at (x, y) from the map's surface (the
     * cell surface: its winning bin merged with the adjacent bins that agree with it,
     * multibin/grid/CellSurface.h, at the point as `height_query` says); false if unobserved. With
     * the dual grid, where both grids know the place and agree within 3 sigma, their independent
     * estimates are fused (no datum is in both grids); otherwise the more certain one is given. */
    bool getHeight(double x_m, double y_m, double& height_m, double& sigma_m) const;
    /** Height [m] and sigma [m] of the sub-cell surface at (x, y): the plane of the cell's
     * surface evaluated at the point, its gradient from the cell's points and those of the
     * neighbouring cells on the same surface, blended with the planes of the cells around the
     * point where they agree (never across a step); sigma grows towards the
     * cell's edges with the gradient's uncertainty (multibin::heightAt in CellSurface.h,
     * doc/sub-cell-surface.md). False if unobserved. */
    bool heightAt(double x_m, double y_m, double& height_m, double& sigma_m) const;
    /** Height [m] and sigma [m] of the cell containing (x, y): the cell surface (CellSurface.h),
     * one value per cell, what rasters and gap filling use. False if unobserved. */
    bool cellHeight(double x_m, double y_m, double& height_m, double& sigma_m) const;

    /** The map origin [m] in the frame of the robot poses (TCreationOptions::origin_auto): fixed
     * at construction, by the first insertion or by recenter(); (0, 0) until then. */
    mrpt::math::TPoint2D mapOrigin() const;

    /** @name Dual grid @{ */
    bool isDualGrid() const { return creationOptions.dual_grid; }
    /** Centres both grids on (x, y) [m]: cells still inside are untouched; local cells that
     * leave are written back into the global grid. Called before each insertion. */
    void recenter(double x_m, double y_m);
    /** Writes every local cell back into the global grid and empties the local grid, so the
     * global grid holds the whole run (for evaluation and export). */
    void flushLocalToGlobal();
    /** @} */
    /** Layers of toRaster(). */
    enum class RasterLayer {
        Height,     //!< [m]
        Sigma,      //!< [m]
        Certainty,  //!< certainty c of the cell surface's bins [-]; 0 for filled cells
        Source      //!< HeightSource as a number: 1 measured, 2 median-filled, 3 surface-filled
    };
    /** One layer over the grid window as a raster, NaN where unknown; row 0 is the southernmost
     * row. Filled cells are included when insertionOptions.query.dem_return_filled is set. */
    multibin::EsriAsciiGrid toRaster(RasterLayer layer = RasterLayer::Height) const;
    /** The layer over any window of cells (cell indices of grid(): multibin/geometry/Lattice.h),
     * NaN where unknown: a large map's outputs read it tile by tile (occupiedTiles()). */
    multibin::EsriAsciiGrid toRaster(RasterLayer layer, const multibin::CellWindow& cells) const;
    /** Several layers over a window, one query per cell: toRaster(layers[i], cells) each. */
    std::vector<multibin::EsriAsciiGrid> toRasters(const std::vector<RasterLayer>& layers,
                                                   const multibin::CellWindow& cells) const;
    /** What toRasters() writes at its known cells, without a raster: visit(ix, iy, values) for
     * each known cell of the window (values[i] of layers[i]), tile by tile of the store, each
     * tile's cells row by row. A sparse map's outputs read it: the unknown cells cost nothing. */
    void forEachKnownCell(
        const std::vector<RasterLayer>& layers, const multibin::CellWindow& cells,
        const std::function<void(int ix, int iy, const float* values)>& visit) const;
    /** The aligned windows of tileCells x tileCells cells of grid() (multibin::tileOfCell,
     * multibin/io/TiledRaster.h) that may hold a known cell (a bin of either grid, or a filled
     * cell), row by row from the south: where the data is, whatever the window's extent. */
    std::vector<multibin::CellWindow> occupiedTiles(int tileCells = 256) const;
    /** Colour image of the heights (or sigmas) with insertionOptions.render.colormap, north up;
     * black where unknown. One pixel per cell of the window; a window longer than 4096 cells is
     * drawn one pixel per k x k block of cells (their mean), k the smallest that fits 4096. */
    void getAsImage(mrpt::img::CImage& img, bool sigma = false) const;
    /** @name Traversability (multibin/traversability/TerrainFeatures.h, doc/traversability.md)
     * @{ */
    /** The robot's limits and how the layers are computed (ini section `..._traversabilityOpts`).
     */
    multibin::traversability::TraversabilityOptions traversabilityOptions;
    /** Step, slope, roughness with their sigmas, P(untraversable) and the foothold probability of
     * every cell of the grid window (NaN where unknown), from the sub-cell surface, the bins and
     * the last gap filling (dem_update_map()). Recomputed only where the map changed since the
     * last call (all of it after a change of traversabilityOptions or of the window). */
    multibin::traversability::TraversabilityLayers traversabilityLayers() const;
    /** Brings the layers up to date (as traversabilityLayers()) without copying them: for a
     * live loop that reads them through the queries below. */
    void updateTraversability() const;
    /** Layers of traversabilityRaster(). */
    enum class TraversabilityLayer {
        Untraversable,  //!< P(untraversable) [-]
        Step,           //!< [m]
        Slope,          //!< [deg]
        Roughness,      //!< [m]
        Foothold        //!< P(good foothold) [-]
    };
    /** One traversability layer as a raster in the pose frame, NaN where unknown. */
    multibin::EsriAsciiGrid traversabilityRaster(TraversabilityLayer layer) const;
    /** An MRPT occupancy grid on the map's lattice (pose frame) whose occupancy is
     * P(untraversable), 0.5 where unknown: what mrpt::nav::PlannerSimple2D plans on. */
    void getAsOccupancyGrid(mrpt::maps::COccupancyGridMap2D& grid) const;
    /** Fills `points` with the centres (x, y, height) [m] of the cells whose P(untraversable) is
     * at least minProbability: the obstacles of MRPT's point-based planners. */
    void getUntraversablePoints(mrpt::maps::CSimplePointsMap& points,
                                double minProbability = 0.5) const;
    /** A foothold: the centre of a cell, its height and the probability it is good. */
    struct TFoothold {
        bool found = false;
        double x_m = 0, y_m = 0, z_m = 0;
        double probability = 0;
    };
    /** The known cell within searchRadius_m of (x, y) with the highest foothold probability (the
     * nearest of equals). */
    TFoothold bestFoothold(double x_m, double y_m, double searchRadius_m) const;
    /** @} */
    /** Everything the map counted since the last clear() (insertions, visibility constraint,
     * sensor models, observations skipped or refused), copied under the map's lock: safe to call
     * while another thread inserts. Include multibin/map/MapStatistics.h to call it. */
    multibin::MapStatistics statistics() const;
    /** True if observations with this sensor label are inserted (insertionOptions.sensor_labels
     * is empty or lists it). */
    bool acceptsLabel(const std::string& label) const;
    /** @} */

    /** @name CMetricMap @{ */
    bool isEmpty() const override;
    std::string asString() const override;
    void getVisualizationInto(mrpt::opengl::CSetOfObjects& outObj) const override;
    /** Writes what elevation-mapper writes by default, read tile by tile so the files grow
     * with the data, not its bounding box: PREFIX_height.tif, PREFIX_sigma.tif,
     * PREFIX_certainty.tif and PREFIX_source.tif (float32 GeoTIFF: tiled, compressed, only the
     * tiles with data, NaN unknown; see RasterLayer) with PREFIX_height.tfw (world file);
     * previews PREFIX_height.png, PREFIX_sigma.png, PREFIX_source.png (axes [m], legend;
     * downsampled beyond 2048 cells a side); PREFIX.3Dscene. No raster for an empty map. */
    void saveMetricMapRepresentationToFile(const std::string& filNamePrefix) const override;
    float compute3DMatchingRatio(const mrpt::maps::CMetricMap* otherMap,
                                 const mrpt::poses::CPose3D& otherMapPose,
                                 const TMatchingRatioParams& params) const override;
    /** @} */

    /** @name CHeightGridMap2D_Base (DEM interface). Cell (cx, cy) counts from the window's
     * lower-left corner. @{ */
    bool insertIndividualPoint(const double x, const double y, const double z,
                               const TPointInsertParams& params = TPointInsertParams()) override;
    double dem_get_resolution() const override;
    size_t dem_get_size_x() const override;
    size_t dem_get_size_y() const override;
    bool dem_get_z_by_cell(const size_t cx, const size_t cy, double& z_out) const override;
    bool dem_get_z(const double x, const double y, double& z_out) const override;
    /** Runs gap filling if observations arrived since the last one (lazy: never per point). A
     * map read from a file needs no call: it fills on its first query. */
    void dem_update_map() override;
    /** @} */

    /** Window extent [m]. */
    double getXMin() const;
    double getXMax() const;
    double getYMin() const;
    double getYMax() const;

    MAP_DEFINITION_START(CMultiBinElevationMap)
    TCreationOptions creationOpts;
    TInsertionOptions insertionOpts;
    multibin::traversability::TraversabilityOptions traversabilityOpts;
    MAP_DEFINITION_END(CMultiBinElevationMap)

private:
    friend struct multibin::MapInternals;  // grid(), localGrid(), lastFill(): tests and tools

    /** The grid (the global one with the dual grid), the precise local grid (empty unless dual
     * grid), the last gap filling's result over the window it ran on as one raster, built on its
     * first call (empty, stats only, beyond kMaxWholeWindowCells; lastFilledCells() holds it at
     * any size), and whether observations arrived after it. */
    const multibin::BinGrid& grid() const;
    const multibin::BinGrid& localGrid() const;
    const multibin::fill::FillResult& lastFill() const;
    bool fillIsStale() const;

    void internal_clear() override;
    bool internal_insertObservation(
        const mrpt::obs::CObservation& obs,
        const std::optional<const mrpt::poses::CPose3D>& robotPose = std::nullopt) override;
    double internal_computeObservationLikelihood(
        const mrpt::obs::CObservation& obs, const mrpt::poses::CPose3D& takenFrom) const override;
    bool internal_canComputeObservationLikelihood(
        const mrpt::obs::CObservation& obs) const override;

    /** heightAt() (subCell) or cellHeight(): the map's surface at (x, y) in the pose frame;
     * sigma without the pose part the points share if not `sharedPosePart` (the gap filling's
     * input). */
    bool surfaceQuery(bool subCell, double x_m, double y_m, double& height_m, double& sigma_m,
                      bool sharedPosePart = true) const;
    /** surfaceQuery() where measured; else, with includeFilled, the last gap filling's height
     * where it filled the cell of (x, y). */
    HeightSource elevationQuery(bool subCell, double x_m, double y_m, double& height_m,
                                double& sigma_m, bool includeFilled) const;
    /** The last gap filling's height where it filled the cell of (x, y), else Unknown (the
     * caller holds the lock): elevationQuery() where unmeasured. */
    HeightSource filledQuery(double x_m, double y_m, double& height_m, double& sigma_m) const;
    /** Gap filling of the whole window into the last fill (the caller holds the lock for
     * writing): dem_update_map()'s work. */
    void fillNow() const;
    /** A map read from a file (bins, no insertion since) fills its gaps once, before its first
     * query that may answer a filled height: it answers as the map that wrote it did. Called
     * first by those queries; a no-op inside another entry point. */
    void fillIfLoaded() const;
    /** Before a read: the tiles a memory budget put on disk back in memory, then
     * fillIfLoaded(). Called first by every entry point that reads cells; a no-op inside
     * another entry point. */
    void prepareForReading() const;
    /** After an insertion seen from sensor_m [m, grid frame]: within memory_budget_mb, by
     * writing far tiles to disk. */
    void keepWithinMemoryBudget(const Eigen::Vector3d& sensor_m);
    /** Before an insertion into `grid` from sensor_m [m, grid frame]: the tiles on disk it may
     * reach back in memory. */
    void reloadTilesInReach(multibin::BinGrid& grid, const Eigen::Vector3d& sensor_m);
    /** Observation -> sensor-frame points -> map frame -> grid. */
    bool insertWithPosePdf(const mrpt::obs::CObservation& obs,
                           const mrpt::poses::CPose3DPDFGaussian& robotPose);
    /** Grows the window (if allowed) to cover map-frame points near the sensor that pass the
     * eq 13 gate of `params`. */
    void growToCover(const multibin::PointsWithCov& mapPoints, const Eigen::Vector3d& sensor_m,
                     const multibin::BinUpdateParams& params);

    /** Largest window the traversability layers and lastFill() compute over as one raster
     * [cells] (8192 x 8192): beyond it (a long route's box), the layers refuse and lastFill()
     * holds statistics only, instead of allocating GBs (gap filling itself is tiled). */
    static constexpr size_t kMaxWholeWindowCells = size_t(1) << 26;
    /** Side of the square the global grid covers around the robot [cells]: global_size_m. */
    int globalSideCells() const;
    /** How far from its sensor a point may grow the window [m]: the sensors' range,
     * TInsertionOptions::max_range_m (a stray far return must not stretch it). */
    double growthReach_m() const;
    /** How far from the map origin the window may grow [m] (BinStore::kGrowthLimitCells). */
    double growthLimit_m() const;
    /** True if growToCover() would change the window for these sensor-frame points seen from
     * `sensorInMap` (the robot pose's mean composed with the sensor pose), without propagating
     * more than the few points near the window's edge. */
    bool growthNeeded(const multibin::PointsWithCov& sensorPoints,
                      const multibin::PosePropagator& propagator,
                      const multibin::BinUpdateParams& params) const;

    /** The insertion core of one update cycle: BinGrid::insertPoints or insertSensorPoints. */
    using FuseIntoGrid =
        std::function<multibin::InsertStats(multibin::BinGrid&, const multibin::BinUpdateParams&)>;
    /** One update cycle of `grid`: insertion core, then the visibility constraint (with the
     * fan test for a scan's rays, not for a camera frame's: multibin::RayFan). */
    multibin::InsertStats insertIntoGrid(multibin::BinGrid& grid,
                                         const multibin::BinUpdateParams& params,
                                         const FuseIntoGrid& fuse,
                                         const std::optional<Eigen::Vector3d>& sensorOrigin_m,
                                         bool cameraFrame = false);
    /** recenter() on (x, y) relative to mapOrigin() [m]. */
    void recenterRelative(double x_m, double y_m);
    /** mapOrigin() if fixed, else the origin data at (x, y) [m, pose frame] would fix. */
    mrpt::math::TPoint2D originFor(double x_m, double y_m) const;
    /** Fixes an automatic map origin at originFor(x, y) if it is not fixed yet. */
    void fixOriginNear(double x_m, double y_m);
    /** Fuses one local cell into the global grid (write-back of data the global grid lacks). */
    void writeBackLocalCell(int ix, int iy);
    multibin::BinGrid& gridFor(const mrpt::obs::CObservation& obs);

    /** The map's state (grids, statistics, sensor-model state, last fill): see
     * src/map/CMultiBinElevationMap_impl.h. Never null. */
    struct Impl;
    std::unique_ptr<Impl> m_impl;
};

}  // namespace mrpt::maps

namespace multibin {
/** Makes sure the library is linked and its map class registered with MRPT. Only needed by a
 * program that names the map in an ini file only and links without the exported CMake target
 * (which already keeps the library linked). */
void registerMultiBinElevationMap();
}  // namespace multibin
