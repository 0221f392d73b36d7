/* Part of the multibin elevation-mapping library.
 *
 * elevation-mapper: builds a CMultiBinElevationMap from a rawlog or a simplemap and writes the
 * outputs chosen with --outputs (serialized map, GeoTIFF, .3Dscene, PNG previews; ESRI ASCII
 * rasters and a PLY mesh on request); with --ground-truth it also evaluates the map side by side
 * with its baselines and MRPT's height maps (report.json and figures). `--help` lists the options.
 *
 * The ini file has the maps in a section ([MappingApplication] unless --section), as MRPT's
 * observations2map reads them, so one file serves both programs. With no arguments it runs on the
 * shipped default data. */
#include <mrpt/config/CConfigFile.h>
#include <mrpt/img/CImage.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/maps/CMultiMetricMap.h>
#include <mrpt/serialization/CArchive.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <sys/stat.h>
#include <unistd.h>

#include "EvaluationRun.h"
#include "Figures.h"
#include "MapOutputs.h"
#include "ObservationTally.h"
#include "ProgressBar.h"
#include "RawlogSource.h"
#include "RunWarnings.h"
#include "multibin/fill/SparseFill.h"
#include "multibin/io/ErrorMessage.h"
#include "multibin/io/NumberText.h"
#include "multibin/io/OutputFile.h"
#include "multibin/map/MapStatistics.h"

namespace fs = std::filesystem;
using mrpt::maps::CMultiBinElevationMap;

