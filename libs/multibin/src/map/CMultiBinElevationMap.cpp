/* Part of the multibin elevation-mapping library. */
#include <mrpt/config/CConfigFile.h>
#include <mrpt/maps/TMetricMapTypesRegistry.h>
#include <mrpt/rtti/CObject.h>
#include "CMultiBinElevationMap_impl.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "multibin/io/StrictConfigSection.h"
#include "multibin/map/CellSurface.h"

using namespace mrpt::maps;

// "multiBinElevationMap" is the name used in CMultiMetricMap ini files
// (multiBinElevationMap_count).
MAP_DEFINITION_REGISTER("mrpt::maps::CMultiBinElevationMap,multiBinElevationMap",
                        mrpt::maps::CMultiBinElevationMap)

IMPLEMENTS_SERIALIZABLE(CMultiBinElevationMap, CMetricMap, mrpt::maps)

// Register with MRPT's class registry when the library loads, so polymorphic deserialization
// (CArchive::ReadObject) finds the class in any program that loads the library. A C++ dynamic
// initialiser placed after IMPLEMENTS_SERIALIZABLE runs after the class id it reads (same
// translation unit, in order); MRPT_INITIALIZER (a constructor attribute) may run before it with
// clang, which then registers a null class name.
namespace {
const bool kClassRegistered =
    (mrpt::rtti::registerClass(CLASS_ID(mrpt::maps::CMultiBinElevationMap)), true);
}  // namespace

namespace multibin {
void registerMultiBinElevationMap() {
    // Registration happens at load time; naming this function forces the library to be linked.
    mrpt::rtti::registerClass(CLASS_ID(mrpt::maps::CMultiBinElevationMap));
}
}  // namespace multibin

namespace {
// Keys MRPT itself puts in every `_creationOpts` section (TMapGenericParams).
const std::vector<std::string> kGenericMapKeys = {
    "enableSaveAs3DObject", "enableObservationLikelihood", "enableObservationInsertion"};

/** options.validate(), its error prefixed with the file and section the options came from. */
template <typename Options>
void validateIn(const multibin::StrictConfigSection& s, const Options& options) {
    try {
        options.validate();
    } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(s.where() + ": " + e.what());
    }
}

/** "ini file 'F'" or "ini" (a source that is not a file). Messages hold no ']': MRPT's exception
 * wrapper takes the text up to one for a source location. */
std::string iniName(const mrpt::config::CConfigFileBase& source) {
    if (const auto* f = dynamic_cast<const mrpt::config::CConfigFile*>(&source))
        return "ini file '" + f->getAssociatedFile() + "'";
    return "ini";
}

constexpr int kMaxMapCount = 64;  //!< maps of this class in one CMultiMetricMap

/** Checks what MRPT's TSetOfMetricMapInitializers does not, before it creates `count` map
 * definitions (count = -1 or 100000 took 9-23 GB): the `multiBinElevationMap_count` key of the
 * parent section, and every section of this map's prefix (`<parent>_multiBinElevationMap_NN_X`:
 * NN below the count, X creationOpts or insertOpts), so a misspelt one is an error, not ignored. */
