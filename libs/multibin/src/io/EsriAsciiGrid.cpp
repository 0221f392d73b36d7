/* Part of the multibin elevation-mapping library. */
#include "multibin/io/EsriAsciiGrid.h"

#include "multibin/io/NumberText.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

namespace multibin {

EsriAsciiGrid EsriAsciiGrid::onLattice(const Lattice& lattice) {
    EsriAsciiGrid g;
    g.cellsize_m = lattice.cellSize_m;
    g.xllcenter_m = lattice.cellCenterX_m(0);
    g.yllcenter_m = lattice.cellCenterY_m(0);
    g.heights_m.setConstant(lattice.ny(), lattice.nx(), std::numeric_limits<float>::quiet_NaN());
    return g;
}

namespace {
[[noreturn]] void fail(const std::string& path, const std::string& what) {
    throw std::runtime_error("ESRI ASCII grid '" + path + "': " + what);
}

double parseNumber(const std::string& path, const std::string& token, const std::string& what) {
    double v = 0;
    if (!parseFiniteNumber(token, v)) fail(path, "malformed " + what + " '" + token + "'");
    return v;
}
}  // namespace

double EsriAsciiGrid::interpolate(double x_m, double y_m) const {
    const double fc = (x_m - xllcenter_m) / cellsize_m;
    const double fr = (y_m - yllcenter_m) / cellsize_m;
    if (!(fc >= 0 && fr >= 0 && fc <= cols() - 1 && fr <= rows() - 1)) return std::nan("");
    const int c0 = std::min(static_cast<int>(fc), cols() - 2);
    const int r0 = std::min(static_cast<int>(fr), rows() - 2);
    const double tx = fc - c0, ty = fr - r0;
    const double h00 = heights_m(r0, c0), h01 = heights_m(r0, c0 + 1);
    const double h10 = heights_m(r0 + 1, c0), h11 = heights_m(r0 + 1, c0 + 1);
    return (1 - ty) * ((1 - tx) * h00 + tx * h01) + ty * ((1 - tx) * h10 + tx * h11);
}

EsriAsciiGrid EsriAsciiGrid::load(const std::string& path) {
    std::ifstream in(path);
    if (!in) fail(path, "cannot open file");
    std::map<std::string, std::string> header;
    std::string key, value;
    // Six header lines; key names are case-insensitive in the format.
    for (int i = 0; i < 6; i++) {
        if (!(in >> key >> value)) fail(path, "truncated header");
        for (auto& ch : key) ch = static_cast<char>(std::tolower(ch));
        header[key] = value;
    }
    auto need = [&](const char* k) -> const std::string& {
        const auto it = header.find(k);
        if (it == header.end()) fail(path, std::string("header lacks '") + k + "'");
        return it->second;
    };
    EsriAsciiGrid g;
    const double ncols = parseNumber(path, need("ncols"), "ncols");
    const double nrows = parseNumber(path, need("nrows"), "nrows");
    if (ncols < 2 || nrows < 2 || ncols > 1e5 || nrows > 1e5 || ncols != std::floor(ncols) ||
        nrows != std::floor(nrows))
        fail(path, "ncols/nrows must be whole numbers in [2, 100000]");
    g.cellsize_m = parseNumber(path, need("cellsize"), "cellsize");
    if (!(g.cellsize_m > 0)) fail(path, "cellsize must be positive");
    if (header.count("xllcenter")) {
        g.xllcenter_m = parseNumber(path, header["xllcenter"], "xllcenter");
        g.yllcenter_m = parseNumber(path, need("yllcenter"), "yllcenter");
    } else {  // corner-registered variant
        g.xllcenter_m = parseNumber(path, need("xllcorner"), "xllcorner") + 0.5 * g.cellsize_m;
        g.yllcenter_m = parseNumber(path, need("yllcorner"), "yllcorner") + 0.5 * g.cellsize_m;
    }
    g.nodata_value = parseNumber(path, need("nodata_value"), "NODATA_value");
    const int nr = static_cast<int>(nrows), nc = static_cast<int>(ncols);
    g.heights_m.resize(nr, nc);
    std::string tok;
    for (int fileRow = 0; fileRow < nr; fileRow++) {
        const int r = nr - 1 - fileRow;  // file starts at the northern edge
        for (int c = 0; c < nc; c++) {
            if (!(in >> tok))
                fail(path, "truncated data: expected " + std::to_string(nr * nc) + " values, got " +
                               std::to_string(fileRow * nc + c));
            const double v = parseNumber(path, tok, "height value");
            g.heights_m(r, c) = v == g.nodata_value ? NAN : static_cast<float>(v);
        }
    }
    if (in >> tok) fail(path, "more values than ncols x nrows");
    return g;
}

void EsriAsciiGrid::save(const std::string& path) const {
    std::FILE* f = std::fopen(path.c_str(), "w");
    if (!f) throw std::runtime_error("ESRI ASCII grid '" + path + "': cannot open for writing");
    std::fprintf(f, "ncols %d\nnrows %d\nxllcenter %.6f\nyllcenter %.6f\ncellsize %.9f\n", cols(),
                 rows(), xllcenter_m, yllcenter_m, cellsize_m);
    std::fprintf(f, "NODATA_value %g\n", nodata_value);
    for (int r = rows() - 1; r >= 0; r--) {
        for (int c = 0; c < cols(); c++) {
            const float v = heights_m(r, c);
            std::fprintf(f, c ? " %.6f" : "%.6f", std::isnan(v) ? nodata_value : double(v));
        }
        std::fputc('\n', f);
    }
    if (std::fclose(f) != 0)
        throw std::runtime_error("ESRI ASCII grid '" + path + "': write failed");
}

}  // namespace multibin
