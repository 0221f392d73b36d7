/* Part of the multibin elevation-mapping library: the elevation-mapper program. */
#include "EvaluationRun.h"

#include "MapOutputs.h"
#include "ProgressBar.h"

#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationRobotPose.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>

#include "multibin/io/RasterExport.h"
#include "multibin/traversability/TraversabilityEvaluation.h"

namespace fs = std::filesystem;
using mrpt::maps::CMultiBinElevationMap;
using multibin::Lattice;
using multibin::eval::CellArray;
using multibin::eval::MethodEstimate;

namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

/** The truth on the map's lattice, cut to `area_m` when given. */
CellArray loadTruth(const std::string& path, double cellSize_m, const std::vector<double>& area_m,
                    Lattice& lattice) {
    if (!fs::exists(path)) throw std::runtime_error("ground truth '" + path + "' not found");
    const multibin::EsriAsciiGrid truth = multibin::EsriAsciiGrid::load(path);  // names the file
    CellArray whole;
    try {
        whole = multibin::eval::groundTruthOnLattice(truth, cellSize_m, lattice);
    } catch (const std::bad_alloc&) {
        throw std::runtime_error("ground truth '" + path + "': out of memory");
    } catch (const std::invalid_argument& e) {
        throw std::runtime_error("ground truth '" + path + "': " + e.what());
    }
    if (area_m.empty()) return whole;
    const Lattice sub = multibin::eval::subLattice(lattice, area_m);
    const CellArray cut =
        whole.block(sub.window.iy0 - lattice.window.iy0, sub.window.ix0 - lattice.window.ix0,
                    sub.window.ny, sub.window.nx);
    lattice = sub;
    return cut;
}

/** Cell size of the evaluated map's (global) grid [m]. */
double evaluatedCellSize_m(const CMultiBinElevationMap& map) {
    const auto& c = map.creationOptions;
    return c.dual_grid ? c.global_resolution_m : c.resolution_m;
}

multibin::EsriAsciiGrid rasterOf(const Lattice& L, const CellArray& values) {
    multibin::EsriAsciiGrid g = multibin::EsriAsciiGrid::onLattice(L);
    g.heights_m = values.matrix();
    return g;
}

/** Heights of one of MRPT's DEMs at the lattice's cell centres; NaN where it has none, or outside
 * `within` when given. */
CellArray sampleDem(const mrpt::maps::CHeightGridMap2D_Base& dem, const Lattice& lattice,
                    const Lattice* within = nullptr) {
    CellArray h;
    h.setConstant(lattice.window.ny, lattice.window.nx, NAN);
    for (int r = 0; r < lattice.window.ny; r++)
        for (int c = 0; c < lattice.window.nx; c++) {
            const double x = lattice.cellCenterX_m(c), y = lattice.cellCenterY_m(r);
            int cc, rr;
            double z;
            if ((!within || within->cellOf(x, y, cc, rr)) && dem.dem_get_z(x, y, z))
                h(r, c) = float(z);
        }
    return h;
}

/** Row-major values of a lattice's cells (CellArray rows are y). */
std::vector<float> rowMajor(const CellArray& a) {
    std::vector<float> v(size_t(a.rows()) * size_t(a.cols()), NAN);
    for (int r = 0; r < a.rows(); r++)
        for (int c = 0; c < a.cols(); c++) v[size_t(r) * size_t(a.cols()) + size_t(c)] = a(r, c);
    return v;
}

/** The truth's classes of the evaluated cells (and their features): -1 where unknown, and, with an
 * evaluated area, where a cell's disc reaches beyond it: the class of such a disc describes
 * surface outside the area (the ground around the boards, which the scenario's sensors never see
 * behind the boards' edges), not the area scored. */
std::vector<int8_t> scoredTruth(const multibin::EsriAsciiGrid& truthRaster, const Lattice& lattice,
                                const std::vector<double>& area_m,
                                const multibin::traversability::TraversabilityOptions& o,
                                std::vector<multibin::traversability::DiscFeatures>& features) {
    std::vector<int8_t> truth =
        multibin::traversability::truthClasses(truthRaster, lattice, o, &features);
    if (area_m.empty()) return truth;
    for (int r = 0; r < lattice.ny(); r++)
        for (int c = 0; c < lattice.nx(); c++) {
            const double x = lattice.cellCenterX_m(c), y = lattice.cellCenterY_m(r);
            if (x - o.radius_m < area_m[0] || x + o.radius_m > area_m[1] ||
                y - o.radius_m < area_m[2] || y + o.radius_m > area_m[3])
                truth[lattice.index(c, r)] = -1;
        }
    return truth;
}