void checkMapSections(const mrpt::config::CConfigFileBase& source, const std::string& prefix) {
    const std::string tag = "_multiBinElevationMap_";
    const auto at = prefix.rfind(tag);
    if (at == std::string::npos) return;  // not created through a CMultiMetricMap ini
    const std::string parent = prefix.substr(0, at);
    const std::string countKey = "multiBinElevationMap_count";
    const std::string countText = source.read_string(parent, countKey, "0");
    char* end = nullptr;
    const long count = std::strtol(countText.c_str(), &end, 10);
    if (countText.empty() || *end != '\0' || count < 0 || count > kMaxMapCount)
        throw std::invalid_argument(iniName(source) + ", section '" + parent + "', key '" +
                                    countKey + "': expected a whole number from 0 to " +
                                    std::to_string(kMaxMapCount) + ", got '" + countText + "'");
    std::vector<std::string> sections;
    source.getAllSections(sections);
    const std::string mapPrefix = parent + tag.substr(0, tag.size() - 1);
    for (const auto& sec : sections) {
        if (sec.compare(0, mapPrefix.size(), mapPrefix) != 0) continue;
        bool known = false;
        for (long i = 0; i < count && !known; i++) {
            char nn[8];
            std::snprintf(nn, sizeof nn, "%02ld", i);
            for (const char* part : {"_creationOpts", "_insertOpts"})
                known = known || sec == parent + tag + nn + part;
        }
        if (!known)
            throw std::invalid_argument(
                iniName(source) + ", section '" + sec + "': unknown section (this map reads '" +
                parent + tag + "NN_creationOpts' and '" + parent + tag +
                "NN_insertOpts', NN from 00 to " + std::to_string(count - 1) + ")");
    }
}

const char* colormapName(mrpt::img::TColormap c) {
    switch (c) {
        case mrpt::img::cmGRAYSCALE:
            return "grayscale";
        case mrpt::img::cmJET:
            return "jet";
        case mrpt::img::cmHOT:
            return "hot";
        default:
            return "jet";
    }
}
}  // namespace

// ---------------------------------------------------------------------------------------------
// Options
// ---------------------------------------------------------------------------------------------
namespace {
/** Calls visit(key, oldName, member) for every key of `o` (a TCreationOptions or a const one;
 * oldName is the documented alias from before the unit suffix, or empty): the one list of keys
 * that load and save share, in the order save writes them. */
template <class Options, class Visit>
void visitCreationKeys(Options& o, Visit&& visit) {
    visit("resolution_m", "resolution", o.resolution_m);
    visit("bin_height_m", "bin_height", o.bin_height_m);
    visit("grow", "", o.grow);
    visit("max_size_m", "", o.max_size_m);
    visit("min_x_m", "min_x", o.min_x);
    visit("max_x_m", "max_x", o.max_x);
    visit("min_y_m", "min_y", o.min_y);
    visit("max_y_m", "max_y", o.max_y);
    visit("dual_grid", "", o.dual_grid);
    visit("local_size_m", "", o.local_size_m);
    visit("local_resolution_m", "local_resolution", o.local_resolution_m);
    visit("global_size_m", "", o.global_size_m);
    visit("global_resolution_m", "global_resolution", o.global_resolution_m);
}
}  // namespace

void CMultiBinElevationMap::TCreationOptions::loadFromConfigFile(
    const mrpt::config::CConfigFileBase& source, const std::string& section) {
    multibin::StrictConfigSection s(source, section);
    visitCreationKeys(*this, [&](const char* key, const std::string& oldName, auto& value) {
        if (oldName.empty())
            s.read(key, value);
        else
            s.read(key, oldName, value);
    });
    s.allow(kGenericMapKeys);
    s.finish();
    validateIn(s, *this);
}

void CMultiBinElevationMap::TCreationOptions::saveToConfigFile(mrpt::config::CConfigFileBase& c,
                                                               const std::string& section) const {
    visitCreationKeys(*this, [&](const char* key, const std::string&, const auto& value) {
        c.write(section, key, value);
    });
}

namespace {
/** Largest cell index an option may produce: int with room for a window of 2^30 cells. */
constexpr double kMaxCellIndex = 1 << 30;
}  // namespace