namespace {

struct Arguments {
    std::string config, section = "MappingApplication", rawlog, simplemap,
                        out = "elevation-mapper-out", groundTruth, profile, evalArea,
                        outputs = OutputSelection::kDefault, sceneColour, exportResolution, epsg;
    bool withMrf = false, plots = true;
    bool usedDefaults = false;
};

void printUsage() {
    const Arguments d;
    std::cout
        << "Usage: elevation-mapper --config INI (--rawlog FILE | --simplemap FILE) [options]\n"
           "       elevation-mapper            (no arguments: maps the shipped mock-up scenario)\n"
           "\n"
           "Builds a multi-bin elevation map, fills its gaps and writes the chosen outputs.\n"
           "\n"
           "Input:\n"
           "  --config INI         ini file with the maps, as MRPT's observations2map reads it\n"
           "                       (multiBinElevationMap_count = 1, ...); required\n"
           "  -s, --section NAME   the ini section that lists the maps (default: "
        << d.section
        << ")\n"
           "  --rawlog FILE        a rawlog (either format); robot poses from\n"
           "                       CObservationRobotPose, else odometry\n"
           "  --simplemap FILE     a simplemap (.simplemap or .simplemap.gz) with pose PDFs\n"
           "                       (give exactly one of --rawlog and --simplemap)\n"
           "Output:\n"
           "  --out DIR            output folder, created if needed (default: "
        << d.out
        << ")\n"
           "  --export-resolution M  also write elevation_{height,sigma}_supersampled.asc:\n"
           "                       the sub-cell surface (heightAt) every M metres, rasters' area\n"
           "  --outputs LIST       comma-separated, or 'all' (default: "
        << d.outputs << ")\n"
        << OutputSelection::help()
        << "  --epsg CODE          the projected CRS of the robot poses (e.g. 32633, UTM 33N),\n"
           "                       written into the GeoTIFFs (default: none, the map frame)\n"
        << "  --scene-colour NAME  colour of elevation.3Dscene: height, sigma, certainty or\n"
           "                       source (default: height; sigma if the ini sets\n"
           "                       color_by_sigma = true)\n"
           "                       Rasters cover the known cells plus "
        << MapLayers::kMargin_cells
        << " cells. No input is ever\n"
           "                       overwritten; each file is written whole or not at all.\n"
           "Evaluation (all off by default):\n"
           "  --ground-truth GT.asc  evaluate against a truth raster: raw, laser_only, multibin,\n"
           "                       multibin_filled, mrpt_height_grid; writes report.json,\n"
           "                       profile.csv, eval_*.asc and the figures fig_pi.png,\n"
           "                       fig_profile.png, layers.png (python3-matplotlib)\n"
           "  --with-mrf           also MRPT's CHeightGridMap2D_MRF on a 35 x 35 cell crop (slow)\n"
           "  --profile x0,y0,x1,y1  profile line of fig_profile.png [m] (default: along x\n"
           "                       through the middle of the evaluated area)\n"
           "  --eval-area xmin,xmax,ymin,ymax  evaluate only there [m] (default: the whole truth)\n"
           "  --no-plots           do not draw the figures (default: drawn)\n"
           "  -h, --help           this text\n"
           "\n"
           "Exit code 0 on success; 1 with a one-line error (naming the file) on bad input, or\n"
           "when no point could be fused (the per-class report says why).\n";
}

Arguments parseArguments(int argc, char** argv) {
    Arguments a;
    if (argc == 1) {
        const fs::path src = MULTIBIN_SOURCE_DIR;
        a.config = (src / "ini" / "mockup.ini").string();
        a.rawlog = (src / "rawlogs" / "mockup.rawlog").string();
        a.groundTruth = (src / "rawlogs" / "mockup_gt.asc").string();
        a.usedDefaults = true;
        return a;
    }
    std::map<std::string, std::string*> flags{
        {"--config", &a.config},      {"--section", &a.section},          {"-s", &a.section},
        {"--rawlog", &a.rawlog},      {"--simplemap", &a.simplemap},      {"--out", &a.out},
        {"--outputs", &a.outputs},    {"--ground-truth", &a.groundTruth}, {"--profile", &a.profile},
        {"--eval-area", &a.evalArea}, {"--scene-colour", &a.sceneColour}};
    flags["--export-resolution"] = &a.exportResolution;
    flags["--epsg"] = &a.epsg;
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
        if (it == flags.end())
            throw std::invalid_argument("unknown argument '" + arg + "' (see --help)");
        if (i + 1 >= argc) throw std::invalid_argument(arg + " needs a value");
        *it->second = argv[++i];
    }
    if (a.config.empty()) throw std::invalid_argument("--config INI is required");
    if (a.rawlog.empty() == a.simplemap.empty())
        throw std::invalid_argument("give exactly one of --rawlog FILE and --simplemap FILE");
    if (a.out.empty()) throw std::invalid_argument("--out needs a folder");
    if (a.section.empty()) throw std::invalid_argument("--section needs a name");
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

/** The grid window's extent, for messages. */
std::string windowText(const CMultiBinElevationMap& map) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "x %.6g..%.6g m, y %.6g..%.6g m", map.getXMin(), map.getXMax(),
                  map.getYMin(), map.getYMax());
    return buf;
}

/** Keeps only the multi-bin elevation maps of `inits`; returns how many others there were. The
 * mapper writes no other map, and another type in the same ini (an occupancy grid of any size)
 * would be built and fed for nothing. */
