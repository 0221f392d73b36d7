/* Part of the multibin elevation-mapping library: terrain-sim. */
#include "RandomScene.h"

#include "Scenario.h"
#include "SurfaceTexture.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace terrain_sim {

const char* objectKindName(ObjectKind kind) {
    switch (kind) {
        case ObjectKind::Box:
            return "box";
        case ObjectKind::Post:
            return "post";
        case ObjectKind::Step:
            return "step";
        case ObjectKind::Column:
            return "column";
    }
    return "?";
}

bool SceneObject::covers(double x, double y) const {
    const double dx = x - x_m, dy = y - y_m;
    if (kind == ObjectKind::Column) return dx * dx + dy * dy <= halfX_m * halfX_m;
    const double c = std::cos(yaw_rad), s = std::sin(yaw_rad);
    const double u = c * dx + s * dy, v = -s * dx + c * dy;  // in the object's frame
    return std::abs(u) <= halfX_m && std::abs(v) <= halfY_m;
}

double SceneObject::boundingRadius_m() const {
    return kind == ObjectKind::Column ? halfX_m : std::hypot(halfX_m, halfY_m);
}

namespace {

using Rng = std::mt19937_64;

double uniform(Rng& rng, double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(rng);
}
int uniformInt(Rng& rng, int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); }

/** The board without its rows and columns of exact zeros along the edges (outside the scanned
 * area: 16-20 samples on each side of CD, one on AC and W). Tiled as they are, they make a 2-3 cm
 * trench at z = 0 along a seam once a turn brings them to the tile's start. */
multibin::EsriAsciiGrid trimZeroBorder(multibin::EsriAsciiGrid b) {
    const Eigen::MatrixXf& h = b.heights_m;
    auto zeroRow = [&](int r) { return (h.row(r).array().abs() < 1e-6f).all(); };
    auto zeroCol = [&](int c) { return (h.col(c).array().abs() < 1e-6f).all(); };
    int r0 = 0, r1 = int(h.rows()) - 1, c0 = 0, c1 = int(h.cols()) - 1;
    while (r0 < r1 && zeroRow(r0)) ++r0;
    while (r1 > r0 && zeroRow(r1)) --r1;
    while (c0 < c1 && zeroCol(c0)) ++c0;
    while (c1 > c0 && zeroCol(c1)) --c1;
    const Eigen::MatrixXf kept = h.block(r0, c0, r1 - r0 + 1, c1 - c0 + 1);
    b.heights_m = kept;
    b.xllcenter_m += c0 * b.cellsize_m;
    b.yllcenter_m += r0 * b.cellsize_m;
    return b;
}

/** One of the board's 8 symmetries: mirrored (transposed) or not, then rotated k x 90 deg. */
multibin::EsriAsciiGrid orientBoard(multibin::EsriAsciiGrid b, int quarterTurns, bool mirror) {
    b = trimZeroBorder(std::move(b));
    if (mirror) {
        const Eigen::MatrixXf t = b.heights_m.transpose();
        b.heights_m = t;
    }
    for (int k = 0; k < quarterTurns; ++k) {
        const Eigen::MatrixXf t = b.heights_m.transpose();
        b.heights_m = t.colwise().reverse();
    }
    return b;
}

/** The robot's heights and clearance around an object: its feet reach 0.27 m from the body
 * centre; low, small boxes may be straddled. */
double clearance_m(const SceneObject& o) { return o.boundingRadius_m() + 0.27; }
bool straddleable(const SceneObject& o, double groundTop_m) {
    return o.kind == ObjectKind::Box && o.boundingRadius_m() < 0.15 && o.top_m - groundTop_m < 0.2;
}

/** A path near a reference point c: p(s) = c - d n + s t + kappa s^2 / 2 n, with t the heading
 * theta's unit vector and n its left normal, s in [s0, s1] [m]. */
struct PathShape {
    double cx = 0, cy = 0, theta = 0, d = 0, kappa = 0, s0 = -1.2, s1 = 0.6, speed = 0.1;
    void point(double s, double& x, double& y, double& heading) const {
        const double tx = std::cos(theta), ty = std::sin(theta), nx = -ty, ny = tx;
        const double lat = -d + 0.5 * kappa * s * s;
        x = cx + s * tx + lat * nx;
        y = cy + s * ty + lat * ny;
        heading = theta + std::atan(kappa * s);
    }
};