void CMultiBinElevationMap::TCreationOptions::validate() const {
    auto bad = [](const std::string& key, const std::string& what) {
        throw std::invalid_argument("CMultiBinElevationMap creation option '" + key + "': " + what);
    };
    if (!(resolution_m > 0) || !std::isfinite(resolution_m))
        bad("resolution_m", "must be a positive cell size [m]");
    if (!(bin_height_m > 0) || !std::isfinite(bin_height_m))
        bad("bin_height_m", "must be a positive bin height [m]");
    if (!(max_size_m > 0) || !std::isfinite(max_size_m))
        bad("max_size_m", "must be a positive size [m]");
    for (const auto& [key, v] : {std::pair{"min_x_m", min_x},
                                 {"max_x_m", max_x},
                                 {"min_y_m", min_y},
                                 {"max_y_m", max_y}}) {
        if (!std::isfinite(v)) bad(key, "must be finite [m]");
        // Cell indices are int: an extent far from the origin would overflow them.
        if (std::abs(v / resolution_m) > kMaxCellIndex) {
            std::ostringstream os;
            os << v << " m is cell index " << v / resolution_m << " at " << resolution_m
               << " m cells, beyond the +-" << kMaxCellIndex << " the grid can index";
            bad(key, os.str());
        }
    }
    if (max_x < min_x || max_y < min_y)
        bad("min_x_m/max_x_m/min_y_m/max_y_m", "max must not be below min");
    for (const auto& [key, v] : {std::pair{"local_size_m", local_size_m},
                                 {"local_resolution_m", local_resolution_m},
                                 {"global_size_m", global_size_m},
                                 {"global_resolution_m", global_resolution_m}})
        if (!(v > 0) || !std::isfinite(v)) bad(key, "must be positive [m]");
    if (!grow && (max_x <= min_x || max_y <= min_y))
        bad("grow", "a fixed extent (grow = false) needs min_x < max_x and min_y < max_y");
    // Refuse before allocating: every cell of a grid's window takes a slot of BinGrid (12 bytes:
    // first bin, cycle stamp, update index) before any bin is stored.
    constexpr double kCellBytes = 12, kMaxCells = 2.0e8;  // 2.4 GB of cell slots
    auto checkArea = [&](const std::string& key, double side_m, double cell_m) {
        const double side_cells = side_m / cell_m;
        if (side_cells * side_cells <= kMaxCells) return;
        std::ostringstream os;
        os << "a grid of " << side_cells << " x " << side_cells << " cells (" << cell_m
           << " m cells) would need " << side_cells * side_cells * kCellBytes / 1e9
           << " GB for its cells alone; use a coarser resolution or a smaller size";
        bad(key, os.str());
    };
    if (dual_grid) {
        checkArea("local_size_m", local_size_m, local_resolution_m);
        checkArea("global_size_m", global_size_m, global_resolution_m);
    } else {
        checkArea("max_size_m", std::max({max_size_m, max_x - min_x, max_y - min_y}), resolution_m);
    }
}

void CMultiBinElevationMap::TInsertionOptions::loadFromConfigFile(
    const mrpt::config::CConfigFileBase& source, const std::string& section) {
    multibin::StrictConfigSection s(source, section);
    s.read("certainty_increment", certainty_increment);
    s.read("max_elevation_uncertainty_m", "max_elevation_uncertainty", max_elevation_uncertainty_m);
    s.read("height_sigma_floor_m", "height_sigma_floor", height_sigma_floor_m);
    s.read("default_pose_sigmas", default_pose_sigmas, 6);
    s.read("robot_pose_max_dt_s", "robot_pose_max_dt", robot_pose_max_dt_s);
    s.read("range_sigma_m", "range_sigma", range_sigma_m);
    s.read("min_range_m", "min_range", min_range_m);
    s.read("max_range_m", "max_range", max_range_m);
    s.read("sensor_labels", sensor_labels);
    s.read("global_sensor_labels", global_sensor_labels);
    s.readChoice<mrpt::img::TColormap>("colormap", colormap,
                                       {{"jet", mrpt::img::cmJET},
                                        {"hot", mrpt::img::cmHOT},
                                        {"grayscale", mrpt::img::cmGRAYSCALE}});
    s.read("color_by_sigma", color_by_sigma);
    visibility.read(s);
    s.read("dem_return_filled", dem_return_filled);
    s.read("relief_sigma", relief_sigma);
    s.readChoice<HeightQuery>("height_query", height_query,
                              {{"plane", HeightQuery::Plane}, {"nearest", HeightQuery::Nearest}});
    fill.read(s);
    sensors.read(s);
    s.finish();
    validateIn(s, *this);
}

