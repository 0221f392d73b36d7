/* Part of the multibin elevation-mapping library.
 *
 * elevation-mapper: builds a CMultiBinElevationMap from a rawlog or a simplemap and writes the
 * serialized map, images, rasters, a mesh and a .3Dscene; with --ground-truth it also evaluates
 * the map side by side with its baselines and MRPT's height maps (report.json and figures).
 *
 *   elevation-mapper --config INI (--rawlog FILE | --simplemap FILE) --out DIR
 *                    [--ground-truth GT.asc [--with-mrf] [--profile x0,y0,x1,y1]
 *                     [--eval-area xmin,xmax,ymin,ymax]] [--no-plots]
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
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "EvaluationRun.h"
#include "ProgressBar.h"
#include "RawlogSource.h"
#include "multibin/fill/HeightRaster.h"
#include "multibin/io/ErrorMessage.h"
#include "multibin/io/NumberText.h"

namespace fs = std::filesystem;
using mrpt::maps::CMultiBinElevationMap;

namespace {

constexpr const char* kMapsSection = "MappingApplication";

struct Arguments {
    std::string config, rawlog, simplemap, out, groundTruth, profile, evalArea;
    bool withMrf = false, plots = true;
    bool usedDefaults = false;
};

void printUsage() {
    std::cout
        << "Usage: elevation-mapper --config INI (--rawlog FILE | --simplemap FILE) --out DIR\n"
           "                        [--ground-truth GT.asc [--with-mrf] [--profile x0,y0,x1,y1]\n"
           "                         [--eval-area xmin,xmax,ymin,ymax]] [--no-plots]\n"
           "       elevation-mapper            (runs on the shipped default data)\n\n"
           "Builds a multi-bin elevation map (gaps filled) and writes to DIR: elevation_map.bin\n"
           "(serialized map, gz), elevation_height.png, elevation_sigma.png, ESRI ASCII rasters\n"
           "elevation_{height,sigma,certainty,source}.asc, elevation_height.tif (float32 TIFF),\n"
           "elevation.ply (mesh) and elevation.3Dscene.\n"
           "With --ground-truth it evaluates raw, laser_only, multibin, multibin_filled and\n"
           "mrpt_height_grid (and mrpt_height_grid_mrf with --with-mrf, on a crop of 35 x 35\n"
           "cells) over the truth's area (or the part of it inside --eval-area [m]) and writes\n"
           "report.json, profile.csv and, unless\n"
           "--no-plots, figures drawn by matplotlib (fig_pi.png, fig_profile.png, layers.png).\n"
           "The ini file lists the maps in section ["
        << kMapsSection
        << "], as observations2map\n"
           "reads them (multiBinElevationMap_count = 1, ...).\n";
}

Arguments parseArguments(int argc, char** argv) {
    Arguments a;
    if (argc == 1) {
        const fs::path src = MULTIBIN_SOURCE_DIR;
        a.config = (src / "ini" / "mockup.ini").string();
        a.rawlog = (src / "rawlogs" / "mockup.rawlog").string();
        a.groundTruth = (src / "rawlogs" / "mockup_gt.asc").string();
        a.out = "elevation-mapper-out";
        a.usedDefaults = true;
        return a;
    }
    std::map<std::string, std::string*> flags{{"--config", &a.config},
                                              {"--rawlog", &a.rawlog},
                                              {"--simplemap", &a.simplemap},
                                              {"--out", &a.out},
                                              {"--ground-truth", &a.groundTruth},
                                              {"--profile", &a.profile},
                                              {"--eval-area", &a.evalArea}};
    for (int i = 1; i < argc; i++) {
        const std::string arg = argv[i];
        if (arg == "-h" || arg == "--help") {
            printUsage();
            std::exit(0);
        }
        if (arg == "--with-mrf") {
            a.withMrf = true;
            continue;
        }
        if (arg == "--no-plots") {
            a.plots = false;
            continue;
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
    if (a.groundTruth.empty() && (a.withMrf || !a.profile.empty() || !a.evalArea.empty()))
        throw std::invalid_argument("--with-mrf, --profile and --eval-area need --ground-truth");
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

/** The matplotlib script that draws the figures: beside the sources, or installed. */
std::string plotScript() {
    for (const fs::path& p :
         {fs::path(MULTIBIN_SOURCE_DIR) / "apps/elevation-mapper/plot_report.py",
          fs::path(MULTIBIN_DATA_DIR) / "plot_report.py"})
        if (fs::exists(p)) return p.string();
    return {};
}

/** Draws the figures with Debian's python3-matplotlib; a missing plotter is a warning, not an
 * error (every number is in report.json and the rasters). */
void drawFigures(const fs::path& out) {
    const std::string script = plotScript();
    const std::string python = "/usr/bin/python3";
    if (script.empty() || !fs::exists(python)) {
        std::cerr << "elevation-mapper: warning: figures not drawn (needs " << python
                  << " with python3-matplotlib and plot_report.py)\n";
        return;
    }
    const std::string cmd = python + " '" + script + "' '" + out.string() + "'";
    std::cout.flush();
    if (std::system(cmd.c_str()) != 0)
        std::cerr << "elevation-mapper: warning: figures not drawn: '" << cmd << "' failed\n";
}

/** Four comma-separated numbers given to `flag` (e.g. "--profile"), or none for empty text. */
std::vector<double> parseFourNumbers(const std::string& flag, const std::string& text,
                                     const std::string& meaning) {
    std::vector<double> v;
    if (text.empty()) return v;
    std::string item;
    std::istringstream is(text);
    while (std::getline(is, item, ',')) {
        double x = 0;
        if (!multibin::parseFiniteNumber(item, x))
            throw std::invalid_argument(flag + ": '" + item + "' is not a number");
        v.push_back(x);
    }
    if (v.size() != 4) throw std::invalid_argument(flag + " needs " + meaning);
    return v;
}

