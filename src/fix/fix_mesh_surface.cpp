#include "fix/fix_mesh_surface.h"

#include <mpi.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cctype>
#include <cstdlib>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <stdexcept>

#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "core/global_property.h"
#include "core/modify.h"
#include "particles/particles.h"

namespace granary {

namespace {

const char* kUsage =
    "fix ID group mesh/surface file F.stl type T [scale S] [move dx dy dz] "
    "[rotate axis ax ay az angle DEG] [curvature_tolerant yes|no] [surface_vel VX VY VZ]";

// A binary STL is an 80-byte header, a 32-bit little-endian triangle count N
// and N records of 50 bytes: its size must be 84 + 50 N. A file cut inside its
// last triangle would otherwise load with one triangle fewer and no message
// (a hole in the wall), and a count larger than the file would make a reader
// allocate for it. A file is binary when 5 % or more of its first 256 bytes
// are not text (bytes 0x20-0x7f, tab, CR, LF), whatever it starts with (VTK's
// STL reader, which ParaView uses, decides the same way).
std::string stl_head(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  std::string head(256, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  return head;
}

bool is_binary_stl(const std::string& head) {
  std::size_t text = 0;
  for (const char c : head) {
    const auto u = static_cast<unsigned char>(c);
    if ((u >= 0x20 && u <= 0x7f) || c == '\n' || c == '\r' || c == '\t') ++text;
  }
  return !head.empty() && static_cast<double>(head.size() - text) >= 0.05 * static_cast<double>(head.size());
}

// Returns "" or what is wrong with the size of a binary STL.
std::string check_binary_size(const std::string& file) {
  std::string head = stl_head(file);
  if (!is_binary_stl(head)) return "";
  const std::size_t first = head.find_first_not_of(" \t\r\n");
  const std::string as =
      first != std::string::npos && head.compare(first, 5, "solid") == 0 &&
              head.find("facet") != std::string::npos
          ? " (it starts like an ASCII STL, but 5 % or more of its first 256 bytes are not "
            "text, so it is read as binary)"
          : "";
  head.resize(std::min<std::size_t>(head.size(), 84));
  std::error_code ec;
  const auto size = static_cast<unsigned long long>(std::filesystem::file_size(file, ec));
  if (ec) return "";
  if (size < 84) {
    return "binary STL file '" + file + "'" + as + " has " + std::to_string(size) +
           " bytes, fewer than the 84 of its header and triangle count; the file is cut or not an STL";
  }
  const auto* b = reinterpret_cast<const unsigned char*>(head.data() + 80);
  const unsigned long long n =
      b[0] | (b[1] << 8) | (b[2] << 16) | (static_cast<unsigned long long>(b[3]) << 24);
  const unsigned long long expect = 84 + 50 * n;
  if (size == expect) return "";
  if (size < expect) {
    const unsigned long long whole = (size - 84) / 50;
    return "binary STL file '" + file + "'" + as + " is cut: its header announces " + std::to_string(n) +
           " triangles (" + std::to_string(expect) + " bytes) but the file has " + std::to_string(size) +
           " bytes, so triangle " + std::to_string(whole + 1) + " ends at byte " + std::to_string(size) +
           " instead of " + std::to_string(84 + 50 * (whole + 1)) + "; write the file again";
  }
  return "binary STL file '" + file + "'" + as + " has " + std::to_string(size - expect) +
         " bytes after the " + std::to_string(n) + " triangles its header announces (" +
         std::to_string(expect) + " bytes); the triangle count or the file is wrong";
}

// Coordinates are kept in single precision, as a binary STL holds them (and
// as VTK's reader keeps those of ASCII files too): each number of an ASCII
// file is rounded to the nearest float.
const char* const kStlHint =
    "; the file must be an ASCII STL (solid ... facet normal ... endsolid) or a binary STL";

// The triangles of a binary STL whose size check_binary_size() accepted.
std::string read_binary_stl(const std::string& file, std::vector<Vec3>& corners) {
  std::ifstream in(file, std::ios::binary);
  unsigned char head[84];
  in.read(reinterpret_cast<char*>(head), 84);
  const std::uint32_t n =
      head[80] | (head[81] << 8) | (head[82] << 16) | (static_cast<std::uint32_t>(head[83]) << 24);
  if (n == 0) return "STL file '" + file + "' holds no triangles" + kStlHint;
  corners.reserve(3 * static_cast<std::size_t>(n));
  unsigned char rec[50];
  auto float_at = [&](int at) {
    const std::uint32_t bits = rec[at] | (rec[at + 1] << 8) | (rec[at + 2] << 16) |
                               (static_cast<std::uint32_t>(rec[at + 3]) << 24);  // little-endian
    float f;
    std::memcpy(&f, &bits, 4);
    return static_cast<double>(f);
  };
  for (std::uint32_t t = 0; t < n; ++t) {
    if (!in.read(reinterpret_cast<char*>(rec), 50)) return "cannot read STL file '" + file + "'" + kStlHint;
    for (int c = 0; c < 3; ++c)  // after the 12 bytes of the normal
      corners.emplace_back(float_at(12 + 12 * c), float_at(16 + 12 * c), float_at(20 + 12 * c));
  }
  return "";
}

// The triangles of an ASCII STL: one or more solids of facets,
//   solid NAME / facet normal NX NY NZ / outer loop / vertex X Y Z (three) /
//   endloop / endfacet / ... / endsolid NAME
// keywords in any case; a mistake is reported with its line.
std::string read_ascii_stl(const std::string& file, std::vector<Vec3>& corners) {
  std::ifstream in(file);
  std::string line;
  int lineno = 0;
  std::vector<std::pair<std::string, int>> tokens;  // word, line
  while (std::getline(in, line)) {
    ++lineno;
    const std::string lower_first = [&] {
      const std::size_t a = line.find_first_not_of(" \t\r");
      std::string w = a == std::string::npos ? "" : line.substr(a, line.find_first_of(" \t\r", a) - a);
      for (char& ch : w)
        ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
      return w;
    }();
    if (lower_first == "solid" || lower_first == "endsolid") {  // the name is the rest of the line
      tokens.emplace_back(lower_first, lineno);
      continue;
    }
    for (std::size_t k = 0; k < line.size();) {
      const std::size_t a = line.find_first_not_of(" \t\r", k);
      if (a == std::string::npos) break;
      const std::size_t b = std::min(line.find_first_of(" \t\r", a), line.size());
      tokens.emplace_back(line.substr(a, b - a), lineno);
      k = b;
    }
  }
  std::size_t at = 0;
  auto where = [&](std::size_t i) {
    return "STL file '" + file + "' line " + std::to_string(i < tokens.size() ? tokens[i].second : lineno);
  };
  auto keyword = [&](std::size_t i) {
    std::string w = i < tokens.size() ? tokens[i].first : "";
    for (char& ch : w)
      ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    return w;
  };
  auto found = [&](std::size_t i) {
    return i < tokens.size() ? "'" + tokens[i].first + "'" : std::string("the end of the file");
  };
  std::string err;
  auto expect = [&](const char* w) {
    if (keyword(at) == w) {
      ++at;
      return true;
    }
    err = where(at) + ": expected '" + w + "', found " + found(at) + kStlHint;
    return false;
  };
  auto number = [&](double& v) {
    if (at >= tokens.size()) {
      err = where(at) + ": expected a number, found the end of the file" + kStlHint;
      return false;
    }
    const std::string& w = tokens[at].first;
    char* end = nullptr;
    const float f = std::strtof(w.c_str(), &end);
    if (end == w.c_str() || *end != '\0' || !std::isfinite(f)) {
      err = where(at) + ": '" + w + "' is not a finite number" + kStlHint;
      return false;
    }
    v = f;
    ++at;
    return true;
  };
  if (tokens.empty()) return "STL file '" + file + "' is empty" + kStlHint;
  while (at < tokens.size()) {
    if (!expect("solid")) return err;
    while (keyword(at) == "facet") {
      ++at;
      double nrm;
      if (!expect("normal")) return err;
      for (int c = 0; c < 3; ++c)
        if (!number(nrm)) return err;
      if (!expect("outer") || !expect("loop")) return err;
      for (int c = 0; c < 3; ++c) {
        Vec3 v;
        if (!expect("vertex") || !number(v[0]) || !number(v[1]) || !number(v[2])) return err;
        corners.push_back(v);
      }
      if (keyword(at) == "vertex") {
        return where(at) + ": a facet with more than three vertices; only triangles are read" + kStlHint;
      }
      if (!expect("endloop") || !expect("endfacet")) return err;
    }
    if (!expect("endsolid")) return err;
  }
  if (corners.empty()) return "STL file '" + file + "' holds no triangles" + kStlHint;
  return "";
}

// Rank 0: read the triangle corners of an STL file (ASCII or binary); returns
// "" or what is wrong, with the way to fix it.
std::string read_stl(const std::string& file, std::vector<Vec3>& corners) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(file, ec)) return "STL file '" + file + "' does not exist; check the name and directory";
  if (!fs::is_regular_file(file, ec)) return "'" + file + "' is not a regular file";
  if (!std::ifstream(file, std::ios::binary)) return "cannot open STL file '" + file + "' for reading";
  if (std::string why = check_binary_size(file); !why.empty()) return why;
  const std::string why =
      is_binary_stl(stl_head(file)) ? read_binary_stl(file, corners) : read_ascii_stl(file, corners);
  if (!why.empty()) return why;
  for (const Vec3& v : corners)
    if (!v.allFinite()) return "STL file '" + file + "' has a corner that is not a finite number";
  return "";
}

void put_bytes(std::string& out, const void* p, std::size_t n) {
  out.append(static_cast<const char*>(p), n);
}

}  // namespace