/** The traversability layer against the truth's (doc/traversability.md): classes from the
 * ground-truth raster itself (the finer it is, the closer to the surface), scored for the map's
 * probabilities and for the features of other methods' cell heights thresholded at the limits
 * themselves (the options' calibration is a fit of the map's layer, not of other methods).
 * With an evaluated area (`area_m`), only the cells whose disc lies inside it are scored. Writes
 * traversability.json, traversability_cells.csv (the truth's and the layer's features of each
 * scored cell) and eval_untraversable_{truth,multibin}.{asc,png}. */
std::string evaluateTraversability(const OutputFolder& out, const CMultiBinElevationMap& map,
                                   const Lattice& lattice, const std::vector<double>& area_m,
                                   const std::string& truthPath,
                                   const std::vector<MethodEstimate>& heightMethods) {
    namespace trav = multibin::traversability;
    const trav::TraversabilityOptions& o = map.traversabilityOptions;
    const multibin::EsriAsciiGrid truthRaster = multibin::EsriAsciiGrid::load(truthPath);
    std::vector<trav::DiscFeatures> truthFeatures;
    const std::vector<int8_t> truth = scoredTruth(truthRaster, lattice, area_m, o, truthFeatures);
    // The map's layer, looked up at each evaluated cell's centre.
    const trav::TraversabilityLayers layers = map.traversabilityLayers();
    const mrpt::math::TPoint2D origin = map.mapOrigin();
    std::vector<float> p(lattice.cellCount(), NAN);
    std::ostringstream csv;  // what a calibration is fitted on (scripts/fit-traversability.py)
    csv << "x_m,y_m,truth_step_m,truth_slope_deg,truth_roughness_m,step_m,slope_deg,roughness_m,"
           "untraversable\n";
    for (int r = 0; r < lattice.ny(); r++)
        for (int c = 0; c < lattice.nx(); c++) {
            int lc, lr;
            const size_t k = lattice.index(c, r);
            if (!layers.lattice.cellOf(lattice.cellCenterX_m(c) - origin.x,
                                       lattice.cellCenterY_m(r) - origin.y, lc, lr))
                continue;
            const size_t l = layers.lattice.index(lc, lr);
            p[k] = layers.untraversable[l];
            if (truth[k] < 0 || !layers.known(l)) continue;
            const trav::DiscFeatures& f = truthFeatures[k];
            csv << lattice.cellCenterX_m(c) << ',' << lattice.cellCenterY_m(r) << ',' << f.step_m
                << ',' << f.slope_deg << ',' << f.roughness_m << ',' << layers.step_m[l] << ','
                << layers.slope_deg[l] << ',' << layers.roughness_m[l] << ','
                << layers.untraversable[l] << '\n';
        }
    out.write("traversability_cells.csv", csv.str());
    std::map<std::string, trav::ClassifierScore> scores{
        {"multibin", trav::scoreProbabilities(p, truth)}};
    std::vector<std::string> order{"multibin"};
    trav::TraversabilityOptions thresholded = o.uncalibrated();
    thresholded.monte_carlo_draws = 0;
    thresholded.use_bins = false;
    // The truth sampled at the cells' centres (its nearest sample): the exact surface on the
    // map's lattice, as a lattice of points rather than cell means.
    MethodEstimate truthPoints;
    truthPoints.name = "truth_at_cell_centres";
    truthPoints.height_m.setConstant(lattice.ny(), lattice.nx(), NAN);
    for (int r = 0; r < lattice.ny(); r++)
        for (int c = 0; c < lattice.nx(); c++) {
            const double d = truthRaster.cellsize_m;
            const long tc = std::lround((lattice.cellCenterX_m(c) - truthRaster.xllcenter_m) / d);
            const long tr = std::lround((lattice.cellCenterY_m(r) - truthRaster.yllcenter_m) / d);
            if (tc >= 0 && tr >= 0 && tc < truthRaster.cols() && tr < truthRaster.rows())
                truthPoints.height_m(r, c) = truthRaster.heights_m(int(tr), int(tc));
        }
    std::vector<MethodEstimate> methods = heightMethods;
    methods.push_back(truthPoints);
    for (const MethodEstimate& m : methods) {
        trav::TraversabilityLayers t;
        trav::computeLayers(trav::cellHeightSamples(lattice, rowMajor(m.height_m)), thresholded, t);
        scores[m.name + "_thresholded"] = trav::scoreProbabilities(t.untraversable, truth);
        order.push_back(m.name + "_thresholded");
    }
    out.write("traversability.json", trav::scoresJson(scores, order, o));
    multibin::PreviewStyle style;
    style.title = "P(untraversable)";
    style.colormap = cv::COLORMAP_INFERNO;
    style.valueFormat = "%.2f";
    for (const auto& [name, values] :
         {std::pair<std::string, std::vector<float>>{"truth", {truth.begin(), truth.end()}},
          {"multibin", p}}) {
        multibin::EsriAsciiGrid g = multibin::EsriAsciiGrid::onLattice(lattice);
        for (int r = 0; r < lattice.ny(); r++)
            for (int c = 0; c < lattice.nx(); c++) {
                const float v = values[lattice.index(c, r)];
                g.heights_m(r, c) = v < 0 ? NAN : v;  // the truth's -1: unknown
            }
        out.writeWith("eval_untraversable_" + name + ".asc", [&](const std::string& path) {
            g.save(path);
            return true;
        });
        out.write("eval_untraversable_" + name + ".png", multibin::encodePreviewPng(g, style));
    }
    return "Traversability against the truth's features (traversability.json):\n" +
           trav::scoresTable(scores, order);
}

}  // namespace

