/* Part of the multibin elevation-mapping library. Internal to gap filling. */
#pragma once

#include <vector>

#include "multibin/fill/FillOptions.h"
#include "multibin/fill/GapLabelling.h"
#include "multibin/fill/HeightRaster.h"
#include "multibin/fill/detail/MedianFiller.h"

namespace multibin::fill::detail {

/** Fills one gap of `r` into `out` as fillGaps() routes it (median, shadow, eq 16 surface or the
 * repeated median); `measured` flags r's measured cells, `median` is a filler over r. It reads r
 * within gapReadMargin() of the gap, and the gap's support square: the whole-window path and the
 * sparse path (SparseFill.h) call it, the latter on a raster around the gap. */
void fillGap(const HeightRaster& r, const FillOptions& o, const Gap& gap,
             const std::vector<char>& measured, MedianFiller& median, FillResult& out);

}  // namespace multibin::fill::detail