FixMeshSurface::FixMeshSurface(Engine& engine, const Args& args, bool stress) : Fix(engine, args) {
  restart_global = true;
  const std::string where = "fix " + id + " " + style;
  if (args.size() < 5) throw InputError(where + ": missing arguments; usage: " + std::string(kUsage));
  if (args[3] != "file") {
    throw InputError(where +
                     ": the first keyword must be 'file' (a fix-generated mesh is not supported); usage: " +
                     std::string(kUsage));
  }
  file = args[4];
  // Transformations in the order given (LIGGGHTS applies them that way).
  struct Transform {
    char kind;  // 's' scale, 'm' move, 'r' rotate
    Vec3 v;
    double value;
  };
  std::vector<Transform> transforms;
  bool have_type = false, heal = false;
  std::size_t k = 5;
  auto need = [&](std::size_t n, const std::string& key) {
    if (k + n > args.size())
      throw InputError(where + ": '" + key + "' needs " + std::to_string(n) + " value(s); usage: " + kUsage);
  };
  while (k < args.size()) {
    const std::string& key = args[k];
    if (key == "type") {
      need(2, key);
      wall_type = static_cast<int>(parse_int(args[k + 1], where + " type"));
      if (wall_type < 1 || wall_type > engine.particles->ntypes) {
        throw InputError(where + ": type " + args[k + 1] + " is outside 1.." +
                         std::to_string(engine.particles->ntypes) + " (the atom types of create_box)");
      }
      have_type = true;
      k += 2;
    } else if (key == "scale") {
      need(2, key);
      const double s = parse_double(args[k + 1], where + " scale");
      if (!(s > 0.0)) throw InputError(where + ": scale must be positive, got " + args[k + 1]);
      transforms.push_back({'s', Vec3::Zero(), s});
      k += 2;
    } else if (key == "move") {
      need(4, key);
      Vec3 d;
      for (int c = 0; c < 3; ++c)
        d[c] = parse_double(args[k + 1 + c], where + " move");
      transforms.push_back({'m', d, 0.0});
      k += 4;
    } else if (key == "rotate") {
      need(7, key);
      if (args[k + 1] != "axis" || args[k + 5] != "angle") {
        throw InputError(where + ": expected 'rotate axis ax ay az angle DEG', got 'rotate " + args[k + 1] +
                         " ...'");
      }
      Vec3 axis;
      for (int c = 0; c < 3; ++c)
        axis[c] = parse_double(args[k + 2 + c], where + " rotate axis");
      if (!(axis.norm() > 0.0)) throw InputError(where + ": the rotation axis must not be zero");
      transforms.push_back({'r', axis.normalized(), parse_double(args[k + 6], where + " rotate angle")});
      k += 7;
    } else if (stress && key == "stress") {
      need(2, key);
      if (args[k + 1] != "on")
        throw InputError(
            where + ": 'stress " + args[k + 1] +
            "' is not supported; the forces on the triangles are always summed (use mesh/surface "
            "for a mesh without stress output)");
      k += 2;
    } else if (stress && key == "wear") {
      need(2, key);
      if (args[k + 1] == "finnie") {
        wear_finnie = true;
      } else if (args[k + 1] != "off") {
        throw InputError(where + ": 'wear " + args[k + 1] +
                         "' is not a wear model; use 'wear finnie' (Finnie's erosion model, with fix "
                         "property/global k_finnie peratomtypepair) or 'wear off'");
      }
      k += 2;
    } else if (stress && key == "reference_point") {
      need(4, key);
      for (int c = 0; c < 3; ++c)
        reference_point_[c] = parse_double(args[k + 1 + c], where + " reference_point");
      k += 4;
    } else if (key == "surface_vel") {
      need(4, key);
      for (int c = 0; c < 3; ++c)
        surface_vel_[c] = parse_double(args[k + 1 + c], where + " surface_vel");
      has_surface_vel_ = true;
      k += 4;
    } else if (key == "verbose" || key == "curvature_tolerant") {
      need(2, key);
      parse_bool(args[k + 1], where + " " + key);
      k += 2;
    } else if (key == "heal") {
      need(2, key);
      if (args[k + 1] != "auto_remove_duplicates" && args[k + 1] != "no")
        throw InputError(where + ": heal takes auto_remove_duplicates or no, got '" + args[k + 1] + "'");
      heal = args[k + 1] == "auto_remove_duplicates";
      k += 2;
    } else if (key == "curvature" || key == "precision") {
      need(2, key);
      const double v = parse_double(args[k + 1], where + " " + key);
      if (!(v > 0.0)) throw InputError(where + ": " + key + " must be positive");
      k += 2;
    } else if (key == "region" || key == "element_exclusion_list" || key == "min_feature_length" ||
               key == "temperature" || key == "mass_temperature" || key == "extrude_planar" ||
               key == "surface_ang_vel") {
      throw InputError(where + ": keyword '" + key +
                       "' is not supported; see doc/fixes/mesh_surface.md for the keywords Granary reads");
    } else {
      throw InputError(where + ": unknown keyword '" + key + "'; usage: " + kUsage);
    }
  }
  if (!have_type) throw InputError(where + ": missing 'type T' (the material of the wall); usage: " + kUsage);

  // rank 0 reads, every rank gets the corners
  std::vector<Vec3> corners;
  std::string err;
  if (engine.rank == 0) err = read_stl(file, corners);
  int len = static_cast<int>(err.size());
  MPI_Bcast(&len, 1, MPI_INT, 0, engine.world);
  err.resize(len);
  if (len > 0) MPI_Bcast(err.data(), len, MPI_CHAR, 0, engine.world);
  if (!err.empty()) throw InputError(where + ": " + err);
  long long n = static_cast<long long>(corners.size());
  MPI_Bcast(&n, 1, MPI_LONG_LONG, 0, engine.world);
  corners.resize(n);
  MPI_Bcast(corners.data(), static_cast<int>(3 * n), MPI_DOUBLE, 0, engine.world);

  corners.push_back(reference_point_);  // transformed with the mesh (taken off below)
  for (const Transform& t : transforms) {
    for (Vec3& v : corners) {
      if (t.kind == 's')
        v *= t.value;
      else if (t.kind == 'm')
        v += t.v;
      else
        v = Eigen::AngleAxisd(t.value * M_PI / 180.0, t.v) * v;
    }
  }
  reference_point_ = corners.back();
  corners.pop_back();
  // duplicate triangles (the same three corners): removed with heal
  // auto_remove_duplicates, an error otherwise (as in LIGGGHTS)
  {
    std::set<std::array<double, 9>> seen;
    std::vector<Vec3> kept;
    for (std::size_t t = 0; t < corners.size() / 3; ++t) {
      std::array<std::array<double, 3>, 3> c;
      for (int j = 0; j < 3; ++j)
        c[j] = {corners[3 * t + j][0], corners[3 * t + j][1], corners[3 * t + j][2]};
      std::sort(c.begin(), c.end());
      std::array<double, 9> key;
      for (int j = 0; j < 3; ++j)
        for (int d = 0; d < 3; ++d)
          key[3 * j + d] = c[j][d];
      if (!seen.insert(key).second) {
        if (heal) continue;
        throw InputError(where + ": triangle " + std::to_string(t + 1) + " of '" + file +
                         "' duplicates an earlier one; remove it from the file or add "
                         "'heal auto_remove_duplicates'");
      }
      for (int j = 0; j < 3; ++j)
        kept.push_back(corners[3 * t + j]);
    }
    corners.swap(kept);
  }
  try {
    mesh.set_triangles(corners);
  } catch (const std::invalid_argument& e) {
    throw InputError(where + ": " + e.what() + " in '" + file +
                     "'; repair the mesh in a CAD or mesh tool (or check scale)");
  }
}

