/* Part of the multibin elevation-mapping library. */
// mrpt::maps::CMultiBinElevationMap: its options (creation, insertion, the map definition MRPT's
// CMultiMetricMap builds from an ini file), each key listed once (the options protocol,
// multibin/io/OptionKeys.h), and the checks of the map's ini sections.
#include <mrpt/config/CConfigFile.h>
#include "CMultiBinElevationMap_impl.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "multibin/io/OptionKeys.h"

using namespace mrpt::maps;
using multibin::atLeast;
using multibin::between;
using multibin::finite;
using multibin::OptionNames;
using multibin::positive;

namespace {
// Keys MRPT itself puts in every `_creationOpts` section (TMapGenericParams).
const std::vector<std::string> kGenericMapKeys = {
    "enableSaveAs3DObject", "enableObservationLikelihood", "enableObservationInsertion"};
/** Creation keys of earlier versions, accepted with a message: `max_size_m` capped the growing
 * window before the storage was tiled. */
constexpr const char* kRetiredCreationKeys[] = {"max_size_m"};

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
    // The parent section too holds each key once (the map count given twice is an error).
    multibin::StrictConfigSection{source, parent};
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
            for (const char* part : {"_creationOpts", "_insertOpts", "_traversabilityOpts"})
                known = known || sec == parent + tag + nn + part;
        }
        if (!known)
            throw std::invalid_argument(
                iniName(source) + ", section '" + sec + "': unknown section (this map reads '" +
                parent + tag + "NN_creationOpts', '" + parent + tag + "NN_insertOpts' and '" +
                parent + tag + "NN_traversabilityOpts', NN from 00 to " +
                std::to_string(count - 1) + ")");
    }
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Options
// ---------------------------------------------------------------------------------------------
namespace {
/** Largest map origin [m]: beyond any projected coordinate system (UTM northings stay below 1e7
 * m); a double still resolves 15 nm there. */
constexpr double kMaxOrigin_m = 1e8;

/** Cell sizes: from 0.1 mm (the growth limit, BinStore::kGrowthLimitCells cells, then still
 * reaches 26 km from the map origin) to 1 km. */
multibin::OptionRule cellSizeRule() { return multibin::between(1e-4, 1e3, "m"); }

/** The creation keys of `o` (a TCreationOptions or a const one), in the order they are written,
 * for the options protocol (multibin/io/OptionKeys.h). */
template <class Options, class Visit>
void visitCreationKeys(Options& o, Visit&& visit) {
    visit({"resolution_m", "resolution"}, o.resolution_m, cellSizeRule());
    visit({"bin_height_m", "bin_height"}, o.bin_height_m, positive("m"));
    visit("grow", o.grow);
    visit({"min_x_m", "min_x"}, o.min_x, finite("m"));
    visit({"max_x_m", "max_x"}, o.max_x, finite("m"));
    visit({"min_y_m", "min_y"}, o.min_y, finite("m"));
    visit({"max_y_m", "max_y"}, o.max_y, finite("m"));
    visit("dual_grid", o.dual_grid);
    visit("local_size_m", o.local_size_m, positive("m"));
    visit({"local_resolution_m", "local_resolution"}, o.local_resolution_m, cellSizeRule());
    visit("global_size_m", o.global_size_m, positive("m"));
    visit({"global_resolution_m", "global_resolution"}, o.global_resolution_m, cellSizeRule());
    visit("origin_auto", o.origin_auto);
    visit("origin_x_m", o.origin_x_m, between(-kMaxOrigin_m, kMaxOrigin_m, "m"));
    visit("origin_y_m", o.origin_y_m, between(-kMaxOrigin_m, kMaxOrigin_m, "m"));
    visit("memory_budget_mb", o.memory_budget_mb, atLeast(0, "MB"));
    visit("tile_store_dir", o.tile_store_dir);
}

using HeightQuery = CMultiBinElevationMap::TInsertionOptions::TQueryOptions::HeightQuery;
const OptionNames<HeightQuery> kHeightQueries{{"plane", HeightQuery::Plane},
                                              {"nearest", HeightQuery::Nearest}};

const OptionNames<mrpt::img::TColormap> kColormaps{
    {"jet", mrpt::img::cmJET}, {"hot", mrpt::img::cmHOT}, {"grayscale", mrpt::img::cmGRAYSCALE}};

/** The insertion keys of `o` (a TInsertionOptions or a const one) with those of its visibility,
 * fill and sensor-model parts, in the order they are written. */
template <class Options, class Visit>
void visitInsertionKeys(Options& o, Visit&& visit) {
    visit("certainty_increment", o.certainty_increment, positive());
    visit({"max_elevation_uncertainty_m", "max_elevation_uncertainty"},
          o.max_elevation_uncertainty_m, positive("m"));
    visit({"height_sigma_floor_m", "height_sigma_floor"}, o.height_sigma_floor_m, atLeast(0, "m"));
    visit("default_pose_sigmas", o.default_pose_sigmas, atLeast(0));
    visit({"robot_pose_max_dt_s", "robot_pose_max_dt"}, o.robot_pose_max_dt_s, atLeast(0, "s"));
    visit({"range_sigma_m", "range_sigma"}, o.range_sigma_m, positive("m"));
    visit({"min_range_m", "min_range"}, o.min_range_m, atLeast(0, "m"));
    visit({"max_range_m", "max_range"}, o.max_range_m, positive("m"));
    visit("sensor_labels", o.sensor_labels);
    visit("global_sensor_labels", o.global_sensor_labels);
    visit("colormap", o.render.colormap, kColormaps);
    visit("color_by_sigma", o.render.color_by_sigma);
    visit("dem_return_filled", o.query.dem_return_filled);
    visit("relief_sigma", o.query.relief_sigma);
    visit("height_query", o.query.height_query, kHeightQueries);
    visit("insertion_threads", o.insertion_threads, between(1, 2));
}

}  // namespace

