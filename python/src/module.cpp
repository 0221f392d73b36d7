/* Part of the multibin elevation-mapping library: the Python module `multibin`.
 * The Python names, signatures and docstrings; the work is in ElevationMap.cpp and
 * FileMapping.cpp. C++ errors become Python exceptions with the library's one-line message:
 * std::invalid_argument -> ValueError, other errors -> RuntimeError, a wrong dtype -> TypeError. */
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <stdexcept>

#include "ElevationMap.h"
#include "multibin/io/ErrorMessage.h"

namespace py = pybind11;
using multibin::python::ElevationMap;

PYBIND11_MODULE(multibin, m) {
    m.doc() =
        "Multi-bin terrain elevation maps (Belter, Labecki, Skrzypczynski, ROBIO 2012) from "
        "Python: numpy in and out. See doc/python.md.";
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const py::builtin_exception&) {
            throw;  // pybind11's own (TypeError, ...): its translator
        } catch (const py::error_already_set&) {
            throw;
        } catch (const std::invalid_argument& e) {
            PyErr_SetString(PyExc_ValueError, multibin::oneLineMessage(e).c_str());
        } catch (const std::exception& e) {
            PyErr_SetString(PyExc_RuntimeError, multibin::oneLineMessage(e).c_str());
        }
    });

    // HeightSource as returned in height()'s and layers()' source arrays.
    m.attr("SOURCE_UNKNOWN") = int(multibin::HeightSource::Unknown);
    m.attr("SOURCE_MEASURED") = int(multibin::HeightSource::Measured);
    m.attr("SOURCE_FILLED_MEDIAN") = int(multibin::HeightSource::FilledMedian);
    m.attr("SOURCE_FILLED_SURFACE") = int(multibin::HeightSource::FilledSurface);
    m.attr("SOURCE_FILLED_HARMONIC") = int(multibin::HeightSource::FilledHarmonic);

    py::class_<ElevationMap>(m, "ElevationMap",
                             "A CMultiBinElevationMap. Every x, y is in the frame of the robot "
                             "poses [m]; heights and sigmas [m]. One writer and any number of "
                             "readers may share a map across Python threads: the methods release "
                             "the GIL and the map's reader-writer lock orders them.")
        .def(py::init([](const std::optional<std::string>& ini_path, const std::string& section,
                         const py::kwargs& options) {
                 return ElevationMap::create(ini_path, section, options);
             }),
             py::arg("ini_path") = py::none(), py::arg("section") = "MappingApplication",
             "A map defined in an ini file as elevation-mapper reads it (`section` lists the "
             "maps; the map's keys in SECTION_multiBinElevationMap_00_creationOpts / "
             "_insertOpts), or the defaults; keyword options set keys of those sections by "
             "their unit-suffixed names (doc/options.md), e.g. resolution_m=0.05. Raises "
             "ValueError naming the key for an unknown key or a bad value.")
        .def_static("load", &ElevationMap::load, py::arg("path"),
                    "A map saved by save() or by elevation-mapper (elevation_map.bin).")
        .def("save", &ElevationMap::save, py::arg("path"),
             "Writes the serialized map (gz), as elevation-mapper's elevation_map.bin.")
        .def("insert_points", &ElevationMap::insertPoints, py::arg("points"),
             py::arg("covariances"), py::arg("sensor_origin") = py::none(),
             "Fuses points (N, 3) [m] with their covariances (N, 3, 3) [m^2], both in the map "
             "(pose) frame, as one update cycle; the map grows to cover them. With sensor_origin "
             "(3,) [m] the visibility constraint follows. Returns the point counts (dict).")
        .def("insert_sensor_points", &ElevationMap::insertSensorPoints, py::arg("points"),
             py::arg("covariances"), py::arg("sensor_pose"), py::arg("robot_pose"),
             py::arg("robot_pose_cov"),
             "Fuses points (N, 3) measured in a sensor frame with their sensor-frame covariances "
             "(N, 3, 3): sensor_pose on the robot and robot_pose in the map are (x, y, z, yaw, "
             "pitch, roll) [m, rad], robot_pose_cov its (6, 6) covariance; each point's map-frame "
             "covariance is J_R C_R J_R^T + J_S C_S J_S^T. Returns the point counts (dict).")
        .def("height", &ElevationMap::height, py::arg("x"), py::arg("y"),
             "(height, sigma, source) at the points (x, y) [m], arrays of x's shape: the sub-cell "
             "surface where measured, else the last fill()'s value; NaN and SOURCE_UNKNOWN where "
             "the map knows nothing.")
        .def("layers", &ElevationMap::layers,
             "The map's rasters over its window: 'height', 'sigma' [m] and 'certainty' (float32, "
             "NaN where unknown), 'source' (uint8), row 0 the southernmost; 'origin' (x, y) of the "
             "lower-left corner [m], 'cell_size' [m] and 'extent' (xmin, xmax, ymin, ymax) for "
             "matplotlib's imshow(layer, origin='lower', extent=extent).")
        .def("fill", &ElevationMap::fill,
             "Fills the gaps (weighted median, Gaussian surface / kriging, harmonic); returns the "
             "cell counts. height() and layers() then answer the filled cells.")
        .def("map_rawlog", &ElevationMap::mapRawlog, py::arg("path"),
             "Inserts every observation of a rawlog with its robot pose PDF, as elevation-mapper "
             "does; returns its counts: 'entries', 'observations', 'by_class' (per observation "
             "class), 'points' (the map's point counts), 'default_pose_covariance' and the "
             "printed 'report'. Raises RuntimeError if no point was fused, saying why.")
        .def("map_simplemap", &ElevationMap::mapSimplemap, py::arg("path"),
             "The same for a simplemap (each keyframe's pose PDF); 'entries' counts keyframes.")
        .def_property_readonly("resolution_m", &ElevationMap::resolution_m, "cell size [m]")
        .def_property_readonly("origin_m", &ElevationMap::origin_m,
                               "the map origin (x, y) [m] the map's geometry is relative to")
        .def_property_readonly("extent_m", &ElevationMap::extent_m,
                               "the grid window (xmin, xmax, ymin, ymax) [m]")
        .def_property_readonly("insert_stats", &ElevationMap::insertStats,
                               "the map's point counts since it was created or loaded")
        .def("__repr__", &ElevationMap::describe);
}
