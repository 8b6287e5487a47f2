// region ID mesh/tet file F scale S move DX DY DZ rotate PHIX PHIY PHIZ
// [keywords]: the volume of the tetrahedra of a legacy ASCII VTK file
// (DATASET UNSTRUCTURED_GRID, cells of type 10; the vertices, lines and
// triangles a mesher writes beside them are skipped). The points are moved
// by (DX, DY, DZ), then scaled by S about the origin, then rotated by PHIX
// degrees about x, PHIY about y and PHIZ about z, in that order. A point is
// inside when it lies inside a tetrahedron or on a face between two of them;
// a point of the mesh's surface (a face of one tetrahedron only) is outside,
// as in LIGGGHTS 3.8. The tetrahedra are found through a uniform grid of
// cells over the mesh's bounds.
#include <mpi.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "core/engine.h"
#include "core/error.h"
#include "core/logger.h"
#include "core/registry.h"
#include "domain/domain.h"
#include "domain/region.h"

namespace granary {

namespace {

const char* kUsage =
    "region ID mesh/tet file F.vtk scale S move DX DY DZ rotate PHIX PHIY PHIZ [side in|out]";
const char* kVtkHint =
    " (region mesh/tet reads legacy ASCII VTK files: '# vtk DataFile Version ...', a title line, ASCII, "
    "DATASET UNSTRUCTURED_GRID, POINTS, CELLS and CELL_TYPES; see doc/commands/region.md)";

/// The words of a file with their line numbers.
struct Words {
  std::vector<std::pair<std::string, int>> w;
  std::size_t at = 0;
  std::string file;
  int last_line = 0;
  bool done() const { return at >= w.size(); }
  std::string where() const {
    return "VTK file '" + file + "' line " + std::to_string(at < w.size() ? w[at].second : last_line);
  }
  std::string found() const { return at < w.size() ? "'" + w[at].first + "'" : "the end of the file"; }
};

std::string upper(std::string s) {
  for (char& c : s)
    c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

// Reads the points and the tetrahedra (4 point indices each) of a legacy ASCII
// VTK unstructured grid; returns "" or what is wrong, with its line.
std::string read_vtk_tets(const std::string& file, std::vector<Vec3>& points, std::vector<int>& tets) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(file, ec)) return "VTK file '" + file + "' does not exist; check the name and directory";
  if (!fs::is_regular_file(file, ec)) return "'" + file + "' is not a regular file";
  std::ifstream in(file);
  if (!in) return "cannot open VTK file '" + file + "' for reading";
  Words t;
  t.file = file;
  std::string line;
  int lineno = 0;
  // the first two lines: the version line and a free title
  for (int k = 0; k < 2; ++k) {
    if (!std::getline(in, line)) return "VTK file '" + file + "' ends before its title line" + kVtkHint;
    ++lineno;
    if (k == 0 && line.rfind("# vtk DataFile", 0) != 0) {
      return "VTK file '" + file + "' line 1: expected '# vtk DataFile Version ...', found '" +
             line.substr(0, 40) + "'" + kVtkHint;
    }
  }
  while (std::getline(in, line)) {
    ++lineno;
    std::istringstream ls(line);
    std::string word;
    while (ls >> word)
      t.w.emplace_back(word, lineno);
  }
  t.last_line = lineno;
  auto expect = [&](const char* want) -> std::string {
    if (!t.done() && upper(t.w[t.at].first) == want) {
      ++t.at;
      return "";
    }
    return t.where() + ": expected '" + want + "', found " + t.found() + kVtkHint;
  };
  auto count = [&](long long& n, const char* what) -> std::string {
    if (t.done()) return t.where() + ": expected " + what + ", found the end of the file" + kVtkHint;
    const std::string& s = t.w[t.at].first;
    char* end = nullptr;
    n = std::strtoll(s.c_str(), &end, 10);
    if (end == s.c_str() || *end != '\0' || n < 0)
      return t.where() + ": '" + s + "' is not " + what + kVtkHint;
    ++t.at;
    return "";
  };
  if (t.done()) return "VTK file '" + file + "' has no data after its title" + kVtkHint;
  if (upper(t.w[0].first) == "BINARY") {
    return t.where() +
           ": a binary VTK file; region mesh/tet reads ASCII files only (write it as ASCII, e.g. "
           "with gmsh's or ParaView's ASCII option)";
  }
  std::string err;
  if (!(err = expect("ASCII")).empty() || !(err = expect("DATASET")).empty()) return err;
  if (t.done() || upper(t.w[t.at].first) != "UNSTRUCTURED_GRID") {
    return t.where() + ": the dataset is " + t.found() + "; region mesh/tet needs an UNSTRUCTURED_GRID" +
           kVtkHint;
  }
  ++t.at;
  if (!(err = expect("POINTS")).empty()) return err;
  long long np = 0;
  if (!(err = count(np, "a number of points")).empty()) return err;
  if (t.done()) return t.where() + ": expected the type of the points, found the end of the file" + kVtkHint;
  ++t.at;  // float, double, ...
  points.resize(static_cast<std::size_t>(np));
  for (long long i = 0; i < np; ++i) {
    for (int c = 0; c < 3; ++c) {
      if (t.done()) {
        return t.where() + ": the file ends after " + std::to_string(i) + " of its " + std::to_string(np) +
               " points (a truncated file?)";
      }
      const std::string& s = t.w[t.at].first;
      char* end = nullptr;
      const double v = std::strtod(s.c_str(), &end);
      if (end == s.c_str() || *end != '\0' || !std::isfinite(v)) {
        return t.where() + ": '" + s + "' is not a finite number (point " + std::to_string(i) + ")" +
               kVtkHint;
      }
      points[static_cast<std::size_t>(i)][c] = v;
      ++t.at;
    }
  }
  if (!(err = expect("CELLS")).empty()) return err;
  long long nc = 0, size = 0;
  if (!(err = count(nc, "a number of cells")).empty() || !(err = count(size, "a list size")).empty())
    return err;
  std::vector<std::vector<long long>> cells(static_cast<std::size_t>(nc));
  for (long long c = 0; c < nc; ++c) {
    long long k = 0;
    const std::size_t at_cell = t.at;
    if (t.done()) {
      return t.where() + ": the file ends after " + std::to_string(c) + " of its " + std::to_string(nc) +
             " cells (a truncated file?)";
    }
    if (!(err = count(k, "a number of cell points")).empty()) return err;
    for (long long j = 0; j < k; ++j) {
      long long p = 0;
      if (t.done()) {
        return t.where() + ": the file ends inside cell " + std::to_string(c) + " (a truncated file?)";
      }
      if (!(err = count(p, "a point index")).empty()) return err;
      if (p >= np) {
        t.at = at_cell;
        return t.where() + ": cell " + std::to_string(c) + " uses point " + std::to_string(p) +
               " but there are " + std::to_string(np) + " points (0.." + std::to_string(np - 1) + ")";
      }
      cells[static_cast<std::size_t>(c)].push_back(p);
    }
  }
  if (!(err = expect("CELL_TYPES")).empty()) return err;
  long long nt = 0;
  if (!(err = count(nt, "a number of cell types")).empty()) return err;
  if (nt != nc) {
    --t.at;
    return t.where() + ": CELL_TYPES has " + std::to_string(nt) + " entries but CELLS has " +
           std::to_string(nc) + kVtkHint;
  }
  for (long long c = 0; c < nc; ++c) {
    long long type = 0;
    if (t.done()) {
      return t.where() + ": the file ends after " + std::to_string(c) + " of its " + std::to_string(nc) +
             " cell types (a truncated file?)";
    }
    if (!(err = count(type, "a cell type")).empty()) return err;
    if (type != 10) continue;  // VTK_TETRA
    const auto& cell = cells[static_cast<std::size_t>(c)];
    if (cell.size() != 4) {
      --t.at;
      return t.where() + ": cell " + std::to_string(c) + " is a tetrahedron (type 10) with " +
             std::to_string(cell.size()) + " points";
    }
    for (long long p : cell)
      tets.push_back(static_cast<int>(p));
  }
  if (tets.empty()) return "VTK file '" + file + "' holds no tetrahedra (cells of type 10)" + kVtkHint;
  return "";
}

class RegionMeshTet : public Region {
 public:
  RegionMeshTet(Engine& engine, const Args& args) : Region(engine, args, 12) {
    const std::string what = "region " + id + " (mesh/tet)";
    auto keyword = [&](std::size_t k, const char* want) {
      if (args[k] != want) {
        throw InputError(what + ": expected '" + want + "' at argument " + std::to_string(k + 1) +
                         ", found '" + args[k] + "'; usage: " + kUsage);
      }
    };
    keyword(2, "file");
    keyword(4, "scale");
    keyword(6, "move");
    keyword(10, "rotate");
    if (scale[0] != 1.0 || scale[1] != 1.0 || scale[2] != 1.0) {
      throw InputError(what + ": the mesh is in box units; use units box (scale it with the scale keyword)");
    }
    const std::string file = args[3];
    const double s = parse_double(args[5], what + " scale");
    if (!(s > 0.0)) throw InputError(what + ": scale must be positive, got " + args[5]);
    Vec3 move, phi;
    for (int c = 0; c < 3; ++c) {
      move[c] = parse_double(args[7 + c], what + " move");
      phi[c] = parse_double(args[11 + c], what + " rotate") * M_PI / 180.0;
    }

    // rank 0 reads, every rank gets the mesh
    std::vector<Vec3> points;
    std::vector<int> tets;
    std::string err;
    if (engine.rank == 0) err = read_vtk_tets(file, points, tets);
    int len = static_cast<int>(err.size());
    MPI_Bcast(&len, 1, MPI_INT, 0, engine.world);
    err.resize(static_cast<std::size_t>(len));
    if (len > 0) MPI_Bcast(err.data(), len, MPI_CHAR, 0, engine.world);
    if (!err.empty()) throw InputError(what + ": " + err);
    long long n[2] = {static_cast<long long>(points.size()), static_cast<long long>(tets.size())};
    MPI_Bcast(n, 2, MPI_LONG_LONG, 0, engine.world);
    points.resize(static_cast<std::size_t>(n[0]));
    tets.resize(static_cast<std::size_t>(n[1]));
    MPI_Bcast(points.data(), static_cast<int>(3 * n[0]), MPI_DOUBLE, 0, engine.world);
    MPI_Bcast(tets.data(), static_cast<int>(n[1]), MPI_INT, 0, engine.world);

    const Eigen::Matrix3d rot =
        (Eigen::AngleAxisd(phi[2], Vec3::UnitZ()) * Eigen::AngleAxisd(phi[1], Vec3::UnitY()) *
         Eigen::AngleAxisd(phi[0], Vec3::UnitX()))
            .toRotationMatrix();
    for (Vec3& p : points)
      p = rot * (s * (p + move));

    // each tetrahedron as its first corner and the inverse of its edge matrix
    const std::size_t ntet = tets.size() / 4;
    tet_.reserve(ntet);
    lo_ = Vec3::Constant(HUGE_VAL);
    hi_ = Vec3::Constant(-HUGE_VAL);
    std::vector<std::pair<Vec3, Vec3>> boxes;
    for (std::size_t k = 0; k < ntet; ++k) {
      const Vec3& a = points[static_cast<std::size_t>(tets[4 * k])];
      Eigen::Matrix3d e;
      Vec3 blo = a, bhi = a;
      for (int j = 0; j < 3; ++j) {
        const Vec3& b = points[static_cast<std::size_t>(tets[4 * k + 1 + static_cast<std::size_t>(j)])];
        e.col(j) = b - a;
        blo = blo.cwiseMin(b);
        bhi = bhi.cwiseMax(b);
      }
      const double det = e.determinant();
      const double edge = std::max({e.col(0).norm(), e.col(1).norm(), e.col(2).norm()});
      if (!(std::abs(det) > 1e-12 * edge * edge * edge)) {
        throw InputError(what + ": tetrahedron " + std::to_string(k) + " of '" + file +
                         "' is flat (its four corners lie in a plane); remove it from the mesh");
      }
      volume_ += std::abs(det) / 6.0;
      tet_.push_back({a, e.inverse(), {false, false, false, false}});
      boxes.emplace_back(blo, bhi);
      lo_ = lo_.cwiseMin(blo);
      hi_ = hi_.cwiseMax(bhi);
    }

    // a periodic box does not map the mesh (a region is not periodic)
    const Domain& dom = *engine.domain;
    if (dom.box_exist) {
      for (int d = 0; d < 3; ++d) {
        if (dom.periodic[static_cast<std::size_t>(d)] && (lo_[d] < dom.boxlo[d] || hi_[d] > dom.boxhi[d])) {
          engine.logger->warning(what + ": the mesh reaches beyond the periodic box in " +
                                 std::string(1, "xyz"[d]) +
                                 "; the region is not mapped across the periodic boundary");
        }
      }
    }

    // the faces of one tetrahedron only make the surface
    std::map<std::array<int, 3>, int> faces;
    auto face = [&](std::size_t k, int j) {
      std::array<int, 3> f;
      int m = 0;
      for (int c = 0; c < 4; ++c)
        if (c != j) f[static_cast<std::size_t>(m++)] = tets[4 * k + static_cast<std::size_t>(c)];
      std::sort(f.begin(), f.end());
      return f;
    };
    for (std::size_t k = 0; k < ntet; ++k)
      for (int j = 0; j < 4; ++j)
        ++faces[face(k, j)];
    for (std::size_t k = 0; k < ntet; ++k)
      for (int j = 0; j < 4; ++j)
        tet_[k].outer[j] = faces[face(k, j)] == 1;

    // a uniform grid of about one cell per tetrahedron over the bounds
    const Vec3 ext = (hi_ - lo_).cwiseMax(1e-300);
    const double cell = std::cbrt(ext.prod() / static_cast<double>(ntet));
    for (int d = 0; d < 3; ++d) {
      nbin_[d] = std::clamp(static_cast<int>(std::ceil(ext[d] / std::max(cell, 1e-300))), 1, 256);
      inv_bin_[d] = nbin_[d] / ext[d];
    }
    start_.assign(static_cast<std::size_t>(nbin_[0]) * nbin_[1] * nbin_[2] + 1, 0);
    auto range = [&](const Vec3& blo, const Vec3& bhi, int ilo[3], int ihi[3]) {
      for (int d = 0; d < 3; ++d) {
        ilo[d] = bin_of(blo[d], d);
        ihi[d] = bin_of(bhi[d], d);
      }
    };
    for (int pass = 0; pass < 2; ++pass) {
      std::vector<int> fill;
      if (pass == 1) {
        for (std::size_t b = 1; b < start_.size(); ++b)
          start_[b] += start_[b - 1];
        list_.resize(static_cast<std::size_t>(start_.back()));
        fill.assign(start_.begin(), start_.end() - 1);
      }
      for (std::size_t k = 0; k < ntet; ++k) {
        int ilo[3], ihi[3];
        range(boxes[k].first, boxes[k].second, ilo, ihi);
        for (int i = ilo[0]; i <= ihi[0]; ++i)
          for (int j = ilo[1]; j <= ihi[1]; ++j)
            for (int l = ilo[2]; l <= ihi[2]; ++l) {
              const std::size_t b = bin_index(i, j, l);
              if (pass == 0)
                ++start_[b + 1];
              else
                list_[static_cast<std::size_t>(fill[b]++)] = static_cast<int>(k);
            }
      }
    }
  }

