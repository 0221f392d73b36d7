/* Writes the seed inputs of the committed corpora (tests/fuzz/corpus/<target>/seed_*): serialized
 * maps (single and dual grid), ini sections, and encoded observations. Run once by hand:
 *   make_seed_corpus tests/fuzz/corpus
 * The fuzzers grew the corpora from these (doc/reliability.md). */
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/maps/CMultiBinElevationMap.h>

#include <cstring>
#include <filesystem>
#include <fstream>

#include "fuzz_common.h"

namespace fs = std::filesystem;

namespace {
void write(const fs::path& dir, const std::string& name, const std::vector<uint8_t>& bytes) {
    fs::create_directories(dir);
    std::ofstream(dir / name, std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}
void write(const fs::path& dir, const std::string& name, const std::string& text) {
    write(dir, name, std::vector<uint8_t>(text.begin(), text.end()));
}
template <typename T>
void put(std::vector<uint8_t>& b, T v) {
    const auto* p = reinterpret_cast<const uint8_t*>(&v);
    b.insert(b.end(), p, p + sizeof(T));
}
multibin::PointsWithCov somePoints() {
    multibin::PointsWithCov pts;
    for (int i = 0; i < 30; i++) {
        multibin::PointWithCov p;
        p.point_m = Eigen::Vector3f(0.04f * float(i) - 0.5f, 0.03f * float(i % 7) - 0.1f,
                                    (i % 9 == 0) ? 0.3f : 0.01f * float(i % 4));
        p.cov_m2 = {1e-4f, 0, 0, 1e-4f, 0, 1e-4f};
        pts.push_back(p);
    }
    return pts;
}
}  // namespace

int main(int argc, char** argv) {
    const fs::path root = argc > 1 ? argv[1] : "corpus";
    using Map = mrpt::maps::CMultiBinElevationMap;

    // map_deserialize: a single fixed grid with data, an empty map, a dual grid with data.
    {
        Map::TCreationOptions c;
        c.grow = false;
        c.min_x = -1, c.max_x = 1, c.min_y = -0.5, c.max_y = 0.5;
        c.resolution_m = 0.1;
        Map m(c);
        m.insertPoints(somePoints());
        m.insertPoints(somePoints());
        write(root / "map_deserialize", "seed_single", fuzz::serialize(m));
        write(root / "map_deserialize", "seed_empty", fuzz::serialize(Map()));
        Map::TCreationOptions d;
        d.dual_grid = true;
        d.local_size_m = 0.6, d.local_resolution_m = 0.1;
        d.global_size_m = 1.2, d.global_resolution_m = 0.2;
        Map dm(d);
        dm.insertPoints(somePoints());
        write(root / "map_deserialize", "seed_dual", fuzz::serialize(dm));
    }
    // ini_options: every key of both sections as saved, and a few hand-written ones.
    {
        mrpt::config::CConfigFileMemory ini;
        Map::TCreationOptions c;
        Map::TInsertionOptions i;
        c.saveToConfigFile(ini, "creation");
        i.saveToConfigFile(ini, "insertion");
        std::string text;
        ini.getContent(text);
        write(root / "ini_options", "seed_all_keys", text);
        write(root / "ini_options", "seed_small",
              "[creation]\nresolution = 0.05\ngrow = false\nmin_x = -1\nmax_x = 1\nmin_y = -1\n"
              "max_y = 1\n[insertion]\nsensor_labels = LASER, STEREO\nlaser_agc = LASER:512\n");
        write(root / "ini_options", "seed_dual",
              "[creation]\ndual_grid = true\nlocal_size_m = 1\nlocal_resolution = 0.05\n"
              "global_size_m = 4\nglobal_resolution = 0.1\n[insertion]\n"
              "default_pose_sigmas = 0.01 0.01 0.01 0.005 0.005 0.005\n");
    }
    // observation_insert: one input per observation kind (bounded values).
    {
        for (int kind = 0; kind < 4; kind++)
            for (int setup = 0; setup < 2; setup++) {
                std::vector<uint8_t> b;
                put<uint8_t>(b, uint8_t(setup));
                for (int k = 0; k < 3; k++) {
                    put<uint8_t>(b, uint8_t(kind));
                    for (int i = 0; i < 400; i++)
                        put<uint8_t>(b, uint8_t((i * 97 + k * 31) & 0xfe));
                }
                write(root / "observation_insert",
                      "seed_kind" + std::to_string(kind) + "_setup" + std::to_string(setup), b);
            }
    }
    return 0;
}
