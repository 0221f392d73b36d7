/* terrain-sim: a simulated Messor sensor rig (pitched URG-04LX laser, STOC-style stereo camera)
 * over real scanned terrain boards, writing rawlogs with pose PDFs and ground truth. */
#include "Scenario.h"

#include <multibin/io/ErrorMessage.h>

#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace {

const char* kUsage =
    "Usage: terrain-sim --terrain A.asc[,B.asc,...] --scenario mockup|walk --out PREFIX [options]\n"
    "Writes PREFIX.rawlog (gzip), PREFIX.simplemap, PREFIX_gt.asc, PREFIX.ini, PREFIX_path.txt.\n"
    "Options:\n"
    "  --tiles CxR          boards tiled C along x (walking direction) by R along y (default 3x3)\n"
    "  --seed N             random seed; the same seed gives byte-identical output (default 1)\n"
    "  --gt-cell M          ground-truth cell size [m] (default 0.015)\n"
    "  --margin M           flat ground stored around the tiles [m] (default 0.6)\n"
    "  --stereo-size WxH    stereo image size [px] (default 320x240)\n"
    "  --stereo-rate HZ     stereo frames per second (default 1; the laser runs at 10 Hz)\n"
    "  --no-disparity       do not write the STOC-style disparity image\n"
    "  --step M             mockup: rig advance per laser scan [m] (default 0.01)\n"
    "  --speed MPS          walk: forward speed [m/s] (default 0.1)\n"
    "  --dark-patches N     black discs on the boards (default 6)\n"
    "  --max-frames N       stop after N frames (default: the whole trajectory)\n"
    "Sensor errors the library's models do not describe (doc/terrain-sim.md; default: none,\n"
    "the noise drawn from the models' own sigmas with exact calibration):\n"
    "  --noise matched|independent|exact  independent: all of the below at their stated\n"
    "                       values (doc/independent-evaluation.md); the options below override\n"
    "                       it. exact: no noise, bias, stereo fattening or pose error at all\n"
    "                       (the written sigmas and pose PDFs unchanged)\n"
    "  --tail-dof N         Student-t noise with N > 2 dof at the same sigma, laser and stereo\n"
    "                       (0: Gaussian)\n"
    "  --outliers F         share of laser ranges and stereo disparities replaced by the true\n"
    "                       value times U(0.5, 1.5)\n"
    "  --laser-range-bias B0,B1        extra range bias B0 + B1 r [m, m/m]\n"
    "  --laser-mixed P[,JUMP]          mixed-pixel chance at depth edges over JUMP m (0.5, 0.03)\n"
    "  --laser-pitch-error DEG         true mounting pitch minus the written one\n"
    "  --stereo-mixed P                chance that a pixel at a depth edge blends both sides\n"
    "  --stereo-baseline-error M       true baseline minus the written one [m]\n"
    "  --stereo-principal-point-error DU,DV  true cx, cy minus the written ones [px]\n"
    "  --help               this text\n";

double parseDouble(const std::string& opt, const std::string& v) {
    size_t used = 0;
    double d = 0;
    try {
        d = std::stod(v, &used);
    } catch (...) {
        used = 0;
    }
    if (used != v.size() || v.empty() || !std::isfinite(d))
        throw std::invalid_argument(opt + ": '" + v + "' is not a number");
    return d;
}

long parseInt(const std::string& opt, const std::string& v, long lo) {
    size_t used = 0;
    long n = 0;
    try {
        n = std::stol(v, &used);
    } catch (...) {
        used = 0;
    }
    if (used != v.size() || v.empty() || n < lo)
        throw std::invalid_argument(opt + ": '" + v +
                                    "' is not an integer >= " + std::to_string(lo));
    return n;
}

/** "A,B" (or "A" when `secondOptional`, leaving b as it is) as two numbers. */
void parseNumbers(const std::string& opt, const std::string& v, double& a, double& b,
                  bool secondOptional = false) {
    const auto comma = v.find(',');
    if (comma == std::string::npos) {
        if (!secondOptional)
            throw std::invalid_argument(opt + ": '" + v + "' is not of the form A,B");
        a = parseDouble(opt, v);
        return;
    }
    a = parseDouble(opt, v.substr(0, comma));
    b = parseDouble(opt, v.substr(comma + 1));
}

void parsePair(const std::string& opt, const std::string& v, int& a, int& b) {
    const auto x = v.find('x');
    if (x == std::string::npos)
        throw std::invalid_argument(opt + ": '" + v + "' is not of the form AxB");
    a = static_cast<int>(parseInt(opt, v.substr(0, x), 1));
    b = static_cast<int>(parseInt(opt, v.substr(x + 1), 1));
}

}  // namespace