  bool inside(const Vec3& x) const override {
    for (int d = 0; d < 3; ++d)
      if (x[d] < lo_[d] || x[d] > hi_[d]) return false;
    const std::size_t b = bin_index(bin_of(x[0], 0), bin_of(x[1], 1), bin_of(x[2], 2));
    // every tetrahedron whose closure holds x is in the cell's list
    bool closure = false, surface = false;
    for (int k = start_[b]; k < start_[b + 1]; ++k) {
      const Tet& t = tet_[static_cast<std::size_t>(list_[static_cast<std::size_t>(k)])];
      const Vec3 l = t.inv * (x - t.a);  // barycentric coordinates of corners 1-3
      const double lam[4] = {1.0 - l.sum(), l[0], l[1], l[2]};
      if (lam[0] > kTol && lam[1] > kTol && lam[2] > kTol && lam[3] > kTol) return true;
      if (lam[0] < -kTol || lam[1] < -kTol || lam[2] < -kTol || lam[3] < -kTol) continue;
      // on this tetrahedron's surface: outside when on a face of the mesh's surface
      closure = true;
      for (int j = 0; j < 4; ++j)
        surface = surface || (lam[j] <= kTol && t.outer[j]);
    }
    return closure && !surface;
  }

  bool bounds(Vec3& lo, Vec3& hi) const override {
    if (!interior) return false;
    lo = lo_;
    hi = hi_;
    return true;
  }

  double volume() const override { return interior ? volume_ : -1.0; }

 private:
  static constexpr double kTol = 1e-12;
  struct Tet {
    Vec3 a;
    Eigen::Matrix3d inv;
    bool outer[4];  // face opposite corner j is a face of the mesh's surface
  };
  int bin_of(double v, int d) const {
    return std::clamp(static_cast<int>((v - lo_[d]) * inv_bin_[d]), 0, nbin_[d] - 1);
  }
  std::size_t bin_index(int i, int j, int l) const {
    return (static_cast<std::size_t>(l) * static_cast<std::size_t>(nbin_[1]) + static_cast<std::size_t>(j)) *
               static_cast<std::size_t>(nbin_[0]) +
           static_cast<std::size_t>(i);
  }
  std::vector<Tet> tet_;
  Vec3 lo_, hi_;
  double volume_ = 0.0;
  int nbin_[3] = {1, 1, 1};
  double inv_bin_[3] = {1, 1, 1};
  std::vector<int> start_, list_;
};

}  // namespace

GRANARY_REGION_STYLE("mesh/tet", RegionMeshTet);

}  // namespace granary
