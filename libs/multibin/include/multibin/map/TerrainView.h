/* Part of the multibin elevation-mapping library. */
#pragma once

#include <mrpt/math/CMatrixFixed.h>
#include <mrpt/math/TBoundingBox.h>
#include <mrpt/math/TPoint2D.h>
#include <mrpt/math/TPoint3D.h>
#include <mrpt/opengl/COpenGLScene.h>
#include <mrpt/opengl/CSetOfObjects.h>

#include <string>
#include <vector>

#include "multibin/io/RasterExport.h"
#include "multibin/io/TiledRaster.h"

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

/** The categories of the source layer (CMultiBinElevationMap::HeightSource: measured, filled by
 * the weighted median, filled by the Gaussian surface) with the colours every view of it uses
 * (the 3D view, elevation_source.png; plot_report.py repeats them for matplotlib). */
const std::vector<RasterCategory>& heightSourceCategories();

/** Parses "height", "sigma", "certainty" or "source"; throws std::invalid_argument naming the
 * text otherwise. */
SceneColouring sceneColouringFromName(const std::string& name);
const char* sceneColouringName(SceneColouring c);

/** The direction the 3D view is made to be seen from: SceneViewer3D's default (azimuth and
 * elevation 45 degrees, vertical field of view 30 degrees). The legend faces it, and
 * frameTerrainScene() puts the scene's camera on it. */
struct TerrainViewDirection {
    double azimuth_deg = 45, elevation_deg = 45, fov_deg = 30;
    mrpt::math::TVector3D towardsCamera() const;  //!< unit vector from the target to the eye
    mrpt::math::TVector3D right() const;          //!< the screen's right, horizontal
    mrpt::math::TVector3D up() const;             //!< the screen's up
    mrpt::math::CMatrixDouble33 axes() const;     //!< columns right(), up(), towardsCamera()
};

/** Width over height of the window frameTerrainScene() frames for (4:3; wider windows show more
 * around the map). */
constexpr double kTerrainViewAspect = 4.0 / 3.0;

/** A camera of TerrainViewDirection: the point it looks at and its distance from it. */
struct TerrainCamera {
    mrpt::math::TPoint3D target;
    double distance_m = 0;
};

/** The camera along TerrainViewDirection, at the box's centre, at the nearest distance that shows
 * every corner of `box` within 90 % of a window of width/height `aspect`. */
TerrainCamera frameTerrainView(const mrpt::math::TBoundingBox& box, double aspect);

/** Makes a saved scene open framed: the main viewport's camera from frameTerrainView() over the
 * viewport's bounding box, followed by SceneViewer3D (COpenGLScene::enableFollowCamera), on a
 * light background for the dark labels. Nothing on an empty scene. */
void frameTerrainScene(mrpt::opengl::COpenGLScene& scene);

/** Builds the 3D view of the map into `out` with stock mrpt::opengl classes only (a saved
 * .3Dscene opens in SceneViewer3D without this library): the known cells as a lit surface
 * coloured per cell (a CMesh with a texture of one texel per cell: MRPT 2.5's renderer draws a
 * CMesh's per-vertex colours as one colour, but draws textures) with the previews' colour map of
 * the layer (colourLut(layerPreviewStyle(layer).colormap)), unknown cells left out, a grid of a
 * stated spacing under it for scale, and a legend on its right as seen from TerrainViewDirection:
 * a colour bar facing that direction, as tall as half the map's diagonal, with upright text
 * labels (CText; or the source layer's categories). Nothing when the map knows no cell. */
void buildTerrainView(const mrpt::maps::CMultiBinElevationMap& map, SceneColouring colouring,
                      mrpt::opengl::CSetOfObjects& out);
/** The same from layers read already (knownLayers(), MapLayerFiles.h, in the frame of the robot
 * poses): the heights and the layer `colouring` shows (the heights again for Height), the map's
 * mapOrigin() given; a caller that writes other outputs reads the map once for all. */
void buildTerrainView(const TiledRaster& heights, const TiledRaster& shown,
                      const mrpt::math::TPoint2D& mapOrigin, SceneColouring colouring,
                      mrpt::opengl::CSetOfObjects& out);

}  // namespace multibin
