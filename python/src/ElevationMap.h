/* Part of the multibin elevation-mapping library: the Python module.
 * multibin.ElevationMap: a CMultiBinElevationMap with numpy in and out. Each method takes and
 * returns Python objects, checks them (ArrayInput.h) while holding the GIL, and releases the GIL
 * while the map works, so a Python thread can query while another inserts: the map's own
 * reader-writer lock keeps them apart. */
#pragma once

#include <mrpt/maps/CMultiBinElevationMap.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <memory>
#include <optional>
#include <string>

namespace multibin::python {

class ElevationMap {
public:
    /** The map an ini file defines (as elevation-mapper reads it: `section` lists the maps),
     * or the defaults without one; `options` then sets keys of its creation and insertion
     * sections by their unit-suffixed names (doc/options.md). */
    static ElevationMap create(const std::optional<std::string>& iniPath,
                               const std::string& section, const pybind11::dict& options);
    /** A map serialized by save() or by elevation-mapper (elevation_map.bin, gz or plain). */
    static ElevationMap load(const std::string& path);
    /** Writes the serialized map (gz), whole or not at all (temporary file, then rename). */
    void save(const std::string& path) const;

    /** Points Nx3 [m, pose frame] with covariances Nx3x3 [m^2]: one update cycle; with a sensor
     * origin (3 [m]) the visibility constraint follows. Returns the point counts. */
    pybind11::dict insertPoints(const pybind11::handle& points, const pybind11::handle& covariances,
                                const pybind11::object& sensorOrigin);
    /** Points Nx3 in the sensor frame with their sensor-frame covariances, propagated through
     * the sensor pose on the robot and the robot pose PDF (6-vectors x, y, z, yaw, pitch, roll
     * and its 6x6 covariance): C = J_R C_R J_R^T + J_S C_S J_S^T. */
    pybind11::dict insertSensorPoints(const pybind11::handle& points,
                                      const pybind11::handle& covariances,
                                      const pybind11::handle& sensorPose,
                                      const pybind11::handle& robotPose,
                                      const pybind11::handle& robotPoseCov);

    /** (height, sigma, source) arrays of x's shape; NaN and 0 where unknown (queryHeight). */
    pybind11::tuple height(const pybind11::handle& x, const pybind11::handle& y) const;
    /** The rasters (height, sigma, certainty, source) and their lattice. */
    pybind11::dict layers() const;
    /** Gap filling (dem_update_map); returns its cell counts. */
    pybind11::dict fill();

    /** Maps a rawlog / simplemap as elevation-mapper does; returns its counts (FileMapping.cpp). */
    pybind11::dict mapRawlog(const std::string& path);
    pybind11::dict mapSimplemap(const std::string& path);

    /** Cell size [m], map origin (x, y) [m] and the window's extent (xmin, xmax, ymin, ymax). */
    double resolution_m() const;
    pybind11::tuple origin_m() const;
    pybind11::tuple extent_m() const;
    /** The map's point counts since it was created or loaded. */
    pybind11::dict insertStats() const;
    std::string describe() const;

    const mrpt::maps::CMultiBinElevationMap& map() const { return *m_map; }

private:
    explicit ElevationMap(std::shared_ptr<mrpt::maps::CMultiBinElevationMap> map);
    /** Before the first insertion of data at (x, y) [m]: an automatic origin is fixed near it, as
     * insertObservation does, so georeferenced points keep their precision. */
    void fixOriginNear(double x_m, double y_m);
    /** Grows the window to cover map-frame points seen from `sensor_m`, then inserts them. */
    pybind11::dict growAndInsert(const PointsWithCov& mapPoints, const Eigen::Vector3d& sensor_m,
                                 bool haveSensor, const PoseVariances* pose);

    std::shared_ptr<mrpt::maps::CMultiBinElevationMap> m_map;  //!< never null
};

/** The counts of InsertStats as a dict (one place for their Python names). */
pybind11::dict insertStatsDict(const InsertStats& s);

}  // namespace multibin::python