void CMultiBinElevationMap::TInsertionOptions::saveToConfigFile(mrpt::config::CConfigFileBase& c,
                                                                const std::string& section) const {
    c.write(section, "certainty_increment", certainty_increment);
    c.write(section, "max_elevation_uncertainty_m", max_elevation_uncertainty_m);
    c.write(section, "height_sigma_floor_m", height_sigma_floor_m);
    std::ostringstream sig;
    sig.precision(17);
    for (size_t i = 0; i < default_pose_sigmas.size(); i++)
        sig << (i ? " " : "") << default_pose_sigmas[i];
    c.write(section, "default_pose_sigmas", sig.str());
    c.write(section, "robot_pose_max_dt_s", robot_pose_max_dt_s);
    c.write(section, "range_sigma_m", range_sigma_m);
    c.write(section, "min_range_m", min_range_m);
    c.write(section, "max_range_m", max_range_m);
    std::string labels;
    for (const auto& l : sensor_labels) labels += (labels.empty() ? "" : ",") + l;
    c.write(section, "sensor_labels", labels);
    std::string globalLabels;
    for (const auto& l : global_sensor_labels)
        globalLabels += (globalLabels.empty() ? "" : ",") + l;
    c.write(section, "global_sensor_labels", globalLabels);
    c.write(section, "colormap", std::string(colormapName(colormap)));
    c.write(section, "color_by_sigma", color_by_sigma);
    visibility.write(c, section);
    c.write(section, "dem_return_filled", dem_return_filled);
    c.write(section, "relief_sigma", relief_sigma);
    c.write(section, "height_query",
            std::string(height_query == HeightQuery::Plane ? "plane" : "nearest"));
    fill.write(c, section);
    sensors.write(c, section);
}

void CMultiBinElevationMap::TInsertionOptions::validate() const {
    auto bad = [](const std::string& key, const std::string& what) {
        throw std::invalid_argument("CMultiBinElevationMap insertion option '" + key +
                                    "': " + what);
    };
    const auto finite = [](double v) { return std::isfinite(v); };
    if (!(certainty_increment > 0) || !finite(certainty_increment))
        bad("certainty_increment", "must be positive and finite");
    if (!(max_elevation_uncertainty_m > 0) || !finite(max_elevation_uncertainty_m))
        bad("max_elevation_uncertainty_m", "must be positive and finite [m]");
    if (!(height_sigma_floor_m >= 0) || !finite(height_sigma_floor_m))
        bad("height_sigma_floor_m", "must be >= 0 and finite [m]");
    if (default_pose_sigmas.size() != 6)
        bad("default_pose_sigmas",
            "needs 6 values, has " + std::to_string(default_pose_sigmas.size()));
    for (double v : default_pose_sigmas)
        if (!(v >= 0) || !finite(v)) bad("default_pose_sigmas", "values must be >= 0 and finite");
    if (!(robot_pose_max_dt_s >= 0)) bad("robot_pose_max_dt_s", "must be >= 0 [s]");
    if (!(range_sigma_m > 0) || !finite(range_sigma_m))
        bad("range_sigma_m", "must be positive and finite [m]");
    visibility.validate();
    fill.validate();
    if (!(min_range_m >= 0 && max_range_m > min_range_m))
        bad("min_range_m/max_range_m", "need 0 <= min_range_m < max_range_m");
    sensors.validate();
}

mrpt::math::CMatrixDouble66 CMultiBinElevationMap::TInsertionOptions::defaultPoseCovariance()
    const {
    mrpt::math::CMatrixDouble66 C;
    C.setZero();
    for (int i = 0; i < 6; i++)
        C(i, i) = default_pose_sigmas[size_t(i)] * default_pose_sigmas[size_t(i)];
    return C;
}

