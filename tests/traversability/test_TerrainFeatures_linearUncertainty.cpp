/* The layers' closed form (linear_uncertainty: the samples' errors propagated linearly through
 * the features, Gaussian probabilities) against the Monte Carlo it replaces, on known surfaces and
 * on the shipped mock-up's map with the hexapod preset. */
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/maps/CMultiBinElevationMap.h>
#include <mrpt/maps/CSimpleMap.h>

#include <cmath>
#include <functional>
#include <string>

#include "multibin/traversability/TerrainFeatures.h"

using namespace multibin;
using namespace multibin::traversability;

namespace {
constexpr double kDeg = 3.14159265358979323846 / 180.0;

/** Samples of z = f(x, y) on 15 x 15 cells of 2 cm, 2 per cell side, each with sigma_m. */
SurfaceSamples surface(const std::function<double(double, double)>& f, double sigma_m) {
    const double cell = 0.02;
    const int k = 2;
    SurfaceSamples s(Lattice{cell, CellWindow{0, 0, 15, 15}}, k);
    for (int sr = 0; sr < s.sy(); sr++)
        for (int sc = 0; sc < s.sx(); sc++) {
            const size_t i = s.sampleIndex(sc, sr);
            s.height_m[i] = float(f((sc + 0.5) * cell / k, (sr + 0.5) * cell / k));
            s.sigma_m[i] = float(sigma_m);
        }
    return s;
}

/** How far the closed form's P(untraversable) (or foothold) lies from the Monte Carlo's. */
struct Agreement {
    double meanAbs = 0, maxAbs = 0;
    size_t cells = 0;
};
Agreement compare(const std::vector<float>& a, const std::vector<float>& b) {
    Agreement g;
    for (size_t k = 0; k < a.size(); k++) {
        if (!std::isfinite(a[k]) || !std::isfinite(b[k])) continue;
        const double d = std::abs(double(a[k]) - double(b[k]));
        g.meanAbs += d, g.maxAbs = std::max(g.maxAbs, d), g.cells++;
    }
    if (g.cells) g.meanAbs /= double(g.cells);
    return g;
}

/** The layers by Monte Carlo (`draws`) and by the closed form, same options otherwise. */
std::pair<TraversabilityLayers, TraversabilityLayers> bothWays(const SurfaceSamples& s,
                                                               TraversabilityOptions o, int draws) {
    std::pair<TraversabilityLayers, TraversabilityLayers> out;
    o.monte_carlo_draws = draws;
    o.linear_uncertainty = false;
    computeLayers(s, o, out.first);
    o.linear_uncertainty = true;
    computeLayers(s, o, out.second);
    return out;
}
}  // namespace

// Known surfaces near each limit, identity calibration (the map's own errors only, where the
// closed form's approximations show most): a plane at 33 deg (limit 35), a step of 7.5 cm
// (limit 8 cm) and waves whose roughness (RMS 2 cm) and step (8 cm) are both at their limits.
// Tolerance: mean |dP| <= 0.05 over the surface's cells, max 0.15 (the Monte Carlo's own error at
// 2048 draws is <= 0.011); measured 0.003 (plane), 0.006 (step), 0.040 (waves: the closed form
// takes the three exceedances as independent, the draws see their correlation).
TEST(LinearUncertainty, MatchesMonteCarloOnKnownSurfacesNearEachLimit) {
    const std::vector<std::pair<std::string, std::function<double(double, double)>>> surfaces = {
        {"plane 33 deg",
         [](double x, double y) { return std::tan(33 * kDeg) * (0.6 * x + 0.8 * y); }},
        {"step 7.5 cm", [](double x, double) { return x > 0.15 ? 0.075 : 0.0; }},
        {"waves", [](double x, double y) {
             return 0.04 * std::sin(2 * M_PI * x / 0.05) * std::cos(2 * M_PI * y / 0.07);
         }}};
    TraversabilityOptions o;
    for (const auto& [name, f] : surfaces) {
        const auto [mc, linear] = bothWays(surface(f, 0.004), o, 2048);
        const Agreement p = compare(mc.untraversable, linear.untraversable);
        EXPECT_GT(p.cells, 100u) << name;
        EXPECT_LE(p.meanAbs, 0.05) << name;
        EXPECT_GT(p.maxAbs, 0.0) << name;  // the closed form did run
        EXPECT_LE(p.maxAbs, 0.15) << name;
        // The sigmas at the centre: within 30 % of the draws' spread where it is not tiny (the
        // step's, a range's, is the approximate one: 25 % low on the plane, 5 % on the waves).
        const size_t c = mc.lattice.index(7, 7);
        for (const auto& [a, b] : {std::pair{mc.slopeSigma_deg[c], linear.slopeSigma_deg[c]},
                                   {mc.roughnessSigma_m[c], linear.roughnessSigma_m[c]},
                                   {mc.stepSigma_m[c], linear.stepSigma_m[c]}})
            if (a > 1e-4f) EXPECT_NEAR(b, a, 0.3 * a) << name;
        std::printf("%s: cells %zu, mean |dP| %.4f, max %.4f\n", name.c_str(), p.cells, p.meanAbs,
                    p.maxAbs);
    }
}

// The shipped mock-up mapped as ini/mockup.ini configures it, with the hexapod preset (its
// calibration): the closed form against the default Monte Carlo (128 draws), every known cell.
TEST(LinearUncertainty, MatchesMonteCarloOnTheMockup) {
    const std::string data = MULTIBIN_REFERENCE_DATA_DIR;
    mrpt::maps::CSimpleMap simplemap;
    ASSERT_TRUE(simplemap.loadFromFile(data + "/mockup.simplemap"));
    const mrpt::config::CConfigFile ini(data + "/../ini/mockup.ini");
    const mrpt::config::CConfigFile preset(data + "/../ini/traversability-hexapod.ini");
    const std::string section = "MappingApplication_multiBinElevationMap_00_";
    mrpt::maps::CMultiBinElevationMap::TCreationOptions creation;
    creation.loadFromConfigFile(ini, section + "creationOpts");
    mrpt::maps::CMultiBinElevationMap map(creation);
    map.insertionOptions.loadFromConfigFile(ini, section + "insertOpts");
    map.traversabilityOptions.loadFromConfigFile(preset, section + "traversabilityOpts");
    map.insertSimpleMapWithPosePdfs(simplemap);
    const TraversabilityLayers mc = map.traversabilityLayers();
    map.traversabilityOptions.linear_uncertainty = true;
    const TraversabilityLayers linear = map.traversabilityLayers();
    const Agreement p = compare(mc.untraversable, linear.untraversable);
    const Agreement f = compare(mc.foothold, linear.foothold);
    std::printf("mock-up: cells %zu, P mean |dP| %.4f max %.4f; foothold mean %.4f max %.4f\n",
                p.cells, p.meanAbs, p.maxAbs, f.meanAbs, f.maxAbs);
    EXPECT_GT(p.cells, 5000u);
    EXPECT_LE(p.meanAbs, 0.03);
    EXPECT_LE(p.maxAbs, 0.3);
    EXPECT_GT(p.maxAbs, 0.0);  // the closed form did run
    // The foothold is not held to the draws: they take each draw's ranges as they fall, the noise
    // counted on top of the estimated heights' own (the features' draws are centred on the map's
    // features; the foothold's are not), so the draws' foothold is lower (0.16 mean on this map).
}