mrpt::math::TPoint2D CMultiBinElevationMap::TCreationOptions::originNear(double x_m,
                                                                         double y_m) const {
    const double cell_m = dual_grid ? global_resolution_m : resolution_m;
    // Clamped to the origin's range: data beyond it are beyond any map (and stay finite here).
    const auto snap = [&](double v) {
        const double km =
            std::clamp(std::round(v / 1000.0), -kMaxOrigin_m / 1000, kMaxOrigin_m / 1000);
        return std::round(km * 1000.0 / cell_m) * cell_m;
    };
    return {snap(x_m), snap(y_m)};
}

std::optional<mrpt::math::TPoint2D> CMultiBinElevationMap::TCreationOptions::originBeforeData()
    const {
    if (!origin_auto) return mrpt::math::TPoint2D(origin_x_m, origin_y_m);
    if (!dual_grid && max_x > min_x && max_y > min_y)
        return originNear(0.5 * (min_x + max_x), 0.5 * (min_y + max_y));
    return std::nullopt;
}

void CMultiBinElevationMap::TCreationOptions::loadFromConfigFile(
    const mrpt::config::CConfigFileBase& source, const std::string& section) {
    std::vector<std::string> allowed = kGenericMapKeys;
    for (const char* key : kRetiredCreationKeys)
        if (source.keyExists(section, key)) {
            std::cerr << "CMultiBinElevationMap: " << iniName(source) << ", section [" << section
                      << "]: key '" << key
                      << "' is no longer used and is ignored: the map is stored in tiles and "
                         "grows with the data, with no size limit. Remove the key.\n";
            allowed.push_back(key);
        }
    multibin::loadStrictly(
        source, section, *this,
        [&](multibin::StrictConfigSection& s) {
            visitCreationKeys(*this, multibin::OptionReader{s});
        },
        allowed);
}

void CMultiBinElevationMap::TCreationOptions::saveToConfigFile(mrpt::config::CConfigFileBase& c,
                                                               const std::string& section) const {
    visitCreationKeys(*this, multibin::OptionWriter{c, section});
}

namespace {
/** Largest cell index an option may produce: int with room for a window of 2^30 cells. */
constexpr double kMaxCellIndex = 1 << 30;
}  // namespace