std::vector<Frame> walkPath(const Terrain& ground, const PathShape& p, TrajectoryOptions o,
                            uint64_t poseSeed) {
    std::vector<Frame> frames;
    for (int k = 0;; ++k) {
        const double t = k / o.laserRate_hz, s = p.s0 + p.speed * t;
        if (s > p.s1) break;
        double x, y, heading;
        p.point(s, x, y, heading);
        const double ph = 2 * M_PI * t / o.gaitPeriod_s, sway = 0.006 * std::sin(ph);
        x -= sway * std::sin(heading);  // the gait's sway along the path's left normal
        y += sway * std::cos(heading);
        Frame f;
        f.t_s = t;
        f.truth = hexapodPose(ground, x, y, heading + 0.01 * std::sin(ph), ph);
        f.stereo = k % 10 == 0;
        frames.push_back(f);
    }
    Rng rng(poseSeed);
    applyPoseErrors(frames, walkErrorModel(), o, rng);
    return frames;
}

/** Smallest distance [m] of the path's points from (x, y). */
double closestApproach_m(const PathShape& p, double x, double y) {
    double best = 1e9;
    for (double s = p.s0; s <= p.s1; s += 0.01) {
        double px, py, h;
        p.point(s, px, py, h);
        best = std::min(best, std::hypot(px - x, py - y));
    }
    return best;
}

double maxGroundUnder(const Terrain& g, const SceneObject& o) {
    const double r = o.boundingRadius_m();
    double top = -1e9;
    for (double x = o.x_m - r; x <= o.x_m + r; x += 0.005)
        for (double y = o.y_m - r; y <= o.y_m + r; y += 0.005)
            if (o.covers(x, y)) top = std::max(top, g.height(x, y));
    return top;
}

SceneObject drawObject(Rng& rng, const Terrain& g, double x, double y) {
    SceneObject o;
    o.kind = ObjectKind(uniformInt(rng, 0, 3));
    o.x_m = x;
    o.y_m = y;
    o.yaw_rad = uniform(rng, 0, M_PI);
    // Per kind: half side x, half side y (square: = x), height, each drawn in [lo, hi] [m].
    struct Sizes {
        double x0, x1, y0, y1, h0, h1;
        bool square;
    };
    static const Sizes kSizes[] = {
        {0.04, 0.15, 0.04, 0.15, 0.08, 0.25, false},  // box
        {0.02, 0.04, 0, 0, 0.3, 0.6, true},           // post
        {0.15, 0.25, 0.1, 0.2, 0.05, 0.12, false},    // step
        {0.12, 0.2, 0, 0, 1.0, 1.8, true},            // column: a standing person
    };
    const Sizes& z = kSizes[int(o.kind)];
    o.halfX_m = uniform(rng, z.x0, z.x1);
    o.halfY_m = z.square ? o.halfX_m : uniform(rng, z.y0, z.y1);
    const double height = uniform(rng, z.h0, z.h1);
    o.top_m = maxGroundUnder(g, o) + height;
    return o;
}

/** A pass by the reference point (cx, cy); `like` (if given) is the first pass, which "repeat"
 * and "reverse" follow along the same line. */
PathShape drawPath(Rng& rng, const std::string& kind, double cx, double cy, const PathShape* like) {
    PathShape p;
    if (like && (kind == "repeat" || kind == "reverse")) {
        p = *like;
        if (kind == "reverse") {  // the same line walked the other way
            p.theta += M_PI;
            p.d = -p.d;
            p.kappa = -p.kappa;
            std::swap(p.s0, p.s1);
            p.s0 = -p.s0;
            p.s1 = -p.s1;
        }
    } else {
        p.cx = cx;
        p.cy = cy;
        p.theta = like && kind == "crossing" ? like->theta + uniform(rng, 0.5, 2.6)
                                             : uniform(rng, 0, 2 * M_PI);
        p.d = uniform(rng, -0.7, 0.7);
        p.kappa = kind == "curved" ? uniform(rng, 0.4, 1.0) * (uniformInt(rng, 0, 1) ? 1 : -1) : 0;
        p.s0 = -uniform(rng, 1.0, 1.4);
        p.s1 = uniform(rng, 0.3, 0.7);
    }
    p.speed = uniform(rng, 0.08, 0.15);
    return p;
}