size_t keepOnlyElevationMaps(mrpt::maps::TSetOfMetricMapInitializers& inits) {
    mrpt::maps::TSetOfMetricMapInitializers kept;
    for (const auto& init : inits)
        if (init->getMetricMapClassType()->derivedFrom(CLASS_ID(CMultiBinElevationMap)))
            kept.push_back(init);
    const size_t others = inits.size() - kept.size();
    inits = kept;
    return others;
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

/** The files of the evaluation (EvaluationRun and the figures); '*' ends a prefix. */
const std::vector<std::string> kEvaluationFiles{"report.json", "profile.csv",     "eval_*",
                                                "fig_pi.png",  "fig_profile.png", "layers.png"};

/** Refuses an input that is not a regular file (a device, a FIFO, a socket): MRPT reads one
 * forever, blocks on it or fails without a message. `what`: "rawlog", "config", ... */
void checkRegularFile(const std::string& what, const std::string& path) {
    struct stat st {};
    if (path.empty() || ::stat(path.c_str(), &st) != 0 || S_ISDIR(st.st_mode) ||
        S_ISREG(st.st_mode))
        return;  // absent and folders: their own messages where the input is read
    throw std::runtime_error(what + " '" + path +
                             "' is not a regular file (a device, a FIFO or a socket)");
}

/** Maps and writes; `stage` says what is being done, for errors that do not say it. */
/** Wall and process CPU time spent in one stage of the run [s]: on a shared machine the CPU
 * time is what the stage costs, the wall time what one waited for it. */
struct StageTime {
    double wall_s = 0, cpu_s = 0;
    struct Start {
        std::chrono::steady_clock::time_point wall = std::chrono::steady_clock::now();
        std::clock_t cpu = std::clock();
    };
    /** Adds the time since `t0`. */
    void addSince(const Start& t0) {
        wall_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0.wall).count();
        cpu_s += double(std::clock() - t0.cpu) / CLOCKS_PER_SEC;
    }
    /** Takes another stage's time out of this one (it ran inside this one's interval). */
    void subtract(const StageTime& inner) { wall_s -= inner.wall_s, cpu_s -= inner.cpu_s; }
    std::string text() const {
        std::ostringstream os;
        os << wall_s << " s (CPU " << cpu_s << " s)";
        return os.str();
    }
};