int main(int argc, char** argv) {
    try {
        terrain_sim::ScenarioConfig cfg;
        bool haveScenario = false;
        // The noise preset first, so that the single-error options override it in any order.
        for (int i = 1; i + 1 < argc; ++i) {
            if (std::string(argv[i]) != "--noise") continue;
            const std::string v = argv[i + 1];
            if (v == "independent")
                terrain_sim::applyIndependentNoise(cfg);
            else if (v == "exact")
                terrain_sim::applyExactMeasurements(cfg);
            else if (v != "matched")
                throw std::invalid_argument("--noise: '" + v +
                                            "' is not matched, independent or exact");
        }
        for (int i = 1; i < argc; ++i) {
            const std::string a = argv[i];
            if (a == "--help" || a == "-h") {
                std::cout << kUsage;
                return 0;
            }
            if (a == "--no-disparity") {
                cfg.stereo.disparity = false;
                continue;
            }
            if (a.rfind("--", 0) != 0)
                throw std::invalid_argument("unexpected argument '" + a + "'");
            if (i + 1 >= argc) throw std::invalid_argument(a + " needs a value");
            const std::string v = argv[++i];
            if (a == "--terrain") {
                cfg.terrainFiles.clear();
                std::stringstream ss(v);
                for (std::string f; std::getline(ss, f, ',');)
                    if (!f.empty()) cfg.terrainFiles.push_back(f);
            } else if (a == "--tiles") {
                parsePair(a, v, cfg.tilesX, cfg.tilesY);
            } else if (a == "--scenario") {
                if (v != "mockup" && v != "walk")
                    throw std::invalid_argument("--scenario: '" + v + "' is not mockup or walk");
                cfg.scenario = v;
                haveScenario = true;
            } else if (a == "--seed") {
                cfg.seed = static_cast<uint64_t>(parseInt(a, v, 0));
            } else if (a == "--out") {
                cfg.outPrefix = v;
            } else if (a == "--gt-cell") {
                cfg.gtCell_m = parseDouble(a, v);
                if (!(cfg.gtCell_m > 0)) throw std::invalid_argument("--gt-cell must be > 0");
            } else if (a == "--margin") {
                cfg.margin_m = parseDouble(a, v);
                if (cfg.margin_m < 0) throw std::invalid_argument("--margin must be >= 0");
            } else if (a == "--stereo-size") {
                parsePair(a, v, cfg.stereo.width_px, cfg.stereo.height_px);
                if (cfg.stereo.width_px < 16 || cfg.stereo.height_px < 16)
                    throw std::invalid_argument("--stereo-size: at least 16x16");
            } else if (a == "--stereo-rate") {
                cfg.trajectory.stereoRate_hz = parseDouble(a, v);
                if (!(cfg.trajectory.stereoRate_hz > 0) || cfg.trajectory.stereoRate_hz > 10)
                    throw std::invalid_argument("--stereo-rate must be in (0, 10] Hz");
            } else if (a == "--step") {
                cfg.trajectory.mockupStep_m = parseDouble(a, v);
                if (!(cfg.trajectory.mockupStep_m > 0))
                    throw std::invalid_argument("--step must be > 0");
            } else if (a == "--speed") {
                cfg.trajectory.walkSpeed_mps = parseDouble(a, v);
                if (!(cfg.trajectory.walkSpeed_mps > 0))
                    throw std::invalid_argument("--speed must be > 0");
            } else if (a == "--dark-patches") {
                cfg.darkPatches = static_cast<int>(parseInt(a, v, 0));
            } else if (a == "--max-frames") {
                cfg.trajectory.maxFrames = static_cast<int>(parseInt(a, v, 1));
            } else if (a == "--noise") {
                // applied above
            } else if (a == "--tail-dof") {
                const int dof = static_cast<int>(parseInt(a, v, 0));
                if (dof == 1 || dof == 2)
                    throw std::invalid_argument("--tail-dof must be 0 or > 2");
                cfg.laser.errors.tailDof = cfg.stereo.errors.tailDof = dof;
            } else if (a == "--outliers") {
                const double f = parseDouble(a, v);
                if (!(f >= 0 && f <= 1))
                    throw std::invalid_argument("--outliers must be in [0, 1]");
                cfg.laser.errors.outlierFraction = cfg.stereo.errors.outlierFraction = f;
            } else if (a == "--laser-range-bias") {
                parseNumbers(a, v, cfg.laser.rangeBias0_m, cfg.laser.rangeBiasSlope);
            } else if (a == "--laser-mixed") {
                parseNumbers(a, v, cfg.laser.mixedProbability, cfg.laser.mixedJump_m, true);
                if (!(cfg.laser.mixedProbability >= 0 && cfg.laser.mixedProbability <= 1) ||
                    !(cfg.laser.mixedJump_m > 0))
                    throw std::invalid_argument("--laser-mixed: P in [0, 1], JUMP > 0");
            } else if (a == "--laser-pitch-error") {
                cfg.laser.pitchError_rad = parseDouble(a, v) * M_PI / 180.0;
            } else if (a == "--stereo-mixed") {
                cfg.stereo.mixedProbability = parseDouble(a, v);
                if (!(cfg.stereo.mixedProbability >= 0 && cfg.stereo.mixedProbability <= 1))
                    throw std::invalid_argument("--stereo-mixed must be in [0, 1]");
            } else if (a == "--stereo-baseline-error") {
                cfg.stereo.baselineError_m = parseDouble(a, v);
                if (!(cfg.stereo.baseline_m + cfg.stereo.baselineError_m > 0))
                    throw std::invalid_argument(
                        "--stereo-baseline-error: the true baseline must be > 0");
            } else if (a == "--stereo-principal-point-error") {
                parseNumbers(a, v, cfg.stereo.cxError_px, cfg.stereo.cyError_px);
            } else {
                throw std::invalid_argument("unknown option '" + a + "' (see --help)");
            }
        }
        if (cfg.terrainFiles.empty()) throw std::invalid_argument("--terrain is required");
        if (!haveScenario) throw std::invalid_argument("--scenario is required (mockup or walk)");
        if (cfg.outPrefix.empty()) throw std::invalid_argument("--out is required");
        const auto s = terrain_sim::runScenario(cfg);
        std::cout << "terrain-sim: " << cfg.scenario << ", " << s.frames << " frames ("
                  << s.stereoFrames << " stereo), laser returns " << s.laserReturns << "/"
                  << s.laserBeams << " (dropouts " << s.laserDropouts << ", dark " << s.laserDark
                  << ", mixed " << s.laserMixed << ")\n";
        for (const auto& f : s.files) std::cout << "  wrote " << f << "\n";
        return 0;
    } catch (const std::exception& e) {
        std::cerr << "terrain-sim: error: " << multibin::oneLineMessage(e) << "\n";
        return 1;
    }
}