/** Whether the robot on path p keeps clear of `o` (or may straddle it). */
bool clearOf(const PathShape& p, const SceneObject& o, const Terrain& g) {
    const double gap = closestApproach_m(p, o.x_m, o.y_m);
    if (gap >= clearance_m(o)) return true;
    return straddleable(o, maxGroundUnder(g, o)) && gap < 0.03;
}

/** Object placements per pass (index into the placements, -1 none) for each event. */
std::vector<int> eventPlan(const std::string& event) {
    if (event == "removed") return {0, -1};
    if (event == "moved") return {0, 1};
    if (event == "appeared-left") return {-1, 0, -1};
    return {0, 1, -1};  // moved-removed
}

}  // namespace

Terrain RandomScene::seenIn(size_t pass) const {
    const int k = passes.at(pass).placement;
    if (k < 0) return ground;
    const SceneObject& o = placements.at(k);
    Eigen::MatrixXf h = ground.samples_m();
    const double r = o.boundingRadius_m(), c = ground.cell_m();
    const int k0 = std::max(0, int(std::floor((o.x_m - r - ground.x0_m()) / c)));
    const int k1 = std::min(int(h.cols()) - 1, int(std::ceil((o.x_m + r - ground.x0_m()) / c)));
    const int r0 = std::max(0, int(std::floor((o.y_m - r - ground.y0_m()) / c)));
    const int r1 = std::min(int(h.rows()) - 1, int(std::ceil((o.y_m + r - ground.y0_m()) / c)));
    for (int row = r0; row <= r1; ++row)
        for (int col = k0; col <= k1; ++col)
            if (o.covers(ground.x0_m() + col * c, ground.y0_m() + row * c))
                h(row, col) = std::max(h(row, col), float(o.top_m));
    return ground.withSamples(h);
}

std::vector<int> RandomScene::vacatedPlacements() const {
    std::vector<int> out;
    const int last = passes.empty() ? -1 : passes.back().placement;
    for (const ScenePass& p : passes)
        if (p.placement >= 0 && p.placement != last &&
            std::find(out.begin(), out.end(), p.placement) == out.end())
            out.push_back(p.placement);
    return out;
}

std::string RandomScene::describe() const {
    char buf[256];
    std::string s = "seed " + std::to_string(seed) + " " + event + ":";
    for (const SceneObject& o : placements) {
        std::snprintf(buf, sizeof buf, " %s %.0fx%.0f mm h %.0f mm at (%.2f, %.2f);",
                      objectKindName(o.kind), 2e3 * o.halfX_m, 2e3 * o.halfY_m,
                      1e3 * (o.top_m - maxGroundUnder(ground, o)), o.x_m, o.y_m);
        s += buf;
    }
    s += " passes";
    for (const ScenePass& p : passes) s += " " + p.path + (p.placement >= 0 ? "+obj" : "");
    std::snprintf(buf, sizeof buf, "; laser %.2f m pitch %.0f deg; tiles", laser.pose.z(),
                  laser.pose.pitch() * 180 / M_PI);
    s += buf;
    for (const std::string& t : tiles) s += " " + t;
    return s;
}

