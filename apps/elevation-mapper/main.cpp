/* Part of the multibin elevation-mapping library.
 *
 * elevation-mapper: builds a CMultiBinElevationMap from a rawlog or a simplemap and writes the
 * serialized map, height and sigma images, an ESRI ASCII raster and a .3Dscene.
 *
 *   elevation-mapper --config INI (--rawlog FILE | --simplemap FILE) --out DIR
 *
 * The ini file has the maps in section [MappingApplication], as MRPT's observations2map reads
 * them, so one file serves both programs. With no arguments it runs on the shipped default data. */
#include <mrpt/config/CConfigFile.h>
#include <mrpt/img/CImage.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/maps/CMultiMetricMap.h>
#include <mrpt/serialization/CArchive.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <stdexcept>
#include <string>

#include "ProgressBar.h"
#include "RawlogSource.h"
#include "multibin/ErrorMessage.h"

namespace fs = std::filesystem;
using mrpt::maps::CMultiBinElevationMap;

namespace {

constexpr const char* kMapsSection = "MappingApplication";

struct Arguments {
    std::string config, rawlog, simplemap, out;
    bool usedDefaults = false;
};

void printUsage() {
    std::cout
        << "Usage: elevation-mapper --config INI (--rawlog FILE | --simplemap FILE) --out DIR\n"
           "       elevation-mapper            (runs on the shipped default data)\n\n"
           "Builds a multi-bin elevation map and writes to DIR: elevation_map.bin (serialized\n"
           "map, gz), elevation_height.png, elevation_sigma.png, elevation_height.asc and\n"
           "elevation_sigma.asc (ESRI ASCII rasters) and elevation.3Dscene.\n"
           "The ini file lists the maps in section ["
        << kMapsSection
        << "], as observations2map\n"
           "reads them (multiBinElevationMap_count = 1, ...).\n";
}

Arguments parseArguments(int argc, char** argv) {
    Arguments a;
    if (argc == 1) {
        const fs::path src = MULTIBIN_SOURCE_DIR;
        a.config = (src / "ini" / "depth-camera.ini").string();
        a.rawlog = (src / "rawlogs" / "mrpt_tests_rgbd.rawlog").string();
        a.out = "elevation-mapper-out";
        a.usedDefaults = true;
        return a;
    }
    std::map<std::string, std::string*> flags{{"--config", &a.config},
                                              {"--rawlog", &a.rawlog},
                                              {"--simplemap", &a.simplemap},
                                              {"--out", &a.out}};
    for (int i = 1; i < argc; i++) {
        const std::string arg = argv[i];
        if (arg == "-h" || arg == "--help") {
            printUsage();
            std::exit(0);
        }
        const auto it = flags.find(arg);
        if (it == flags.end()) throw std::invalid_argument("unknown argument '" + arg + "'");
        if (i + 1 >= argc) throw std::invalid_argument(arg + " needs a value");
        *it->second = argv[++i];
    }
    if (a.config.empty()) throw std::invalid_argument("--config INI is required");
    if (a.rawlog.empty() == a.simplemap.empty())
        throw std::invalid_argument("give exactly one of --rawlog FILE and --simplemap FILE");
    if (a.out.empty()) throw std::invalid_argument("--out DIR is required");
    return a;
}

std::string insertSummary(const multibin::InsertStats& s) {
    char buf[512];
    std::snprintf(buf, sizeof buf,
                  "points fused: %zu; rejected: %zu (range %zu, non-finite %zu, covariance %zu, "
                  "outside map %zu, bin range %zu, eq 13 gate %zu, eq 14 gate %zu)",
                  s.accepted, s.rejected(), s.outOfRange, s.notFinite, s.badCovariance,
                  s.outsideMap, s.outsideBinRange, s.tooUncertain, s.continuityRejected);
    return buf;
}

int run(const Arguments& args) {
    if (!fs::exists(args.config))
        throw std::runtime_error("config '" + args.config + "' not found");
    mrpt::config::CConfigFile ini(args.config);
    mrpt::maps::TSetOfMetricMapInitializers inits;
    inits.loadFromConfigFile(ini, kMapsSection);
    mrpt::maps::CMultiMetricMap maps(inits);
    const auto elevation = maps.mapByClass<CMultiBinElevationMap>();
    if (!elevation)
        throw std::runtime_error("config '" + args.config +
                                 "' defines no multiBinElevationMap in [" + kMapsSection + "]");

    const auto t0 = std::chrono::steady_clock::now();
    ProgressBar bar("mapping");
    if (!args.rawlog.empty()) {
        RawlogSource::forEachInRawlog(
            args.rawlog,
            [&](const mrpt::obs::CObservation::Ptr& obs,
                const mrpt::poses::CPose3DPDFGaussian& pose, bool poseHasCov) {
                for (const auto& m : maps.maps) {
                    if (m.get() == elevation.get()) {
                        if (poseHasCov)
                            elevation->insertObservation(*obs, pose);
                        else
                            elevation->insertObservation(*obs, pose.mean);
                    } else {
                        m->insertObservation(*obs, pose.mean);
                    }
                }
            },
            [&](double f, size_t n) { bar.update(f, std::to_string(n) + " entries"); });
    } else {
        const mrpt::maps::CSimpleMap sm = RawlogSource::loadSimplemap(args.simplemap);
        for (const auto& m : maps.maps)
            if (m.get() != elevation.get()) m->loadFromSimpleMap(sm);
        elevation->insertSimpleMapWithPosePdfs(sm, [&](size_t done, size_t total) {
            bar.update(double(done) / double(total), std::to_string(done) + " keyframes");
        });
    }
    elevation->dem_update_map();
    const double insert_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    bar.finish("done");

    fs::create_directories(args.out);
    const fs::path out = args.out;
    {
        mrpt::io::CFileGZOutputStream f;
        if (!f.open((out / "elevation_map.bin").string()))
            throw std::runtime_error("cannot write '" + (out / "elevation_map.bin").string() + "'");
        auto arch = mrpt::serialization::archiveFrom(f);
        arch << *elevation;
    }
    elevation->saveMetricMapRepresentationToFile((out / "elevation").string());

    std::cout << elevation->asString() << "\n"
              << insertSummary(elevation->insertStats()) << "\n"
              << "observations with the default pose covariance: " << elevation->poseFallbackCount()
              << "\n"
              << "insertion time: " << insert_s << " s\n"
              << "wrote " << fs::absolute(out).string()
              << "/{elevation_map.bin, elevation_height.png, elevation_sigma.png, "
                 "elevation_height.asc, elevation_sigma.asc, elevation.3Dscene}\n";
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        const Arguments args = parseArguments(argc, argv);
        if (args.usedDefaults)
            std::cout << "No arguments: mapping the shipped default data\n  --config "
                      << args.config << "\n  --rawlog " << args.rawlog << "\n  --out " << args.out
                      << "\n";
        return run(args);
    } catch (const std::exception& e) {
        std::cerr << "elevation-mapper: error: " << multibin::oneLineMessage(e) << "\n";
        return 1;
    }
}