EvaluationRun::EvaluationRun(const Options& options, CMultiBinElevationMap& evaluated)
    : m_options(options),
      m_evaluated(evaluated),
      m_laserOnly(evaluated.creationOptions),
      m_truth(loadTruth(options.groundTruthPath, evaluatedCellSize_m(evaluated), options.area_m,
                        m_lattice)),
      m_rawLaser(m_lattice),
      m_rawAll(m_lattice),
      m_heightGrid(mrpt::maps::CHeightGridMap2D::mrSimpleAverage, m_lattice.area_m()[0],
                   m_lattice.area_m()[1], m_lattice.area_m()[2], m_lattice.area_m()[3],
                   m_lattice.cellSize_m) {
    m_laserOnly.insertionOptions = evaluated.insertionOptions;
    // The profile is sampled every half cell: a line beyond the evaluated area would be sampled
    // (billions of times, for a far end point) where there is nothing to draw.
    const auto area = m_lattice.area_m();
    for (size_t k = 0; k + 1 < options.profile_m.size(); k += 2) {
        const double x = options.profile_m[k], y = options.profile_m[k + 1];
        if (!(x >= area[0] && x <= area[1] && y >= area[2] && y <= area[3])) {
            std::ostringstream os;
            os << "--profile: the point (" << x << ", " << y
               << ") m lies outside the evaluated area x " << area[0] << ".." << area[1] << " m, y "
               << area[2] << ".." << area[3] << " m";
            throw std::invalid_argument(os.str());
        }
    }
    if (options.withMrf) {
        // A centred crop: MRPT's GMRF solve grows as about n^2.6 in cells.
        const int side = std::min({options.mrfMaxCells, m_lattice.window.nx, m_lattice.window.ny});
        m_mrfLattice = m_lattice;
        m_mrfLattice.window.ix0 = m_lattice.window.ix0 + (m_lattice.window.nx - side) / 2;
        m_mrfLattice.window.iy0 = m_lattice.window.iy0 + (m_lattice.window.ny - side) / 2;
        m_mrfLattice.window.nx = m_mrfLattice.window.ny = side;
        const auto a = m_mrfLattice.area_m();
        m_mrf = std::make_unique<mrpt::maps::CHeightGridMap2D_MRF>(
            mrpt::maps::CHeightGridMap2D_MRF::mrGMRF_SD, a[0], a[1], a[2], a[3],
            m_mrfLattice.cellSize_m, false);
    }
    // The raw map's points: the same sensor geometry with every rejection rule off.
    m_rawSensorOptions = evaluated.insertionOptions.sensors;
    auto& laser = m_rawSensorOptions.laser;
    laser.agcByLabel.clear();  // no eq 1 intensity check
    laser.mixedPixelFilter = false;
    laser.continuity = false;
    auto& stereo = m_rawSensorOptions.stereo;
    stereo.halo.enabled = false;
    stereo.nearCluster.enabled = false;
}

