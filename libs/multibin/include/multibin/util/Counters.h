/* Part of the multibin elevation-mapping library.
 * Counters that saturate instead of wrapping, and field-by-field sums of counter structs
 * (insertion and sensor-model statistics). */
#pragma once

#include <limits>
#include <type_traits>

namespace multibin::util {

/** to += n for an unsigned counter, stopping at the type's maximum: a counter that wrapped
 * would report a bin of 4e9 points as one of a few. */
template <class Counter, class N>
void addSaturating(Counter& to, N n) {
    static_assert(std::is_unsigned_v<Counter> && std::is_unsigned_v<N>);
    Counter sum;
    to = __builtin_add_overflow(to, n, &sum) ? std::numeric_limits<Counter>::max() : sum;
}

/** Adds each listed member of `from` to the same member of `to`: unsigned counters saturate
 * (addSaturating), members that are structs use their own +=. A stats struct's operator+= so
 * names each counter once. */
template <class Stats, class... Member>
Stats& addMembers(Stats& to, const Stats& from, Member Stats::*... members) {
    auto add = [](auto& a, const auto& b) {
        if constexpr (std::is_unsigned_v<std::decay_t<decltype(a)>>)
            addSaturating(a, b);
        else
            a += b;
    };
    (add(to.*members, from.*members), ...);
    return to;
}

}  // namespace multibin::util
