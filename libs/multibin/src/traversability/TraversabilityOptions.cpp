/* Part of the multibin elevation-mapping library. */
#include "multibin/traversability/TraversabilityOptions.h"

#include <algorithm>
#include <sstream>

#include "multibin/io/OptionKeys.h"

namespace multibin::traversability {

namespace {
/** The keys of `o` (a TraversabilityOptions or a const one), for the options protocol
 * (multibin/io/OptionKeys.h): read, written and checked from this one list. */
template <class Options, class Visit>
void visitKeys(Options& o, Visit&& visit) {
    visit("radius_m", o.radius_m, positive("m"));
    visit("max_step_m", o.max_step_m, positive("m"));
    visit("max_slope_deg", o.max_slope_deg, between(0.1, 89.9, "deg"));
    visit("max_roughness_m", o.max_roughness_m, positive("m"));
    visit("foot_radius_m", o.foothold.radius_m, positive("m"));
    visit("foothold_flatness_m", o.foothold.flatness_m, positive("m"));
    visit("foothold_clearance_m", o.foothold.clearance_m, atLeast(0, "m"));
    visit("samples_per_cell", o.samples_per_cell, between(1, 8));
    visit("monte_carlo_draws", o.monte_carlo_draws, between(0, 4096));
    visit("linear_uncertainty", o.linear_uncertainty);
    visit("min_known_fraction", o.min_known_fraction, between(0.05, 1));
    visit("use_bins", o.use_bins);
    visit("bin_min_certainty_share", o.bin_min_certainty_share, between(0, 1));
    visit("step_bias_m", o.step.bias, finite("m"));
    visit("step_gain", o.step.gain, positive());
    visit("step_model_sigma_m", o.step.model_sigma, atLeast(0, "m"));
    visit("slope_bias_deg", o.slope.bias, finite("deg"));
    visit("slope_gain", o.slope.gain, positive());
    visit("slope_model_sigma_deg", o.slope.model_sigma, atLeast(0, "deg"));
    visit("roughness_bias_m", o.roughness.bias, finite("m"));
    visit("roughness_gain", o.roughness.gain, positive());
    visit("roughness_model_sigma_m", o.roughness.model_sigma, atLeast(0, "m"));
    visit("step_roughness_gain", o.step_roughness_gain, finite());
    visit("step_slope_gain", o.step_slope_gain, finite("m"));
}

/** visitKeys as one callable, for readOptionKeys() and loadOptionKeys(). */
const auto kKeys = [](auto& o, auto&& visit) { visitKeys(o, visit); };
}  // namespace

TraversabilityOptions TraversabilityOptions::uncalibrated() const {
    TraversabilityOptions o = *this;
    o.step = o.slope = o.roughness = {};
    o.step_roughness_gain = o.step_slope_gain = 0;
    return o;
}

double TraversabilityOptions::reach_m() const {
    return std::max(radius_m, foothold.radius_m + foothold.clearance_m);
}

void TraversabilityOptions::read(StrictConfigSection& s) { readOptionKeys(s, *this, kKeys); }
void TraversabilityOptions::loadFromConfigFile(const mrpt::config::CConfigFileBase& source,
                                               const std::string& section) {
    loadOptionKeys(source, section, *this, kKeys);
}

void TraversabilityOptions::write(mrpt::config::CConfigFileBase& c,
                                  const std::string& section) const {
    visitKeys(*this, OptionWriter{c, section});
}

std::string TraversabilityOptions::text() const {
    std::ostringstream os;
    os.precision(17);
    visitKeys(*this, [&](const OptionKey& key, const auto& value, const auto&... /*rule*/) {
        os << key.name << '=' << value << "; ";
    });
    return os.str();
}

void TraversabilityOptions::validate() const {
    const OptionChecker check("traversability option");
    visitKeys(*this, check);
    // A disc wider than this reads thousands of samples per cell: a misplaced unit (mm for m).
    if (reach_m() > 2.0) check.fail("radius_m", "must be at most 2 m (with the foothold discs)");
}

}  // namespace multibin::traversability