void EvaluationRun::insertRawPoints(const mrpt::obs::CObservation& obs,
                                    const mrpt::poses::CPose3DPDFGaussian& robotPose) {
    multibin::sensors::SensorPoints sp;
    const auto& io = m_evaluated.insertionOptions;
    if (!multibin::sensors::observationToSensorPoints(obs, robotPose, m_rawSensorOptions,
                                                      io.min_range_m, io.max_range_m,
                                                      m_rawSensorState, sp))
        return;
    const mrpt::poses::CPose3D sensorInMap = robotPose.mean + sp.sensorPose;
    std::vector<mrpt::math::TPoint3D> points(sp.points.size());
    for (size_t i = 0; i < sp.points.size(); i++) {
        const auto& p = sp.points[i].point_m;
        sensorInMap.composePoint(p.x(), p.y(), p.z(), points[i].x, points[i].y, points[i].z);
    }

    const bool isLaser = dynamic_cast<const mrpt::obs::CObservation2DRangeScan*>(&obs) != nullptr;
    auto t0 = Clock::now();
    for (const auto& p : points) {
        m_rawAll.addPoint(p.x, p.y, p.z);
        if (isLaser) m_rawLaser.addPoint(p.x, p.y, p.z);
    }
    m_raw_s += secondsSince(t0);

    t0 = Clock::now();
    mrpt::maps::CHeightGridMap2D_Base::TPointInsertParams ip;
    ip.update_map_after_insertion = false;
    for (const auto& p : points) m_heightGrid.insertIndividualPoint(p.x, p.y, p.z, ip);
    m_heightGrid_s += secondsSince(t0);

    if (m_mrf) {
        t0 = Clock::now();
        int col, row;
        for (const auto& p : points)
            if (m_mrfLattice.cellOf(p.x, p.y, col, row))
                m_mrf->insertIndividualPoint(p.x, p.y, p.z, ip);
        m_mrf_s += secondsSince(t0);
    }
}

void EvaluationRun::observe(const mrpt::obs::CObservation& obs,
                            const mrpt::poses::CPose3DPDFGaussian& robotPose,
                            bool poseHasCovariance) {
    if (m_evaluated.acceptsLabel(obs.sensorLabel)) insertRawPoints(obs, robotPose);
    if (!dynamic_cast<const mrpt::obs::CObservation2DRangeScan*>(&obs) &&
        !dynamic_cast<const mrpt::obs::CObservationRobotPose*>(&obs))
        return;
    const auto t0 = Clock::now();
    if (poseHasCovariance)
        m_laserOnly.insertObservation(obs, robotPose);
    else
        m_laserOnly.insertObservation(obs, robotPose.mean);
    m_laserOnly_s += secondsSince(t0);
}

MethodEstimate EvaluationRun::sampleMap(const std::string& name, const CMultiBinElevationMap& map,
                                        bool filled) const {
    MethodEstimate m;
    m.name = name;
    m.height_m.setConstant(m_lattice.window.ny, m_lattice.window.nx, NAN);
    m.sigma_m.setConstant(m_lattice.window.ny, m_lattice.window.nx, NAN);
    // The cells' values, as the rasters give them: the table scores one height per cell against
    // the truth raster on the same lattice (the sub-cell surface: doc/sub-cell-surface.md).
    for (int r = 0; r < m_lattice.window.ny; r++)
        for (int c = 0; c < m_lattice.window.nx; c++) {
            double h, s;
            if (map.cellElevation(m_lattice.cellCenterX_m(c), m_lattice.cellCenterY_m(r), h, s,
                                  filled) != CMultiBinElevationMap::HeightSource::Unknown) {
                m.height_m(r, c) = float(h);
                m.sigma_m(r, c) = float(s);
            }
        }
    return m;
}