void FixMeshSurface::init() {
  if (wear_finnie) {
    const GlobalProperty& kf = engine_.modify->require_property(
        "k_finnie", "fix " + id + " " + style + " wear finnie (Finnie's wear constant per pair of types)");
    const int ntypes = engine_.particles->ntypes;
    k_finnie.assign(ntypes + 1, 0.0);
    for (int t = 1; t <= ntypes; ++t)
      k_finnie[t] = kf.per_pair(t, wall_type);
    if (mesh.tri_wear.size() != static_cast<std::size_t>(mesh.ntri())) mesh.tri_wear.assign(mesh.ntri(), 0.0);
  }
  // fix move/mesh, if any, sets the motion again in its init (called after this one)
  mesh.velocity.setZero();
  mesh.omega.setZero();
  // conveyor belt: on each triangle the surface moves along the projection of
  // surface_vel onto the triangle's plane, with the full speed |surface_vel|
  // (so a curved belt runs at one speed everywhere); zero where surface_vel
  // is normal to the triangle
  mesh.surface_velocity.clear();
  if (has_surface_vel_) {
    mesh.surface_velocity.resize(mesh.ntri());
    const double speed = surface_vel_.norm();
    for (int t = 0; t < mesh.ntri(); ++t) {
      const Vec3& n = mesh.normal(t);
      const Vec3 tangential = surface_vel_ - surface_vel_.dot(n) * n;
      const double len = tangential.norm();
      mesh.surface_velocity[t] = len > 1e-12 * speed ? Vec3(tangential * (speed / len)) : Vec3::Zero();
    }
  }
}