void CMultiBinElevationMap::TCreationOptions::validate() const {
    const multibin::OptionChecker check("CMultiBinElevationMap creation option");
    visitCreationKeys(*this, check);
    const auto bad = [&](const std::string& key, const std::string& what) {
        check.fail(key, what);
    };
    const mrpt::math::TPoint2D origin = originBeforeData().value_or(mrpt::math::TPoint2D());
    for (const auto& [key, v, o] : {std::tuple{"min_x_m", min_x, origin.x},
                                    {"max_x_m", max_x, origin.x},
                                    {"min_y_m", min_y, origin.y},
                                    {"max_y_m", max_y, origin.y}}) {
        if (std::abs(v) > kMaxOrigin_m) {
            std::ostringstream os;
            os << v << " m is beyond the +-" << kMaxOrigin_m << " m of map coordinates (cell index "
               << v / resolution_m << " at " << resolution_m << " m cells)";
            bad(key, os.str());
        }
        // Cell indices are int: an extent far from the map origin would overflow them.
        if (std::abs((v - o) / resolution_m) > kMaxCellIndex) {
            std::ostringstream os;
            os << v << " m is cell index " << (v - o) / resolution_m << " from the map origin " << o
               << " m at " << resolution_m << " m cells, beyond the +-" << kMaxCellIndex
               << " the grid can index";
            bad(key, os.str());
        }
    }
    if (max_x < min_x || max_y < min_y)
        bad("min_x_m/max_x_m/min_y_m/max_y_m", "max must not be below min");
    if (!grow && (max_x <= min_x || max_y <= min_y))
        bad("grow", "a fixed extent (grow = false) needs min_x < max_x and min_y < max_y");
    // The local grid's window is filled densely as the robot sees it (16 bytes per cell: first
    // bin, cycle stamp, update index, height bound, then the bins): refuse one beyond memory.
    constexpr double kCellBytes = 16, kMaxCells = 2.0e8;  // 3.2 GB of cell slots
    auto checkArea = [&](const std::string& key, double side_m, double cell_m) {
        const double side_cells = side_m / cell_m;
        if (side_cells * side_cells <= kMaxCells) return;
        std::ostringstream os;
        os << "a grid of " << side_cells << " x " << side_cells << " cells (" << cell_m
           << " m cells) would need " << side_cells * side_cells * kCellBytes / 1e9
           << " GB for its cells alone; use a coarser resolution or a smaller size";
        bad(key, os.str());
    };
    if (dual_grid) checkArea("local_size_m", local_size_m, local_resolution_m);
}

void CMultiBinElevationMap::TInsertionOptions::loadFromConfigFile(
    const mrpt::config::CConfigFileBase& source, const std::string& section) {
    multibin::loadStrictly(source, section, *this, [&](multibin::StrictConfigSection& s) {
        visitInsertionKeys(*this, multibin::OptionReader{s});
        visibility.read(s);
        fill.read(s);
        sensors.read(s);
    });
}

void CMultiBinElevationMap::TInsertionOptions::saveToConfigFile(mrpt::config::CConfigFileBase& c,
                                                                const std::string& section) const {
    visitInsertionKeys(*this, multibin::OptionWriter{c, section});
    visibility.write(c, section);
    fill.write(c, section);
    sensors.write(c, section);
}

void CMultiBinElevationMap::TInsertionOptions::validate() const {
    const multibin::OptionChecker check("CMultiBinElevationMap insertion option");
    if (default_pose_sigmas.size() != 6)
        check.fail("default_pose_sigmas",
                   "needs 6 values, has " + std::to_string(default_pose_sigmas.size()));
    visitInsertionKeys(*this, check);
    visibility.validate();
    fill.validate();
    if (!(max_range_m > min_range_m))
        check.fail("min_range_m/max_range_m", "need 0 <= min_range_m < max_range_m");
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
    if (source.sectionExists(sectionNamePrefix + "_traversabilityOpts"))
        traversabilityOpts.loadFromConfigFile(source, sectionNamePrefix + "_traversabilityOpts");
}

void CMultiBinElevationMap::TMapDefinition::dumpToTextStream_map_specific(std::ostream& out) const {
    creationOpts.dumpToTextStream(out);
    insertionOpts.dumpToTextStream(out);
    out << "traversability: " << traversabilityOpts.text() << "\n";
}

mrpt::maps::CMetricMap* CMultiBinElevationMap::internal_CreateFromMapDefinition(
    const mrpt::maps::TMetricMapInitializer& _def) {
    const auto& def = dynamic_cast<const CMultiBinElevationMap::TMapDefinition&>(_def);
    auto* obj = new CMultiBinElevationMap(def.creationOpts);
    obj->insertionOptions = def.insertionOpts;
    obj->traversabilityOptions = def.traversabilityOpts;
    return obj;
}
