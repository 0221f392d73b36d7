/* Part of the multibin elevation-mapping library: terrain-sim. Random scenes: the terrain,
 * trajectories and moving objects drawn from a seed, for accuracy over scenes nobody tuned on
 * (doc/random-scenes.md). */
#pragma once

#include "LaserSim.h"
#include "StereoSim.h"
#include "Terrain.h"
#include "Trajectory.h"

#include <multibin/io/EsriAsciiGrid.h>

#include <cstdint>
#include <string>
#include <vector>

namespace terrain_sim {

enum class ObjectKind { Box, Post, Step, Column };
const char* objectKindName(ObjectKind kind);

/** A rigid object standing on the terrain: a yawed rectangular block (box, post, step) or a
 * vertical cylinder (column, a standing person's size). */
struct SceneObject {
    ObjectKind kind = ObjectKind::Box;
    double x_m = 0, y_m = 0;                  //!< footprint centre (map frame) [m]
    double yaw_rad = 0;                       //!< rotation of the block about +z [rad]
    double halfX_m = 0.075, halfY_m = 0.075;  //!< half sides; the radius twice for a column [m]
    double top_m = 0.15;                      //!< absolute height of the top face [m]

    /** (x, y) [m] lies on the footprint. */
    bool covers(double x_m, double y_m) const;
    /** Radius of the circle around the centre that holds the footprint [m]. */
    double boundingRadius_m() const;
};

/** One pass of the robot past the scene's object. */
struct ScenePass {
    std::string path;           //!< "straight", "curved", "repeat", "reverse" or "crossing"
    std::vector<Frame> frames;  //!< true and estimated robot poses, 10 Hz
    int placement = -1;         //!< RandomScene::placements index seen in this pass (-1: none)
};

/** The drawn scene. Geometry (terrain, object, paths, rig) is a pure function of the seed and the
 * board pool; the noise option changes only the sensor errors. */
struct RandomScene {
    uint64_t seed = 0;
    std::string event;               //!< "removed", "moved", "appeared-left" or "moved-removed"
    Terrain ground;                  //!< the static terrain, without any object
    std::vector<std::string> tiles;  //!< per tile: "board/rotation/mirror", row-major
    std::vector<SceneObject> placements;  //!< where the object stood, in order of appearance
    std::vector<ScenePass> passes;
    LaserConfig laser;    //!< mounting height and pitch drawn; noise matched or independent
    int darkPatches = 0;  //!< black discs on the boards (texture is drawn from the seed)
    /** The stereo camera (`--sensor stereo`): terrain-sim's rig, mounted 0.4-0.55 m high and
     * pitched 30-45 deg down, pairs only (SGBM matches them); noise matched or independent. */
    StereoConfig stereo;

    /** The terrain the sensors see in pass p: the ground with the pass's object drawn in. */
    Terrain seenIn(size_t pass) const;
    /** Placements present in some pass but not in the last one: where stale bins can remain. */
    std::vector<int> vacatedPlacements() const;
    /** One line: seed, event, object, paths, rig. */
    std::string describe() const;
};

struct RandomSceneOptions {
    std::vector<multibin::EsriAsciiGrid> boards;  //!< pool the tiles are drawn from
    std::vector<std::string> boardNames;          //!< names for describe(), same order
    uint64_t seed = 1;
    /** Sensor and pose errors: "matched" (the library's models), "independent"
     * (applyIndependentNoise) or "exact" (applyExactMeasurements: no error at all). */
    std::string noise = "matched";
};

/** Draws a scene: 2 or 3 x 2 tiles of the pool's boards (each rotated by k x 90 deg and maybe
 * mirrored), an object (box, post, step or person-like column) that is removed, moved, or appears
 * and leaves between 2-3 passes of the walking robot (straight, curved, repeated on the same
 * line, reversed or crossing), with a laser mounted 0.2-0.5 m high pitched 30-60 deg. Throws
 * std::invalid_argument on an empty pool. */
RandomScene makeRandomScene(const RandomSceneOptions& opts);

}  // namespace terrain_sim
