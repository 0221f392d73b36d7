/* Shared helpers of the terrain-sim tests. */
#pragma once

#include <multibin/io/EsriAsciiGrid.h>

#include <Eigen/Core>

namespace sim_test {

/** A flat square board of n x n samples at height z_m, spacing cell_m, lower-left at (0, 0). */
inline multibin::EsriAsciiGrid flatBoard(int n, double cell_m, double z_m) {
    multibin::EsriAsciiGrid g;
    g.heights_m = Eigen::MatrixXf::Constant(n, n, static_cast<float>(z_m));
    g.cellsize_m = cell_m;
    return g;
}

}  // namespace sim_test
