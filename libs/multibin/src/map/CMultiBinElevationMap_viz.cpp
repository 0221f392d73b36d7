/* Part of the multibin elevation-mapping library.
 * CMultiBinElevationMap: 3D visualization with stock mrpt::opengl classes only, so a saved
 * .3Dscene opens in programs that do not load this library. */
#include <mrpt/opengl/CMesh.h>
#include <mrpt/opengl/CSetOfObjects.h>
#include "CMultiBinElevationMap_impl.h"

#include <cmath>

#include "multibin/io/EsriAsciiGrid.h"

using namespace mrpt::maps;

void CMultiBinElevationMap::getVisualizationInto(mrpt::opengl::CSetOfObjects& outObj) const {
    if (!genericMapParams.enableSaveAs3DObject) return;
    const multibin::EsriAsciiGrid heights = toRaster(RasterLayer::Height);
    const int nx = heights.cols(), ny = heights.rows();
    if (nx < 2 || ny < 2) return;

    // CMesh: Z(i, j) with i along x and j along y, vertices at cell centres.
    mrpt::math::CMatrixDynamic<float> Z(nx, ny), mask(nx, ny);
    for (int ix = 0; ix < nx; ix++)
        for (int iy = 0; iy < ny; iy++) {
            const float h = heights.heights_m(iy, ix);
            Z(ix, iy) = std::isnan(h) ? 0.f : h;
            mask(ix, iy) = std::isnan(h) ? 0.f : 1.f;
        }
    auto mesh = mrpt::opengl::CMesh::Create();
    mesh->setName("CMultiBinElevationMap");
    mesh->setGridLimits(heights.xllcenter_m, heights.xMax_m(), heights.yllcenter_m,
                        heights.yMax_m());
    mesh->setZ(Z);
    mesh->setMask(mask);
    if (insertionOptions.color_by_sigma) {
        // Texture: the sigma image, one texel per cell.
        mrpt::img::CImage sigmaImg;
        getAsImage(sigmaImg, true);
        mesh->assignImage(sigmaImg);
    } else {
        mesh->enableColorFromZ(true, insertionOptions.colormap);
    }
    outObj.insert(mesh);
}