void FixMeshSurface::pre_force() {
  for (Vec3& f : mesh.tri_force)
    f.setZero();
  for (Vec3& m : mesh.tri_moment)
    m.setZero();
}

void FixMeshSurface::prepare_restart() {
  // the wear of every rank's contacts, summed on rank 0 (which writes the state)
  if (!wear_finnie) return;
  wear_total_.assign(mesh.ntri(), 0.0);
  if (!mesh.tri_wear.empty())
    MPI_Reduce(mesh.tri_wear.data(), wear_total_.data(), mesh.ntri(), MPI_DOUBLE, MPI_SUM, 0, engine_.world);
}

void FixMeshSurface::pack_restart(std::string& out) const {
  const std::uint64_t ntri = mesh.ntri(), nnodes = mesh.nnodes();
  put_bytes(out, &ntri, sizeof ntri);
  put_bytes(out, &nnodes, sizeof nnodes);
  for (int k = 0; k < mesh.nnodes(); ++k)
    put_bytes(out, mesh.node(k).data(), 3 * sizeof(double));
  // wear finnie: the accumulated wear of every triangle after the nodes
  if (wear_finnie && wear_total_.size() == ntri) put_bytes(out, wear_total_.data(), ntri * sizeof(double));
}

void FixMeshSurface::unpack_restart(const std::string& in) {
  std::uint64_t ntri = 0, nnodes = 0;
  if (in.size() < 2 * sizeof(std::uint64_t))
    throw InputError("fix " + id + " mesh/surface: bad restart state");
  std::memcpy(&ntri, in.data(), sizeof ntri);
  std::memcpy(&nnodes, in.data() + sizeof ntri, sizeof nnodes);
  const std::size_t base = 2 * sizeof(std::uint64_t) + nnodes * 3 * sizeof(double);
  if (ntri != static_cast<std::uint64_t>(mesh.ntri()) ||
      nnodes != static_cast<std::uint64_t>(mesh.nnodes()) ||
      (in.size() != base && in.size() != base + ntri * sizeof(double))) {
    throw InputError("fix " + id + " mesh/surface: the restart file holds a mesh of " + std::to_string(ntri) +
                     " triangles (" + std::to_string(nnodes) + " nodes), but '" + file + "' has " +
                     std::to_string(mesh.ntri()) + " (" + std::to_string(mesh.nnodes()) +
                     "); define the fix with the file it had, or give it another ID");
  }
  std::vector<Vec3> nodes(nnodes);
  std::memcpy(static_cast<void*>(nodes.data()), in.data() + 2 * sizeof(std::uint64_t),
              nnodes * 3 * sizeof(double));
  mesh.set_nodes(nodes);
  // the wear goes on from the stored values (held by rank 0, which sums the
  // ranks' contributions when writing); a state without wear starts from 0
  if (wear_finnie) {
    mesh.tri_wear.assign(ntri, 0.0);
    if (in.size() > base && engine_.rank == 0)
      std::memcpy(mesh.tri_wear.data(), in.data() + base, ntri * sizeof(double));
  }
}

