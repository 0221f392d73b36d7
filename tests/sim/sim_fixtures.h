/* Shared helpers of the terrain-sim tests. */
#pragma once

#include <multibin/io/EsriAsciiGrid.h>

#include "Terrain.h"

#include <Eigen/Core>

namespace sim_test {

/** A flat square board of n x n samples at height z_m, spacing cell_m, lower-left at (0, 0). */
inline multibin::EsriAsciiGrid flatBoard(int n, double cell_m, double z_m) {
    multibin::EsriAsciiGrid g;
    g.heights_m = Eigen::MatrixXf::Constant(n, n, static_cast<float>(z_m));
    g.cellsize_m = cell_m;
    return g;
}

/** Flat ground, x and y in [-1, 1] m (10 mm samples), with a box 0.1 m high over x in (0.1, 0.5)
 * and y in (-0.1, 0.1): depth edges for the laser. */
inline terrain_sim::Terrain boxOnFloor() {
    Eigen::MatrixXf h = Eigen::MatrixXf::Zero(201, 201);
    for (int r = 0; r < 201; ++r)
        for (int k = 0; k < 201; ++k) {
            const double x = -1 + 0.01 * k, y = -1 + 0.01 * r;
            if (x > 0.1 && x < 0.5 && y > -0.1 && y < 0.1) h(r, k) = 0.1f;
        }
    return terrain_sim::Terrain::fromSamples(h, -1, -1, 0.01);
}

/** 3 x 3 textured flat boards of 0.6 m, the centre one 0.15 m high: depth edges for stereo. */
inline terrain_sim::Terrain raisedCentreBoard() {
    const auto low = flatBoard(61, 0.01, 0.0), high = flatBoard(61, 0.01, 0.15);
    return terrain_sim::Terrain::fromBoards({low, low, low, low, high, low, low, low, low}, 3, 3,
                                            0.0);
}

}  // namespace sim_test
