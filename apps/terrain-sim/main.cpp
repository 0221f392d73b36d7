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