FixMeshSurface& FixMeshSurface::find(const Modify& modify, const std::string& mesh_id,
                                     const std::string& what) {
  Fix* f = modify.fix_or_error(mesh_id, what);
  auto* m = dynamic_cast<FixMeshSurface*>(f);
  if (!m) {
    throw InputError(what + ": fix " + mesh_id + " is a " + f->style +
                     " fix, not a mesh/surface fix; give the ID of a fix mesh/surface");
  }
  return *m;
}

std::vector<FixMeshSurface*> FixMeshSurface::select(const Modify& modify, const std::vector<std::string>& ids,
                                                    const std::string& what) {
  std::vector<FixMeshSurface*> list;
  if (ids.empty()) {
    for (const auto& f : modify.fixes)
      if (auto* m = dynamic_cast<FixMeshSurface*>(f.get())) list.push_back(m);
  } else {
    for (const auto& m : ids)
      list.push_back(&find(modify, m, what));
  }
  return list;
}

namespace {

// fix ID group mesh/surface/planar file F.stl type T ...: a mesh/surface
// whose triangles all lie in one plane (LIGGGHTS' planar mesh; insertion
// faces, planar walls), checked when it is read.
class FixMeshSurfacePlanar : public FixMeshSurface {
 public:
  FixMeshSurfacePlanar(Engine& engine, const Args& args) : FixMeshSurface(engine, args) {
    // the plane of the first triangle; every node within 1e-9 of the mesh's
    // size from it, every normal parallel to it (either side)
    const Vec3 n = mesh.normal(0), p0 = mesh.corner(0, 0);
    double size = 0.0;
    for (int k = 0; k < mesh.nnodes(); ++k)
      size = std::max(size, (mesh.node(k) - p0).norm());
    for (int k = 0; k < mesh.nnodes(); ++k) {
      const double d = std::abs((mesh.node(k) - p0).dot(n));
      if (d > 1e-9 * size)
        throw InputError("fix " + id + " mesh/surface/planar: '" + file + "' is not planar: node " +
                         std::to_string(k + 1) + " lies " + std::to_string(d) +
                         " m off the plane of the first triangle; use fix mesh/surface for this mesh");
    }
    for (int t = 0; t < mesh.ntri(); ++t)
      if (std::abs(std::abs(mesh.normal(t).dot(n)) - 1.0) > 1e-9)
        throw InputError("fix " + id + " mesh/surface/planar: triangle " + std::to_string(t + 1) + " of '" +
                         file + "' is not parallel to the first; use fix mesh/surface for this mesh");
  }
};

}  // namespace

GRANARY_FIX_STYLE("mesh/surface", FixMeshSurface);
GRANARY_FIX_STYLE("mesh/surface/planar", FixMeshSurfacePlanar);

}  // namespace granary