int run(const Arguments& args, std::string& stage) {
    for (const auto& [what, path] : {std::pair{"config", args.config},
                                     {"rawlog", args.rawlog},
                                     {"simplemap", args.simplemap},
                                     {"ground truth", args.groundTruth}})
        checkRegularFile(what, path);
    OutputSelection selection = OutputSelection::parse(args.outputs);
    selection.epsg = OutputSelection::parseEpsg(args.epsg);
    double exportCell_m = 0;  // --export-resolution: 0 = none
    if (!args.exportResolution.empty() &&
        (!multibin::parseFiniteNumber(args.exportResolution, exportCell_m) || !(exportCell_m > 0)))
        throw std::invalid_argument("--export-resolution: '" + args.exportResolution +
                                    "' is not a positive cell size [m]");
    const std::string inputName =
        args.rawlog.empty() ? "simplemap '" + args.simplemap + "'" : "rawlog '" + args.rawlog + "'";
    // Checked before the (long) mapping: no planned output may be one of the inputs.
    const OutputFolder folder(args.out, {{"--config", args.config},
                                         {"--rawlog", args.rawlog},
                                         {"--simplemap", args.simplemap},
                                         {"--ground-truth", args.groundTruth}});
    for (const std::string& name : selection.fileNames()) folder.checkNotAnInput(name);
    if (exportCell_m > 0)
        for (const char* name : SupersampledLayers::kFiles) folder.checkNotAnInput(name);
    if (!args.groundTruth.empty())
        for (const std::string& name : kEvaluationFiles) folder.checkNotAnInput(name);

    if (!fs::exists(args.config))
        throw std::runtime_error("config '" + args.config + "' not found");
    if (fs::is_directory(args.config))
        throw std::runtime_error("config '" + args.config + "' is a directory, not a file");
    stage = "reading config '" + args.config + "'";
    mrpt::config::CConfigFile ini(args.config);
    mrpt::maps::TSetOfMetricMapInitializers inits;
    inits.loadFromConfigFile(ini, args.section);
    if (const size_t others = keepOnlyElevationMaps(inits))
        std::cout << "note: " << others << " other map(s) of [" << args.section
                  << "] not built: elevation-mapper builds and writes only multiBinElevationMap\n";
    mrpt::maps::CMultiMetricMap maps(inits);
    const auto elevation = maps.mapByClass<CMultiBinElevationMap>();
    if (!elevation)
        throw std::runtime_error("config '" + args.config +
                                 "' defines no multiBinElevationMap in [" + args.section +
                                 "] (choose the section with --section)");

    selection.sceneColouring = elevation->insertionOptions.render.color_by_sigma
                                   ? multibin::SceneColouring::Sigma
                                   : multibin::SceneColouring::Height;
    if (!args.sceneColour.empty()) {
        try {
            selection.sceneColouring = multibin::sceneColouringFromName(args.sceneColour);
        } catch (const std::invalid_argument& e) {
            throw std::invalid_argument(std::string("--scene-colour: ") + e.what());
        }
    }

    std::unique_ptr<EvaluationRun> evaluation;
    if (!args.groundTruth.empty()) {
        EvaluationRun::Options eo;
        eo.groundTruthPath = args.groundTruth;
        eo.withMrf = args.withMrf;
        eo.profile_m = parseFourNumbers("--profile", args.profile, "x0,y0,x1,y1 [m]");
        eo.area_m = parseFourNumbers("--eval-area", args.evalArea, "xmin,xmax,ymin,ymax [m]");
        evaluation = std::make_unique<EvaluationRun>(eo, *elevation);
    }

    StageTime insertion;  // the multi-bin map's own insertion
    ObservationTally tally;
    RunFacts facts;
    PoseCounts poseCounts;  // a rawlog's: how its observations got their pose
    PoseReach reach;        // how far the robot poses go, against the supported range
    auto insertTimed = [&](const mrpt::obs::CObservation& obs,
                           const mrpt::poses::CPose3DPDFGaussian& pose, bool poseHasCov) {
        tally.before(*elevation);
        reach.add(pose.mean);
        const StageTime::Start t0;
        const bool inserted = poseHasCov ? elevation->insertObservation(obs, pose)
                                         : elevation->insertObservation(obs, pose.mean);
        insertion.addSince(t0);
        tally.after(obs, inserted, *elevation);
        facts.observationsWithPoseCovariance += inserted && poseHasCov;
        if (evaluation) evaluation->observe(obs, pose, poseHasCov);
    };
    stage = "mapping " + inputName;
    const StageTime::Start map0;  // reading: the mapping loop's time outside the insertion
    MrptWarnings mrptWarnings;    // MRPT's own lines while reading: once each, after the bar
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
            [&](double f, size_t n) { bar.update(f, std::to_string(n) + " entries"); },
            elevation->insertionOptions.robot_pose_max_dt_s, &poseCounts, &mrptWarnings);
    } else {
        const mrpt::maps::CSimpleMap sm =
            RawlogSource::loadSimplemap(args.simplemap, &mrptWarnings);
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
    StageTime reading;
    reading.addSince(map0);
    reading.subtract(insertion);
    for (const std::string& w : mrptWarnings.summary())
        std::cerr << "elevation-mapper: warning: " << w << "\n";
    std::cout << tally.report();
    const multibin::InsertStats& fused = elevation->statistics().insert;
    const std::string beyond =
        reach.beyondSupportedRange(elevation->mapOrigin().x, elevation->mapOrigin().y);
    if (fused.accepted == 0 && !beyond.empty())
        throw std::runtime_error(inputName + ": " + beyond + "; " + tally.whyNothingFused(fused));
    if (!beyond.empty()) std::cerr << "elevation-mapper: warning: " << beyond << "\n";
    if (fused.accepted == 0 && fused.outsideMap > 0)
        throw std::runtime_error(inputName + ": the map's window (" + windowText(*elevation) +
                                 ") does not hold the data: " + std::to_string(fused.outsideMap) +
                                 " points fell outside it, none inside (check grow, "
                                 "min_x_m..max_y_m, resolution_m, max_range_m); " +
                                 tally.whyNothingFused(fused));
    if (fused.accepted == 0)
        throw std::runtime_error(inputName + ": " + tally.whyNothingFused(fused));
    if (!elevation->creationOptions.grow && fused.outsideMap > 0)
        std::cout << "note: " << fused.outsideMap << " points fell outside the fixed window ("
                  << windowText(*elevation) << ")\n";

    stage = "filling the map of " + inputName;
    elevation->flushLocalToGlobal();  // dual grid: the global grid holds the whole run
    StageTime filling;
    const StageTime::Start fill0;
    ProgressBar::runWithProgress("filling", [&] { elevation->dem_update_map(); });  // once
    filling.addSince(fill0);
    const StageTime::Start outputs0;  // the layers and the files (the evaluation apart)
    StageTime outputs, scoring;
    std::string table;
    // Scoring (the MRF solve draws its own line) and the layers of a large window take seconds.
    if (evaluation) {
        const StageTime::Start e0;
        table = evaluation->finish(folder, insertion.wall_s, filling.wall_s);
        scoring.addSince(e0);
    }
    MapLayers layers;
    ProgressBar::runWithProgress("layers", [&] {
        layers = MapLayers::of(
            *elevation, selection.tif || selection.tifLayers || selection.scene || selection.png);
    });
    // Everything that can fail on the request is computed before the first output is written.
    SupersampledLayers fine;
    if (exportCell_m > 0)
        ProgressBar::runWithProgress("supersampled", [&] {
            fine = SupersampledLayers::of(*elevation, layers, exportCell_m);
        });
    stage = "writing the outputs into '" + folder.dir().string() + "'";
    std::vector<std::string> written = writeMapOutputs(*elevation, layers, selection, folder);
    if (exportCell_m > 0) {
        fine.saveAsc(folder);
        written.insert(written.end(), std::begin(SupersampledLayers::kFiles),
                       std::end(SupersampledLayers::kFiles));
    }
    outputs.addSince(outputs0);
    outputs.subtract(scoring);

    const auto& fs_ = elevation->lastFilledCells().stats;
    std::cout << elevation->asString() << "\n"
              << insertSummary(elevation->statistics().insert) << "\n"
              << "observations with the default pose covariance: "
              << elevation->statistics().poseFallbacks << "\n"
              << "rawlog poses: " << poseCounts.robotPose << " robot pose, "
              << poseCounts.odometrySinceRobotPose << " robot pose + odometry since, "
              << poseCounts.defaultCovariance << " default covariance\n"
              << "cells filled: " << fs_.median << " by weighted median, " << fs_.gaussian
              << " by Gaussian surface (" << fs_.supportAreas << " support areas); " << fs_.unfilled
              << " left unknown\n"
              << "reading time: " << reading.text() << "; insertion time: " << insertion.text()
              << "; fill time: " << filling.text() << "; outputs time: " << outputs.text()
              << (evaluation ? "; evaluation time: " + scoring.text() : "") << "\n"
              << "rasters: " << layers.cells.nx << " x " << layers.cells.ny
              << " cells (the known cells plus " << MapLayers::kMargin_cells << ")\n"
              << "wrote " << fs::absolute(folder.dir()).string() << "/{";
    for (size_t i = 0; i < written.size(); i++) std::cout << (i ? ", " : "") << written[i];
    std::cout << "}\n";
    if (evaluation) {
        std::cout << "\nEvaluation against " << args.groundTruth << " (report.json):\n" << table;
        if (args.plots) drawFigures(folder, selection.asc ? nullptr : &layers);
    }
    for (const std::string& w : runWarnings(*elevation, facts))
        std::cout << "warning: " << w << "\n";
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    multibin::removePartialFilesOnSignals();  // a killed run leaves no partial file
    std::string stage = "reading the arguments";
    try {
        const Arguments args = parseArguments(argc, argv);
        if (args.usedDefaults)
            std::cout << "No arguments: mapping the shipped mock-up scenario\n  --config "
                      << args.config << "\n  --rawlog " << args.rawlog << "\n  --ground-truth "
                      << args.groundTruth << "\n  --out " << args.out << "\n";
        return run(args, stage);
    } catch (const std::exception& e) {
        std::cerr << "elevation-mapper: error: " << multibin::userMessage(e, stage) << "\n";
        return 1;
    }
}