// ---------------------------------------------------------------------------------------------
// Map definition (CMultiMetricMap ini files)
// ---------------------------------------------------------------------------------------------
CMultiBinElevationMap::TMapDefinition::TMapDefinition() = default;

void CMultiBinElevationMap::TMapDefinition::loadFromConfigFile_map_specific(
    const mrpt::config::CConfigFileBase& source, const std::string& sectionNamePrefix) {
    checkMapSections(source, sectionNamePrefix);
    creationOpts.loadFromConfigFile(source, sectionNamePrefix + "_creationOpts");
    insertionOpts.loadFromConfigFile(source, sectionNamePrefix + "_insertOpts");
}

void CMultiBinElevationMap::TMapDefinition::dumpToTextStream_map_specific(std::ostream& out) const {
    creationOpts.dumpToTextStream(out);
    insertionOpts.dumpToTextStream(out);
}

mrpt::maps::CMetricMap* CMultiBinElevationMap::internal_CreateFromMapDefinition(
    const mrpt::maps::TMetricMapInitializer& _def) {
    const auto& def = dynamic_cast<const CMultiBinElevationMap::TMapDefinition&>(_def);
    auto* obj = new CMultiBinElevationMap(def.creationOpts);
    obj->insertionOptions = def.insertionOpts;
    return obj;
}

// ---------------------------------------------------------------------------------------------
// Construction, queries
// ---------------------------------------------------------------------------------------------
CMultiBinElevationMap::CMultiBinElevationMap() : m_impl(std::make_unique<Impl>()) {
    setCreationOptions(TCreationOptions());
}

CMultiBinElevationMap::CMultiBinElevationMap(const TCreationOptions& creation)
    : m_impl(std::make_unique<Impl>()) {
    setCreationOptions(creation);
}

CMultiBinElevationMap::CMultiBinElevationMap(const CMultiBinElevationMap& other)
    : CMetricMap(other),
      CHeightGridMap2D_Base(other),
      creationOptions(other.creationOptions),
      insertionOptions(other.insertionOptions),
      m_impl(std::make_unique<Impl>(*other.m_impl)) {}

CMultiBinElevationMap& CMultiBinElevationMap::operator=(const CMultiBinElevationMap& other) {
    if (this == &other) return *this;
    CMetricMap::operator=(other);
    CHeightGridMap2D_Base::operator=(other);
    creationOptions = other.creationOptions;
    insertionOptions = other.insertionOptions;
    *m_impl = *other.m_impl;
    return *this;
}

CMultiBinElevationMap::~CMultiBinElevationMap() = default;

const multibin::BinGrid& CMultiBinElevationMap::grid() const { return m_impl->grid; }
const multibin::BinGrid& CMultiBinElevationMap::localGrid() const { return m_impl->local; }
bool CMultiBinElevationMap::fillIsStale() const { return m_impl->fillStale; }
const multibin::fill::FillResult& CMultiBinElevationMap::lastFill() const { return m_impl->fill; }
const multibin::InsertStats& CMultiBinElevationMap::insertStats() const { return m_impl->stats; }
const multibin::VisibilityStats& CMultiBinElevationMap::visibilityStats() const {
    return m_impl->visibilityStats;
}
size_t CMultiBinElevationMap::poseFallbackCount() const { return m_impl->poseFallbacks; }
size_t CMultiBinElevationMap::skippedByLabelCount() const { return m_impl->skippedByLabel; }
const multibin::sensors::SensorModelStats& CMultiBinElevationMap::sensorModelStats() const {
    return m_impl->sensorState.stats;
}

void CMultiBinElevationMap::setCreationOptions(const TCreationOptions& creation) {
    const multibin::MapLock::Exclusive lock(m_impl->lock);
    creation.validate();
    creationOptions = creation;
    internal_clear();
}

