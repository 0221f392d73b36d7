/* Part of the multibin elevation-mapping library: the Python module. */
#include "ElevationMap.h"

#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/maps/CMultiMetricMap.h>
#include <mrpt/serialization/CArchive.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "ArrayInput.h"
#include "HeightQuery.h"
#include "multibin/fill/SparseFill.h"
#include "multibin/geometry/PosePropagation.h"
#include "multibin/io/ErrorMessage.h"
#include "multibin/io/EsriAsciiGrid.h"
#include "multibin/io/Gzip.h"
#include "multibin/io/OutputFile.h"
#include "multibin/map/MapStatistics.h"

namespace py = pybind11;
namespace fs = std::filesystem;
using mrpt::maps::CMultiBinElevationMap;

namespace multibin::python {

namespace {
/** A keyword option's value as ini text: true/false, numbers, text; a list of numbers
 * space-separated and a list of words comma-separated, as the options protocol writes them. */
std::string iniText(const std::string& key, const py::handle& value) {
    if (py::isinstance<py::bool_>(value)) return value.cast<bool>() ? "true" : "false";
    if (py::isinstance<py::str>(value)) return value.cast<std::string>();
    if (py::isinstance<py::int_>(value) || py::isinstance<py::float_>(value))
        return py::repr(value).cast<std::string>();
    if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
        std::string text;
        for (const py::handle item : value) {
            const bool word = py::isinstance<py::str>(item);
            text += (text.empty() ? "" : word ? "," : " ") + iniText(key, item);
        }
        return text;
    }
    throw py::type_error("ElevationMap: option '" + key + "' has a value of type " +
                         std::string(py::str(value.get_type().attr("__name__"))) +
                         "; expected a bool, number, string or list");
}

/** The keys an options struct writes (its unit-suffixed names). */
template <class Options>
std::vector<std::string> keysOf(const std::string& section) {
    mrpt::config::CConfigFileMemory probe;
    Options().saveToConfigFile(probe, section);
    std::vector<std::string> keys;
    probe.getAllKeys(section, keys);
    return keys;
}

bool contains(const std::vector<std::string>& v, const std::string& s) {
    return std::find(v.begin(), v.end(), s) != v.end();
}

std::string fileText(const std::string& path) {
    std::ifstream in(path);
    if (!in) throw std::runtime_error("ElevationMap: cannot read ini file '" + path + "'");
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

void requireFile(const std::string& what, const std::string& path) {
    if (!fs::exists(path)) throw std::runtime_error(what + ": '" + path + "' not found");
    if (fs::is_directory(path))
        throw std::runtime_error(what + ": '" + path + "' is a directory, not a file");
}

/** A raster's samples as a (rows, cols) float32 array, row 0 the southernmost. */
py::array_t<float> rasterArray(const EsriAsciiGrid& g) {
    py::array_t<float> a({g.rows(), g.cols()});
    auto v = a.mutable_unchecked<2>();
    for (int r = 0; r < g.rows(); r++)
        for (int c = 0; c < g.cols(); c++) v(r, c) = g.heights_m(r, c);
    return a;
}
}  // namespace

py::dict insertStatsDict(const InsertStats& s) {
    py::dict d;
    d["accepted"] = s.accepted;
    d["rejected"] = s.rejected();
    d["out_of_range"] = s.outOfRange;
    d["not_finite"] = s.notFinite;
    d["bad_covariance"] = s.badCovariance;
    d["outside_map"] = s.outsideMap;
    d["outside_bin_range"] = s.outsideBinRange;
    d["too_uncertain"] = s.tooUncertain;              // eq 13 gate
    d["continuity_rejected"] = s.continuityRejected;  // eq 14 gate
    return d;
}

ElevationMap::ElevationMap(std::shared_ptr<CMultiBinElevationMap> map) : m_map(std::move(map)) {}

ElevationMap ElevationMap::create(const std::optional<std::string>& iniPath,
                                  const std::string& section, const py::dict& options) {
    if (section.empty()) throw std::invalid_argument("ElevationMap: section must not be empty");
    mrpt::config::CConfigFileMemory ini;
    if (iniPath) {
        requireFile("ElevationMap: ini file", *iniPath);
        ini.setContent(fileText(*iniPath));
    } else {
        ini.write(section, "multiBinElevationMap_count", 1);
    }
    const std::string prefix = section + "_multiBinElevationMap_00_";
    const auto creationKeys = keysOf<CMultiBinElevationMap::TCreationOptions>("s");
    const auto insertionKeys = keysOf<CMultiBinElevationMap::TInsertionOptions>("s");
    for (const auto& [k, value] : options) {
        const std::string key = py::str(k);
        const bool creation = contains(creationKeys, key);
        if (!creation && !contains(insertionKeys, key))
            throw std::invalid_argument("ElevationMap: unknown option '" + key +
                                        "' (the unit-suffixed keys of doc/options.md)");
        ini.write(prefix + (creation ? "creationOpts" : "insertOpts"), key, iniText(key, value));
    }
    const std::string source = iniPath ? "ini file '" + *iniPath + "'" : "options";
    try {
        mrpt::maps::TSetOfMetricMapInitializers inits;
        inits.loadFromConfigFile(ini, section);
        mrpt::maps::CMultiMetricMap maps(inits);
        auto map = maps.mapByClass<CMultiBinElevationMap>();
        if (!map)
            throw std::invalid_argument("defines no multiBinElevationMap in [" + section + "]");
        return ElevationMap(map);
    } catch (const std::exception& e) {
        throw std::invalid_argument("ElevationMap: " + source + ": " + oneLineMessage(e));
    }
}

ElevationMap ElevationMap::load(const std::string& path) {
    requireFile("ElevationMap.load", path);
    try {
        mrpt::io::CFileGZInputStream in(path);
        auto arch = mrpt::serialization::archiveFrom(in);
        const mrpt::serialization::CSerializable::Ptr obj = arch.ReadObject();
        auto map = std::dynamic_pointer_cast<CMultiBinElevationMap>(obj);
        if (!map)
            throw std::runtime_error(std::string("holds a ") +
                                     (obj ? obj->GetRuntimeClass()->className : "null object") +
                                     ", not a CMultiBinElevationMap");
        return ElevationMap(map);
    } catch (const std::exception& e) {
        throw std::runtime_error("ElevationMap.load: '" + path + "': " + oneLineMessage(e));
    }
}

void ElevationMap::save(const std::string& path) const {
    try {
        py::gil_scoped_release nogil;
        // As elevation-mapper saves elevation_map.bin: a private temporary, synced, renamed.
        multibin::writeFileAtomically(path, multibin::gzipSerialized(*m_map));
    } catch (const std::exception& e) {
        throw std::runtime_error("ElevationMap.save: '" + path + "': " + oneLineMessage(e));
    }
}

void ElevationMap::fixOriginNear(double x_m, double y_m) {
    CMultiBinElevationMap::TCreationOptions c = m_map->creationOptions;
    const bool noExtent = !(c.min_x < c.max_x && c.min_y < c.max_y);
    if (!c.origin_auto || c.dual_grid || !noExtent || !m_map->isEmpty()) return;
    const mrpt::math::TPoint2D o = c.originNear(x_m, y_m);
    const mrpt::math::TPoint2D now = m_map->mapOrigin();
    if (o.x == now.x && o.y == now.y) return;
    c.origin_auto = false;  // fixed here, as the first observation would fix it
    c.origin_x_m = o.x;
    c.origin_y_m = o.y;
    m_map->setCreationOptions(c);
}

py::dict ElevationMap::growAndInsert(const PointsWithCov& mapPoints,
                                     const Eigen::Vector3d& sensor_m, bool haveSensor,
                                     const PoseVariances* pose) {
    InsertStats stats;
    {
        py::gil_scoped_release nogil;
        m_map->growToCoverPoints(mapPoints, sensor_m);
        stats = m_map->insertPoints(mapPoints, std::numeric_limits<double>::infinity(),
                                    haveSensor ? std::optional(sensor_m) : std::nullopt, pose);
    }
    return insertStatsDict(stats);
}

py::dict ElevationMap::insertPoints(const py::handle& points, const py::handle& covariances,
                                    const py::object& sensorOrigin) {
    const std::string fn = "insert_points";
    {  // the points' first finite position fixes an automatic origin
        const auto p = realArray(points, fn + ": points");
        if (p.ndim() == 2 && p.shape(0) > 0 && p.shape(1) == 3 && std::isfinite(p.at(0, 0)) &&
            std::isfinite(p.at(0, 1)))
            fixOriginNear(p.at(0, 0), p.at(0, 1));
    }
    const mrpt::math::TPoint2D o = m_map->mapOrigin();
    const PointsWithCov pts = pointsWithCovariance(fn, points, covariances, o.x, o.y);
    Eigen::Vector3d sensor_m = Eigen::Vector3d::Zero();
    const bool haveSensor = !sensorOrigin.is_none();
    if (haveSensor) {
        const auto s = realArray(sensorOrigin, fn + ": sensor_origin");
        if (s.ndim() != 1 || s.shape(0) != 3 || !std::isfinite(s.at(0)) ||
            !std::isfinite(s.at(1)) || !std::isfinite(s.at(2)))
            throw std::invalid_argument(fn + ": sensor_origin must be 3 finite numbers [m]");
        sensor_m = {s.at(0) - o.x, s.at(1) - o.y, s.at(2)};
    } else if (!pts.empty()) {  // growth centre: the points' mean
        for (const PointWithCov& p : pts) sensor_m += p.point_m.cast<double>();
        sensor_m /= double(pts.size());
    }
    return growAndInsert(pts, sensor_m, haveSensor, nullptr);
}

py::dict ElevationMap::insertSensorPoints(const py::handle& points, const py::handle& covariances,
                                          const py::handle& sensorPose, const py::handle& robotPose,
                                          const py::handle& robotPoseCov) {
    const std::string fn = "insert_sensor_points";
    const PointsWithCov sensorPoints = pointsWithCovariance(fn, points, covariances);
    const mrpt::poses::CPose3D sensorOnRobot = pose6(fn + ": sensor_pose", sensorPose);
    mrpt::poses::CPose3DPDFGaussian pdf;
    pdf.mean = pose6(fn + ": robot_pose", robotPose);
    pdf.cov = poseCovariance(fn + ": robot_pose_cov", robotPoseCov);
    fixOriginNear(pdf.mean.x(), pdf.mean.y());
    if (m_map->isDualGrid()) {  // both grids follow the robot, as for an observation
        py::gil_scoped_release nogil;
        m_map->recenter(pdf.mean.x(), pdf.mean.y());
    }
    const mrpt::math::TPoint2D o = m_map->mapOrigin();
    pdf.mean.x(pdf.mean.x() - o.x);  // the library's geometry is relative to the origin
    pdf.mean.y(pdf.mean.y() - o.y);
    const PosePropagator propagator(pdf, sensorOnRobot);
    PointsWithCov mapPoints;
    PoseVariances pose;
    {
        py::gil_scoped_release nogil;
        propagator.apply(sensorPoints, mapPoints, &pose);
    }
    return growAndInsert(mapPoints, propagator.sensorOriginInMap_m(), true, &pose);
}

py::tuple ElevationMap::height(const py::handle& x, const py::handle& y) const {
    const auto xs = realArray(x, "height: x");
    const auto ys = realArray(y, "height: y");
    const std::vector<py::ssize_t> shape(xs.shape(), xs.shape() + xs.ndim());
    if (!(ys.ndim() == xs.ndim() && std::equal(shape.begin(), shape.end(), ys.shape())))
        throw std::invalid_argument("height: x and y must have the same shape (x has " +
                                    std::to_string(xs.size()) + " values, y " +
                                    std::to_string(ys.size()) + ")");
    py::array_t<double> h(shape), s(shape);
    py::array_t<uint8_t> src(shape);
    double* hp = h.mutable_data();
    double* sp = s.mutable_data();
    uint8_t* srcp = src.mutable_data();
    {
        py::gil_scoped_release nogil;
        queryHeights(*m_map, xs.data(), ys.data(), size_t(xs.size()), hp, sp, srcp);
    }
    return py::make_tuple(h, s, src);
}

py::dict ElevationMap::layers() const {
    using Layer = CMultiBinElevationMap::RasterLayer;
    EsriAsciiGrid height, sigma, certainty, source;
    {
        py::gil_scoped_release nogil;
        // Each raster takes the map's lock on its own: a writer between them may grow the
        // window. Read again until the four share one lattice (a grown window is rare).
        auto sameLattice = [](const EsriAsciiGrid& a, const EsriAsciiGrid& b) {
            return a.rows() == b.rows() && a.cols() == b.cols() && a.xllcenter_m == b.xllcenter_m &&
                   a.yllcenter_m == b.yllcenter_m;
        };
        do {
            height = m_map->toRaster(Layer::Height);
            sigma = m_map->toRaster(Layer::Sigma);
            certainty = m_map->toRaster(Layer::Certainty);
            source = m_map->toRaster(Layer::Source);
        } while (!(sameLattice(height, sigma) && sameLattice(height, certainty) &&
                   sameLattice(height, source)));
    }
    py::array_t<uint8_t> src({source.rows(), source.cols()});
    auto v = src.mutable_unchecked<2>();
    for (int r = 0; r < source.rows(); r++)
        for (int c = 0; c < source.cols(); c++) {
            const float f = source.heights_m(r, c);
            v(r, c) = std::isnan(f) ? 0 : uint8_t(f);
        }
    // Lattice: the lower-left corner of the lower-left cell, as imshow(origin="lower") wants.
    const double cell = height.cellsize_m;
    const double x0 = height.xllcenter_m - 0.5 * cell, y0 = height.yllcenter_m - 0.5 * cell;
    py::dict d;
    d["height"] = rasterArray(height);
    d["sigma"] = rasterArray(sigma);
    d["certainty"] = rasterArray(certainty);
    d["source"] = src;
    d["origin"] = py::make_tuple(x0, y0);
    d["cell_size"] = cell;
    d["extent"] = py::make_tuple(x0, x0 + height.cols() * cell, y0, y0 + height.rows() * cell);
    return d;
}

py::dict ElevationMap::fill() {
    {
        py::gil_scoped_release nogil;
        m_map->dem_update_map();
    }
    const fill::FillResult::Stats& s = m_map->lastFilledCells().stats;
    py::dict d;
    d["measured"] = s.measured;
    d["median"] = s.median;
    d["surface"] = s.gaussian;
    d["harmonic"] = s.harmonic;
    d["unfilled"] = s.unfilled;
    d["support_areas"] = s.supportAreas;
    return d;
}

double ElevationMap::resolution_m() const { return m_map->dem_get_resolution(); }

py::tuple ElevationMap::origin_m() const {
    const mrpt::math::TPoint2D o = m_map->mapOrigin();
    return py::make_tuple(o.x, o.y);
}

py::tuple ElevationMap::extent_m() const {
    return py::make_tuple(m_map->getXMin(), m_map->getXMax(), m_map->getYMin(), m_map->getYMax());
}

py::dict ElevationMap::insertStats() const { return insertStatsDict(m_map->statistics().insert); }

std::string ElevationMap::describe() const { return m_map->asString(); }

}  // namespace multibin::python