std::string EvaluationRun::finish(const OutputFolder& out, double multibinInsert_s,
                                  double multibinFill_s) {
    m_laserOnly.flushLocalToGlobal();

    std::vector<MethodEstimate> methods;
    MethodEstimate rawLaser{"raw_laser", m_rawLaser.heights_m(), {}, "raw_laser", m_raw_s, 0, true,
                            {}};
    MethodEstimate rawAll{"raw_all", m_rawAll.heights_m(), {}, "raw_all", m_raw_s, 0, true, {}};
    methods.push_back(rawLaser);
    methods.push_back(rawAll);

    MethodEstimate laserOnly = sampleMap("laser_only", m_laserOnly, false);
    laserOnly.baseline = "raw_laser";
    laserOnly.insert_s = m_laserOnly_s;
    methods.push_back(laserOnly);

    MethodEstimate multibin = sampleMap("multibin", m_evaluated, false);
    multibin.baseline = "raw_all";
    multibin.insert_s = multibinInsert_s;
    methods.push_back(multibin);

    MethodEstimate filled = sampleMap("multibin_filled", m_evaluated, true);
    filled.baseline = "raw_all";
    filled.insert_s = multibin.insert_s;
    filled.fill_s = multibinFill_s;
    filled.filledFrom = "multibin";  // report.json: within 3 sigma over the filled-only cells
    methods.push_back(filled);

    MethodEstimate heightGrid;
    heightGrid.name = "mrpt_height_grid";
    heightGrid.baseline = "raw_all";
    heightGrid.insert_s = m_heightGrid_s;
    heightGrid.height_m = sampleDem(m_heightGrid, m_lattice);
    methods.push_back(heightGrid);

    if (m_mrf) {
        const auto t0 = Clock::now();
        // One GMRF solve over the crop (a minute or more).
        ProgressBar::runWithProgress("MRF solve", [&] { m_mrf->dem_update_map(); });
        MethodEstimate mrf;
        mrf.name = "mrpt_height_grid_mrf";
        mrf.baseline = "raw_all";
        mrf.coversWholeArea = false;  // its crop must not narrow the others' shared cells
        mrf.insert_s = m_mrf_s;
        mrf.fill_s = secondsSince(t0);
        mrf.height_m = sampleDem(*m_mrf, m_lattice, &m_mrfLattice);
        methods.push_back(mrf);
    }

    const auto scores = multibin::eval::scoreMethods(m_truth, methods);
    std::vector<std::string> order;
    for (const auto& m : methods) order.push_back(m.name);
    // Every method where MRPT's height grid has no value: what filling adds where MRPT has nothing.
    std::vector<multibin::eval::AreaScores> areas{
        multibin::eval::scoreGapsOf(heightGrid.name, m_truth, methods)};
    if (m_mrf)  // every method on the GMRF's crop only
        areas.push_back(
            multibin::eval::scoreArea("mrf_crop", m_truth, methods, m_lattice, m_mrfLattice));

    out.write("report.json", multibin::eval::reportJson(scores, order, m_lattice, areas));
    // The truth's own cell means: what thresholded heights at the map's resolution reach at best.
    MethodEstimate truthCells;
    truthCells.name = "truth_cell_means";
    truthCells.height_m = m_truth;
    auto saveRaster = [&](const std::string& name, const CellArray& values) {
        out.writeWith(name, [&](const std::string& path) {
            rasterOf(m_lattice, values).save(path);
            return true;
        });
    };
    saveRaster("eval_truth.asc", m_truth);
    for (const auto& m : methods) saveRaster("eval_" + m.name + ".asc", m.height_m);
    out.write("profile.csv", profileCsv(m_truth, methods));
    return multibin::eval::reportTable(scores, order, areas) +
           evaluateTraversability(out, m_evaluated, m_lattice, m_options.area_m,
                                  m_options.groundTruthPath, {filled, heightGrid, truthCells});
}

std::string EvaluationRun::profileCsv(const CellArray& truth,
                                      const std::vector<MethodEstimate>& methods) const {
    std::vector<double> line = m_options.profile_m;
    if (line.empty()) {
        const auto a = m_lattice.area_m();
        const double yMid = 0.5 * (a[2] + a[3]);
        line = {a[0], yMid, a[1], yMid};
    }
    if (line.size() != 4) throw std::invalid_argument("--profile needs x0,y0,x1,y1 [m]");
    const auto find = [&](const std::string& name) -> const MethodEstimate* {
        for (const auto& m : methods)
            if (m.name == name) return &m;
        return nullptr;
    };
    const MethodEstimate* measured = find("multibin");
    const MethodEstimate* filled = find("multibin_filled");
    const MethodEstimate* raw = find("raw_all");

    std::ostringstream f;
    f << "s_m,x_m,y_m,truth_m,multibin_m,multibin_sigma_m,filled_m,filled_sigma_m,raw_m\n";
    const double dx = line[2] - line[0], dy = line[3] - line[1];
    const double length_m = std::hypot(dx, dy);
    const int samples = std::max(2, int(std::ceil(length_m / (0.5 * m_lattice.cellSize_m))) + 1);
    auto value = [](const CellArray& a, int r, int c) -> std::string {
        if (a.size() == 0 || !std::isfinite(a(r, c))) return "";
        return std::to_string(a(r, c));
    };
    for (int k = 0; k < samples; k++) {
        const double t = double(k) / (samples - 1);
        const double x = line[0] + t * dx, y = line[1] + t * dy;
        int c, r;
        if (!m_lattice.cellOf(x, y, c, r)) continue;
        f << t * length_m << ',' << x << ',' << y << ',' << value(truth, r, c) << ','
          << value(measured->height_m, r, c) << ',' << value(measured->sigma_m, r, c) << ','
          << value(filled->height_m, r, c) << ',' << value(filled->sigma_m, r, c) << ','
          << value(raw->height_m, r, c) << '\n';
    }
    return f.str();
}