RandomScene makeRandomScene(const RandomSceneOptions& opts) {
    if (opts.boards.empty()) throw std::invalid_argument("random scene: no boards given");
    ScenarioConfig cfg;  // the sensors' and poses' errors
    if (opts.noise == "independent")
        applyIndependentNoise(cfg);
    else if (opts.noise == "exact")
        applyExactMeasurements(cfg);
    else if (opts.noise != "matched")
        throw std::invalid_argument("random scene: noise must be matched, independent or exact");
    RandomScene sc;
    sc.seed = opts.seed;
    Rng rng(hash64(opts.seed ^ 0x52414e44u));  // geometry only; sensor noise has its own seeds
    const int tilesX = uniformInt(rng, 2, 3), tilesY = 2;
    std::vector<multibin::EsriAsciiGrid> tiles;
    for (int t = 0; t < tilesX * tilesY; ++t) {
        const int b = uniformInt(rng, 0, int(opts.boards.size()) - 1);
        const int turns = uniformInt(rng, 0, 3);
        const bool mirror = uniformInt(rng, 0, 1) == 1;
        tiles.push_back(orientBoard(opts.boards[b], turns, mirror));
        const std::string name = b < int(opts.boardNames.size()) ? opts.boardNames[b] : "?";
        sc.tiles.push_back(name + "/" + std::to_string(90 * turns) + (mirror ? "m" : ""));
    }
    sc.ground = Terrain::fromBoards(tiles, tilesX, tilesY, 0.6);
    const double side = sc.ground.tileSide_m();
    const double ax = uniform(rng, 0.3, tilesX * side - 0.3);
    const double ay = uniform(rng, -tilesY * side / 2 + 0.3, tilesY * side / 2 - 0.3);
    sc.placements.push_back(drawObject(rng, sc.ground, ax, ay));
    const char* events[] = {"removed", "moved", "appeared-left", "moved-removed"};
    sc.event = events[uniformInt(rng, 0, 3)];
    const std::vector<int> plan = eventPlan(sc.event);
    const char* laterKinds[] = {"repeat", "reverse", "crossing", "curved"};
    std::vector<PathShape> shapes;
    for (size_t p = 0; p < plan.size(); ++p) {
        const std::string kind = p == 0 ? (uniformInt(rng, 0, 1) ? "curved" : "straight")
                                        : laterKinds[uniformInt(rng, 0, 3)];
        if (plan[p] >= int(sc.placements.size())) {  // the object moves: where to, beside A
            const SceneObject& a = sc.placements.front();
            SceneObject b = a;
            const double dir = uniform(rng, 0, 2 * M_PI), dist = uniform(rng, 0.25, 0.6);
            b.x_m = std::clamp(a.x_m + dist * std::cos(dir), 0.2, tilesX * side - 0.2);
            b.y_m = std::clamp(a.y_m + dist * std::sin(dir), -side + 0.2, side - 0.2);
            b.yaw_rad = uniform(rng, 0, M_PI);
            b.top_m = maxGroundUnder(sc.ground, b) + (a.top_m - maxGroundUnder(sc.ground, a));
            sc.placements.push_back(b);
        }
        // Every pass goes by the first placement (where stale bins are scored); redraw until
        // the robot keeps clear of the object standing in that pass.
        PathShape shape;
        for (int attempt = 0;; ++attempt) {
            shape = drawPath(rng, kind, ax, ay, p == 0 ? nullptr : &shapes.front());
            if (plan[p] < 0 || clearOf(shape, sc.placements[plan[p]], sc.ground)) break;
            if (attempt > 200) {  // a repeated line that the moved object now blocks: cross
                shape = drawPath(rng, "crossing", ax, ay, &shapes.front());
                if (clearOf(shape, sc.placements[plan[p]], sc.ground)) break;
            }
        }
        shapes.push_back(shape);
        ScenePass pass;
        pass.path = kind;
        pass.placement = plan[p];
        pass.frames = walkPath(sc.ground, shape, cfg.trajectory, hash64(opts.seed * 31 + p));
        sc.passes.push_back(std::move(pass));
    }
    const double mountHeight = uniform(rng, 0.2, 0.5), pitchDeg = uniform(rng, 30, 60);
    sc.darkPatches = uniformInt(rng, 0, 8);
    sc.laser = cfg.laser;
    sc.laser.pose = mrpt::poses::CPose3D(0, 0, mountHeight, 0, pitchDeg * M_PI / 180, 0);
    // The camera's mount from a stream of its own, so that the laser scenes stay as they were.
    Rng camRng(hash64(opts.seed ^ 0x53544552u));
    sc.stereo = cfg.stereo;
    sc.stereo.disparity = false;  // both pipelines match the rendered pair
    sc.stereo.height_m = uniform(camRng, 0.4, 0.55);
    sc.stereo.pitch_rad = uniform(camRng, 30, 45) * M_PI / 180;
    if (opts.noise == "independent") {
        // Errors of the images that no disparity model describes (doc/random-scenes.md).
        sc.stereo.rightRowError_px = 0.3;
        sc.stereo.rightGain = 1.05;
    }
    return sc;
}

}  // namespace terrain_sim
