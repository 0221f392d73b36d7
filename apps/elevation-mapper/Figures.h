/* Part of the multibin elevation-mapping library: the elevation-mapper program. */
#pragma once

#include "MapOutputs.h"

/** Draws the evaluation figures (fig_pi.png, fig_profile.png, layers.png) with Debian's
 * python3-matplotlib from report.json and profile.csv in `folder`; the layer panels from the
 * rasters elevation_*.asc in `folder`, or, when `layersIfNoAsc` is given (the rasters were not
 * asked for), from a scratch copy of those layers. Python is started with an argument vector (no
 * shell) and writes into a private folder inside `folder`, whose figures are then moved into
 * place: a name in --out, or a symlink planted there, reaches no shell and no other file. A
 * missing plotter or a failing one is a warning, not an error (every number is in report.json
 * and the rasters). */
void drawFigures(const OutputFolder& folder, const MapLayers* layersIfNoAsc);
