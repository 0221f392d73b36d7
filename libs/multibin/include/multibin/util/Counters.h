/* Part of the multibin elevation-mapping library.
 * Field-by-field sums of counter structs (insertion and sensor-model statistics). */
#pragma once

namespace multibin::util {

/** Adds each listed member of `from` to the same member of `to` (members that are structs use
 * their own +=), so a stats struct's operator+= names each counter once. */
template <class Stats, class... Member>
Stats& addMembers(Stats& to, const Stats& from, Member Stats::*... members) {
    ((to.*members += from.*members), ...);
    return to;
}

}  // namespace multibin::util