void CMultiBinElevationMap::internal_clear() {
    const multibin::MapLock::Exclusive lock(m_impl->lock);
    const auto& c = creationOptions;
    multibin::CellWindow w;
    const double res = c.resolution_m;
    if (c.max_x > c.min_x && c.max_y > c.min_y) {
        w.ix0 = static_cast<int>(std::floor(c.min_x / res));
        w.iy0 = static_cast<int>(std::floor(c.min_y / res));
        w.nx = static_cast<int>(std::ceil(c.max_x / res)) - w.ix0;
        w.ny = static_cast<int>(std::ceil(c.max_y / res)) - w.iy0;
    }
    if (c.dual_grid) {
        // Robot-centred windows, placed by recenter() at the first observation.
        auto side = [](double size_m, double res_m) {
            return std::max(1, static_cast<int>(std::lround(size_m / res_m)));
        };
        const int nl = side(c.local_size_m, c.local_resolution_m);
        const int ng = side(c.global_size_m, c.global_resolution_m);
        m_impl->local.reset(c.local_resolution_m, multibin::CellWindow{-nl / 2, -nl / 2, nl, nl});
        m_impl->grid.reset(c.global_resolution_m, multibin::CellWindow{-ng / 2, -ng / 2, ng, ng});
    } else {
        m_impl->grid.reset(res, w);
        m_impl->local.reset(res, multibin::CellWindow{});
    }
    m_impl->stats = {};
    m_impl->visibilityStats = {};
    m_impl->poseFallbacks = 0;
    m_impl->skippedByLabel = 0;
    m_impl->lastRobotPose.reset();
    m_impl->sensorState.reset();
    m_impl->fill = {};
    m_impl->fillWindow = {};
    m_impl->fillStale = true;
}

multibin::BinUpdateParams CMultiBinElevationMap::binUpdateParams() const {
    multibin::BinUpdateParams p;
    p.binHeight_m = creationOptions.bin_height_m;
    p.certaintyIncrement = insertionOptions.certainty_increment;
    p.maxElevationUncertainty_m = insertionOptions.max_elevation_uncertainty_m;
    p.varianceFloor_m2 =
        insertionOptions.height_sigma_floor_m * insertionOptions.height_sigma_floor_m;
    return p;
}

bool CMultiBinElevationMap::getHeight(double x_m, double y_m, double& height_m,
                                      double& sigma_m) const {
    return insertionOptions.height_query == TInsertionOptions::HeightQuery::Plane
               ? heightAt(x_m, y_m, height_m, sigma_m)
               : cellHeight(x_m, y_m, height_m, sigma_m);
}

namespace {
/** Height and sigma from one of CellSurface.h's estimators (heightAt or surfaceAt). */
using SurfaceEstimator = bool (*)(const multibin::BinGrid&, const multibin::BinGrid*, double,
                                  double, const multibin::BinUpdateParams&, bool,
                                  multibin::CellSurface&);
bool answer(SurfaceEstimator estimate, const multibin::BinGrid& grid,
            const multibin::BinGrid* local, double x_m, double y_m,
            const multibin::BinUpdateParams& p, bool reliefSigma, double& height_m,
            double& sigma_m) {
    multibin::CellSurface c;
    if (!estimate(grid, local, x_m, y_m, p, reliefSigma, c)) return false;
    height_m = c.height_m;
    sigma_m = std::sqrt(c.variance_m2);
    return true;
}
}  // namespace

bool CMultiBinElevationMap::heightAt(double x_m, double y_m, double& height_m,
                                     double& sigma_m) const {
    const multibin::MapLock::Shared lock(m_impl->lock);
    return answer(multibin::heightAt, m_impl->grid, isDualGrid() ? &m_impl->local : nullptr, x_m,
                  y_m, binUpdateParams(), insertionOptions.relief_sigma, height_m, sigma_m);
}