int run(const Arguments& args) {
    if (!fs::exists(args.config))
        throw std::runtime_error("config '" + args.config + "' not found");
    if (fs::is_directory(args.config))
        throw std::runtime_error("config '" + args.config + "' is a directory, not a file");
    mrpt::config::CConfigFile ini(args.config);
    mrpt::maps::TSetOfMetricMapInitializers inits;
    inits.loadFromConfigFile(ini, kMapsSection);
    mrpt::maps::CMultiMetricMap maps(inits);
    const auto elevation = maps.mapByClass<CMultiBinElevationMap>();
    if (!elevation)
        throw std::runtime_error("config '" + args.config +
                                 "' defines no multiBinElevationMap in [" + kMapsSection + "]");

    std::unique_ptr<EvaluationRun> evaluation;
    if (!args.groundTruth.empty()) {
        EvaluationRun::Options eo;
        eo.groundTruthPath = args.groundTruth;
        eo.withMrf = args.withMrf;
        eo.profile_m = parseFourNumbers("--profile", args.profile, "x0,y0,x1,y1 [m]");
        eo.area_m = parseFourNumbers("--eval-area", args.evalArea, "xmin,xmax,ymin,ymax [m]");
        evaluation = std::make_unique<EvaluationRun>(eo, *elevation);
    }

    using Clock = std::chrono::steady_clock;
    double insert_s = 0;  // the multi-bin map's own insertion time
    auto insertTimed = [&](const mrpt::obs::CObservation& obs,
                           const mrpt::poses::CPose3DPDFGaussian& pose, bool poseHasCov) {
        const auto t0 = Clock::now();
        if (poseHasCov)
            elevation->insertObservation(obs, pose);
        else
            elevation->insertObservation(obs, pose.mean);
        insert_s += std::chrono::duration<double>(Clock::now() - t0).count();
        if (evaluation) evaluation->observe(obs, pose, poseHasCov);
    };
    ProgressBar bar("mapping");
    if (!args.rawlog.empty()) {
        RawlogSource::forEachInRawlog(
            args.rawlog,
            [&](const mrpt::obs::CObservation::Ptr& obs,
                const mrpt::poses::CPose3DPDFGaussian& pose, bool poseHasCov) {
                for (const auto& m : maps.maps) {
                    if (m.get() == elevation.get())
                        insertTimed(*obs, pose, poseHasCov);
                    else
                        m->insertObservation(*obs, pose.mean);
                }
            },
            [&](double f, size_t n) { bar.update(f, std::to_string(n) + " entries"); });
    } else {
        const mrpt::maps::CSimpleMap sm = RawlogSource::loadSimplemap(args.simplemap);
        for (const auto& m : maps.maps)
            if (m.get() != elevation.get()) m->loadFromSimpleMap(sm);
        CMultiBinElevationMap::forEachObservationWithPosePdf(
            sm,
            [&](const mrpt::obs::CObservation& obs, const mrpt::poses::CPose3DPDFGaussian& pdf) {
                insertTimed(obs, pdf, true);
            },
            [&](size_t done, size_t total) {
                bar.update(double(done) / double(total), std::to_string(done) + " keyframes");
            });
    }
    bar.finish("done");

    fs::create_directories(args.out);
    const fs::path out = args.out;
    elevation->flushLocalToGlobal();  // dual grid: the global grid holds the whole run
    const auto fill0 = Clock::now();
    elevation->dem_update_map();  // gap filling, once
    const double fill_s = std::chrono::duration<double>(Clock::now() - fill0).count();
    std::string table;
    if (evaluation) table = evaluation->finish(out.string(), insert_s, fill_s);
    {
        mrpt::io::CFileGZOutputStream f;
        if (!f.open((out / "elevation_map.bin").string()))
            throw std::runtime_error("cannot write '" + (out / "elevation_map.bin").string() + "'");
        auto arch = mrpt::serialization::archiveFrom(f);
        arch << *elevation;
    }
    elevation->saveMetricMapRepresentationToFile((out / "elevation").string());

    const auto& fs_ = elevation->lastFill().stats;
    std::cout << elevation->asString() << "\n"
              << insertSummary(elevation->insertStats()) << "\n"
              << "observations with the default pose covariance: " << elevation->poseFallbackCount()
              << "\n"
              << "cells filled: " << fs_.median << " by weighted median, " << fs_.gaussian
              << " by Gaussian surface (" << fs_.supportAreas << " support areas); " << fs_.unfilled
              << " left unknown\n"
              << "insertion time: " << insert_s << " s; fill time: " << fill_s << " s\n"
              << "wrote " << fs::absolute(out).string()
              << "/{elevation_map.bin, elevation_height.png, elevation_sigma.png, "
                 "elevation_*.asc, elevation_height.tif, elevation.ply, elevation.3Dscene}\n";
    if (evaluation) {
        std::cout << "\nEvaluation against " << args.groundTruth << " (report.json):\n" << table;
        if (args.plots) drawFigures(out);
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        const Arguments args = parseArguments(argc, argv);
        if (args.usedDefaults)
            std::cout << "No arguments: mapping the shipped mock-up scenario\n  --config "
                      << args.config << "\n  --rawlog " << args.rawlog << "\n  --ground-truth "
                      << args.groundTruth << "\n  --out " << args.out << "\n";
        return run(args);
    } catch (const std::exception& e) {
        std::cerr << "elevation-mapper: error: " << multibin::oneLineMessage(e) << "\n";
        return 1;
    }
}
