/* Part of the multibin elevation-mapping library. */
#pragma once

#include <mrpt/opengl/CSetOfObjects.h>

#include <string>

namespace mrpt::maps {
class CMultiBinElevationMap;
}

namespace multibin {

/** What colours the 3D terrain view of a CMultiBinElevationMap. */
enum class SceneColouring {
    Height,     //!< height [m], the map's colormap
    Sigma,      //!< sigma of the height [m]
    Certainty,  //!< the winning bin's certainty c [-]
    Source      //!< measured, median-filled, surface-filled (fixed categorical colours)
};

/** Parses "height", "sigma", "certainty" or "source"; throws std::invalid_argument naming the
 * text otherwise. */
SceneColouring sceneColouringFromName(const std::string& name);
const char* sceneColouringName(SceneColouring c);

/** Builds the 3D view of the map into `out` with stock mrpt::opengl classes only (a saved
 * .3Dscene opens in SceneViewer3D without this library): the known cells as a lit surface
 * coloured per cell (a CMesh with a texture of one texel per cell: MRPT 2.5's renderer draws a
 * CMesh's per-vertex colours as one colour, but draws textures), unknown cells left out, a colour
 * bar (or a categorical legend) beside it and a grid of a stated spacing under it for scale.
 * Nothing when the map knows no cell. */
void buildTerrainView(const mrpt::maps::CMultiBinElevationMap& map, SceneColouring colouring,
                      mrpt::opengl::CSetOfObjects& out);

}  // namespace multibin