bool CMultiBinElevationMap::cellHeight(double x_m, double y_m, double& height_m,
                                       double& sigma_m) const {
    const multibin::MapLock::Shared lock(m_impl->lock);
    return answer(multibin::surfaceAt, m_impl->grid, isDualGrid() ? &m_impl->local : nullptr, x_m,
                  y_m, binUpdateParams(), insertionOptions.relief_sigma, height_m, sigma_m);
}

bool CMultiBinElevationMap::isEmpty() const {
    const multibin::MapLock::Shared lock(m_impl->lock);
    return m_impl->grid.empty() && m_impl->local.empty();
}

std::string CMultiBinElevationMap::asString() const {
    const multibin::MapLock::Shared lock(m_impl->lock);
    std::ostringstream os;
    os << "CMultiBinElevationMap: " << m_impl->grid.window().nx << " x " << m_impl->grid.window().ny
       << " cells of " << m_impl->grid.cellSize_m() << " m, x in [" << getXMin() << ", "
       << getXMax() << "], y in [" << getYMin() << ", " << getYMax() << "] m, "
       << m_impl->grid.binCount() << " bins of " << creationOptions.bin_height_m << " m";
    return os.str();
}

double CMultiBinElevationMap::getXMin() const {
    return m_impl->grid.window().ix0 * m_impl->grid.cellSize_m();
}
double CMultiBinElevationMap::getXMax() const {
    return (m_impl->grid.window().ix0 + m_impl->grid.window().nx) * m_impl->grid.cellSize_m();
}
double CMultiBinElevationMap::getYMin() const {
    return m_impl->grid.window().iy0 * m_impl->grid.cellSize_m();
}
double CMultiBinElevationMap::getYMax() const {
    return (m_impl->grid.window().iy0 + m_impl->grid.window().ny) * m_impl->grid.cellSize_m();
}

float CMultiBinElevationMap::compute3DMatchingRatio(const mrpt::maps::CMetricMap*,
                                                    const mrpt::poses::CPose3D&,
                                                    const TMatchingRatioParams&) const {
    return 0;  // not a map used for registration
}

double CMultiBinElevationMap::internal_computeObservationLikelihood(
    const mrpt::obs::CObservation&, const mrpt::poses::CPose3D&) const {
    return 0;  // see internal_canComputeObservationLikelihood()
}

bool CMultiBinElevationMap::internal_canComputeObservationLikelihood(
    const mrpt::obs::CObservation&) const {
    return false;  // a terrain map, not a localisation map: no likelihood model
}

// ---------------------------------------------------------------------------------------------
// DEM interface
// ---------------------------------------------------------------------------------------------
bool CMultiBinElevationMap::insertIndividualPoint(const double x, const double y, const double z,
                                                  const TPointInsertParams& params) {
    const multibin::MapLock::Exclusive lock(m_impl->lock);
    creationOptions.validate();
    insertionOptions.validate();
    const double sigma = params.pt_z_std > 0 ? params.pt_z_std : insertionOptions.range_sigma_m;
    multibin::PointsWithCov pts(1);
    pts[0].point_m = Eigen::Vector3f(float(x), float(y), float(z));
    // Horizontal position taken as exact to the cell; only the height variance matters here.
    const float tiny = static_cast<float>(1e-12);
    pts[0].cov_m2 = {tiny, 0, 0, tiny, 0, float(sigma * sigma)};
    growToCover(pts, Eigen::Vector3d(x, y, z));
    return insertPoints(pts).accepted == 1;
}

double CMultiBinElevationMap::dem_get_resolution() const { return m_impl->grid.cellSize_m(); }
size_t CMultiBinElevationMap::dem_get_size_x() const { return size_t(m_impl->grid.window().nx); }
size_t CMultiBinElevationMap::dem_get_size_y() const { return size_t(m_impl->grid.window().ny); }
