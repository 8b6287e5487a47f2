// The read_dump command: particle positions, radii, velocities and image
// flags from one snapshot of a dump file (doc/commands/read_dump.md).
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

#include "comm/comm.h"
#include "commands/particle_commands.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/logger.h"
#include "core/modify.h"
#include "core/registry.h"
#include "core/update.h"
#include "domain/domain.h"
#include "particles/particles.h"

namespace granary {

namespace {

using namespace particle_commands;

const char* const kUsage =
    "read_dump FILE NSTEP FIELD ... [box yes|no] [replace yes|no] [purge yes|no] [trim yes|no] [add yes|no] "
    "[label FIELD COLUMN] [scaled yes|no] [wrapped yes|no] [format native|xyz]; FIELD = x y z radius vx vy "
    "vz "
    "ix iy iz";

constexpr double kDefaultDiameter = 1.0;  // as create_atoms (LAMMPS/LIGGGHTS atom_style sphere defaults)
constexpr double kDefaultDensity = 1.0;

enum Field { X, Y, Z, Radius, Vx, Vy, Vz, Ix, Iy, Iz, NFields };
const char* const kFieldNames[NFields] = {"x", "y", "z", "radius", "vx", "vy", "vz", "ix", "iy", "iz"};

int field_index(const std::string& w) {
  for (int f = 0; f < NFields; ++f)
    if (w == kFieldNames[f]) return f;
  return -1;
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

bool is_gz(const std::string& file) {
  return file.size() > 3 && file.compare(file.size() - 3, 3, ".gz") == 0;
}

struct Options {
  std::string file;
  long long nstep = 0;
  std::vector<int> fields;
  bool box = true, replace = true, purge = false, trim = false, add = false;
  bool scaled = false, wrapped = true;
  std::map<std::string, std::string> labels;  // field (or id, type) -> column label
  bool xyz = false;
};

Options parse(const Args& a) {
  Options o;
  if (a.size() < 3) throw InputError(std::string("wrong number of arguments; usage: ") + kUsage);
  o.file = a[0];
  o.nstep = parse_int(a[1], "read_dump NSTEP");
  if (o.nstep < 0) throw InputError("read_dump NSTEP must be >= 0, got " + a[1]);
  std::size_t k = 2;
  for (; k < a.size(); ++k) {
    const int f = field_index(a[k]);
    if (f < 0) break;
    if (std::find(o.fields.begin(), o.fields.end(), f) != o.fields.end())
      throw InputError("read_dump: the field " + a[k] + " is given twice");
    o.fields.push_back(f);
  }
  if (o.fields.empty()) {
    if (a[2] == "q")
      throw InputError(
          "read_dump: field q (charge): granular particles carry no charge; fields: x y z radius vx "
          "vy vz ix iy iz");
    throw InputError("read_dump needs at least one field after NSTEP, got '" + a[2] + "'; usage: " + kUsage);
  }
  while (k < a.size()) {
    const std::string& w = a[k];
    auto value = [&](std::size_t n) {
      if (k + n >= a.size()) throw InputError("read_dump: keyword " + w + " needs a value; usage: " + kUsage);
      return a[k + n];
    };
    // the yes/no keywords
    bool* flag = w == "box"       ? &o.box
                 : w == "replace" ? &o.replace
                 : w == "purge"   ? &o.purge
                 : w == "trim"    ? &o.trim
                 : w == "add"     ? &o.add
                 : w == "scaled"  ? &o.scaled
                 : w == "wrapped" ? &o.wrapped
                                  : nullptr;
    if (flag) {
      *flag = parse_bool(value(1), "read_dump " + w);
      k += 2;
    } else if (w == "label") {
      const std::string field = value(1), column = value(2);
      if (field != "id" && field != "type" && field_index(field) < 0)
        throw InputError("read_dump label: '" + field +
                         "' is not a field (x y z radius vx vy vz ix iy iz, id, type)");
      o.labels[field] = column;
      k += 3;
    } else if (w == "format") {
      const std::string f = value(1);
      if (f == "xyz")
        o.xyz = true;
      else if (f != "native")
        throw InputError("read_dump format must be native or xyz, got '" + f + "'");
      if (k + 2 != a.size())
        throw InputError(
            "read_dump: format must be the last keyword (it takes the rest of the line in LIGGGHTS)");
      k += 2;
    } else if (w == "q") {
      throw InputError("read_dump: field q (charge): granular particles carry no charge");
    } else {
      throw InputError("read_dump: unknown field or keyword '" + w + "'; usage: " + kUsage);
    }
  }
  if (o.xyz) {
    for (int f : o.fields)
      if (f != X && f != Y && f != Z)
        throw InputError(std::string("read_dump format xyz holds only x y z, not ") + kFieldNames[f]);
    if (o.box) throw InputError("read_dump format xyz: an XYZ file has no box; add 'box no'");
  }
  if (o.purge && (o.replace || o.trim))
    throw InputError(
        "read_dump: purge yes deletes every particle first, so it cannot go with replace yes (the "
        "default) or trim yes; add 'replace no' (as LIGGGHTS 3.8 requires)");
  if (o.purge && !o.add)
    throw InputError("read_dump: purge yes without add yes would leave no particles; add 'add yes'");
  return o;
}

/// One snapshot as read on rank 0: box, the labels of its columns, the values.
struct Snapshot {
  bool found = false;
  std::string error;  // non-empty: what is wrong with the file
  double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  std::string bounds;  // the boundary words of the BOX BOUNDS line
  std::vector<std::string> labels;
  std::vector<double> values;  // nrows x labels.size()
  long long nrows = 0;
};

// The file as a stream; a .gz file is read whole through `gzip -dc`. Null when it cannot be read.
std::unique_ptr<std::istream> open_stream(const std::string& file) {
  if (!is_gz(file)) {
    auto in = std::make_unique<std::ifstream>(file);
    if (!in->good()) return nullptr;
    return in;
  }
  if (!std::ifstream(file).good()) return nullptr;
  std::string quoted = "'";
  for (char c : file)
    quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  FILE* pipe = popen(("gzip -dc " + quoted + "' 2>/dev/null").c_str(), "r");
  if (!pipe) return nullptr;
  std::string all;
  char buf[65536];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, pipe)) > 0)
    all.append(buf, n);
  if (pclose(pipe) != 0) return nullptr;
  return std::make_unique<std::istringstream>(std::move(all));
}

Snapshot read_native(std::istream& in, long long nstep, const std::string& file) {
  Snapshot s;
  std::string line;
  long long lineno = 0;
  auto bad = [&](const std::string& what) {
    s.error = "read_dump: dump file '" + file + "' line " + std::to_string(lineno) + ": " + what;
    return s;
  };
  auto next = [&](std::string& l) {
    if (!std::getline(in, l)) return false;
    ++lineno;
    return true;
  };
  while (next(line)) {
    if (line.rfind("ITEM: TIMESTEP", 0) != 0) continue;
    if (!next(line)) return bad("the file ends after ITEM: TIMESTEP (truncated)");
    long long step = -1;
    try {
      step = parse_int(trim(line), "timestep");
    } catch (const InputError&) {
      return bad("'" + line + "' is not a timestep");
    }
    if (!next(line) || line.rfind("ITEM: NUMBER OF ATOMS", 0) != 0)
      return bad("ITEM: NUMBER OF ATOMS expected after the timestep");
    if (!next(line)) return bad("the file ends in the snapshot header (truncated)");
    long long n = -1;
    try {
      n = parse_int(trim(line), "number of atoms");
    } catch (const InputError&) {
      return bad("'" + line + "' is not a number of atoms");
    }
    if (n < 0) return bad("negative number of atoms");
    if (!next(line) || line.rfind("ITEM: BOX BOUNDS", 0) != 0) return bad("ITEM: BOX BOUNDS expected");
    const std::string bounds = trim(line.substr(16));
    const bool triclinic = bounds.find("xy") != std::string::npos;
    for (int d = 0; d < 3; ++d) {
      if (!next(line)) return bad("the file ends in the box bounds (truncated)");
      std::istringstream ls(line);
      if (!(ls >> s.lo[d] >> s.hi[d])) return bad("'" + line + "' is not a pair of box bounds");
    }
    if (!next(line) || line.rfind("ITEM: ATOMS", 0) != 0) return bad("ITEM: ATOMS expected");
    if (step != nstep) {
      for (long long r = 0; r < n; ++r)
        if (!next(line)) return bad("the file ends inside the snapshot of step " + std::to_string(step));
      continue;
    }
    if (triclinic) return bad("the snapshot's box is triclinic; Granary's boxes are orthogonal");
    s.bounds = bounds;
    std::istringstream hs(line.substr(11));
    std::string w;
    while (hs >> w)
      s.labels.push_back(w);
    if (s.labels.empty()) return bad("ITEM: ATOMS names no columns");
    const std::size_t nc = s.labels.size();
    s.values.reserve(static_cast<std::size_t>(n) * nc);
    for (long long r = 0; r < n; ++r) {
      if (!next(line))
        return bad("the snapshot of step " + std::to_string(step) + " ends after " + std::to_string(r) +
                   " of " + std::to_string(n) + " atoms (truncated file)");
      std::istringstream ls(line);
      for (std::size_t c = 0; c < nc; ++c) {
        std::string v;
        if (!(ls >> v))
          return bad("the atom line has fewer than the " + std::to_string(nc) + " columns of its header");
        char* end = nullptr;
        const double d = std::strtod(v.c_str(), &end);
        if (end == v.c_str() || *end != '\0' || !std::isfinite(d))
          return bad("'" + v + "' (column " + s.labels[c] + ") is not a finite number");
        s.values.push_back(d);
      }
      std::string extra;
      if (ls >> extra)
        return bad("the atom line has more than the " + std::to_string(nc) + " columns of its header");
    }
    s.nrows = n;
    s.found = true;
    return s;
  }
  s.error = "read_dump: dump file '" + file + "' has no snapshot of step " + std::to_string(nstep);
  return s;
}

// XYZ: count line, comment line, "element x y z" rows; snapshots numbered 0, 1, ...
Snapshot read_xyz(std::istream& in, long long nstep, const std::string& file) {
  Snapshot s;
  std::string line;
  long long lineno = 0, index = 0;
  auto bad = [&](const std::string& what) {
    s.error = "read_dump: XYZ file '" + file + "' line " + std::to_string(lineno) + ": " + what;
    return s;
  };
  while (std::getline(in, line)) {
    ++lineno;
    if (trim(line).empty()) continue;
    long long n = -1;
    try {
      n = parse_int(trim(line), "atom count");
    } catch (const InputError&) {
      return bad("'" + line + "' is not an atom count");
    }
    if (!std::getline(in, line)) return bad("the file ends after the atom count (truncated)");
    ++lineno;
    const bool take = index == nstep;
    if (take) {
      s.labels = {"id", "type", "x", "y", "z"};
      s.values.reserve(static_cast<std::size_t>(n) * 5);
    }
    for (long long r = 0; r < n; ++r) {
      if (!std::getline(in, line))
        return bad("the snapshot ends after " + std::to_string(r) + " atoms (truncated)");
      ++lineno;
      if (!take) continue;
      std::istringstream ls(line);
      std::string element;
      double x[3];
      if (!(ls >> element >> x[0] >> x[1] >> x[2])) return bad("'" + line + "' is not 'element x y z'");
      int type = 1;
      try {
        type = static_cast<int>(parse_int(element, "type"));
      } catch (const InputError&) {
      }
      s.values.insert(s.values.end(),
                      {static_cast<double>(r + 1), static_cast<double>(type), x[0], x[1], x[2]});
    }
    if (take) {
      s.nrows = n;
      s.found = true;
      return s;
    }
    ++index;
  }
  s.error = "read_dump: XYZ file '" + file + "' has no snapshot " + std::to_string(nstep) +
            " (snapshots count from 0)";
  return s;
}

// Bring the snapshot from rank 0 to every rank; an error found on rank 0 is thrown everywhere.
void broadcast(Engine& e, Snapshot& s) {
  int ok = s.found ? 1 : 0;
  MPI_Bcast(&ok, 1, MPI_INT, 0, e.world);
  std::string err = s.error;
  int len = static_cast<int>(err.size());
  MPI_Bcast(&len, 1, MPI_INT, 0, e.world);
  err.resize(len);
  MPI_Bcast(err.data(), len, MPI_CHAR, 0, e.world);
  if (!ok) throw InputError(err);
  MPI_Bcast(s.lo, 3, MPI_DOUBLE, 0, e.world);
  MPI_Bcast(s.hi, 3, MPI_DOUBLE, 0, e.world);
  std::string head;
  for (const auto& l : s.labels)
    head += l + " ";
  head += "|" + s.bounds;
  len = static_cast<int>(head.size());
  MPI_Bcast(&len, 1, MPI_INT, 0, e.world);
  head.resize(len);
  MPI_Bcast(head.data(), len, MPI_CHAR, 0, e.world);
  const auto bar = head.rfind('|');  // the bounds hold no '|', a column label might
  s.bounds = head.substr(bar + 1);
  s.labels.clear();
  std::istringstream hs(head.substr(0, bar));
  std::string w;
  while (hs >> w)
    s.labels.push_back(w);
  MPI_Bcast(&s.nrows, 1, MPI_LONG_LONG, 0, e.world);
  s.values.resize(static_cast<std::size_t>(s.nrows) * s.labels.size());
  // in pieces below INT_MAX values
  const std::size_t total = s.values.size(), piece = std::size_t(1) << 26;
  for (std::size_t off = 0; off < total; off += piece)
    MPI_Bcast(s.values.data() + off, static_cast<int>(std::min(piece, total - off)), MPI_DOUBLE, 0, e.world);
}

void cmd_read_dump(Engine& e, const Args& a) {
  begin(e, a, 3, "read_dump", kUsage);
  const Options o = parse(a);
  Particles& p = *e.particles;
  Domain& dom = *e.domain;
  require_no_clump_spheres(e, 1, "all", "read_dump");
  if (e.modify->find_fix_by_style("multisphere"))
    throw InputError(
        "read_dump: a dump holds no clump orientations; with fix multisphere defined, continue from "
        "a restart file (read_restart) instead");

  Snapshot s;
  if (e.rank == 0) {
    auto in = open_stream(o.file);
    if (!in)
      s.error = "read_dump: cannot open dump file '" + o.file + "'" +
                (is_gz(o.file) ? " (or gzip cannot read it)" : "");
    else
      s = o.xyz ? read_xyz(*in, o.nstep, o.file) : read_native(*in, o.nstep, o.file);
  }
  broadcast(e, s);

  // the column of each field: its label, or for x y z the first of x, xs, xu, xsu
  const std::size_t nc = s.labels.size();
  auto column_of = [&](const std::string& label) -> int {
    for (std::size_t c = 0; c < nc; ++c)
      if (s.labels[c] == label) return static_cast<int>(c);
    return -1;
  };
  auto label_for = [&](const std::string& field) {
    auto it = o.labels.find(field);
    return it == o.labels.end() ? field : it->second;
  };
  const int cid = column_of(label_for("id"));
  if (cid < 0)
    throw InputError("read_dump: snapshot " + std::to_string(o.nstep) + " of '" + o.file +
                     "' has no column '" + label_for("id") + "' (atom ids)");
  const int ctype = column_of(label_for("type"));
  if (o.add && ctype < 0)
    throw InputError("read_dump: add yes needs atom types: the snapshot has no column '" + label_for("type") +
                     "'");
  int col[NFields];
  bool scaled[3] = {false, false, false}, unwrapped[3] = {false, false, false};
  for (int f = 0; f < NFields; ++f)
    col[f] = -1;
  for (int f : o.fields) {
    const std::string name = kFieldNames[f];
    if (f <= Z && !o.labels.count(name)) {
      const std::string forms[4] = {name, name + "s", name + "u", name + "su"};
      for (int k = 0; k < 4 && col[f] < 0; ++k) {
        col[f] = column_of(forms[k]);
        if (col[f] >= 0) {
          scaled[f] = k == 1 || k == 3;
          unwrapped[f] = k >= 2;
        }
      }
    } else {
      col[f] = column_of(label_for(name));
      if (f <= Z) {
        scaled[f] = o.scaled;
        unwrapped[f] = !o.wrapped;
      }
    }
    if (col[f] < 0)
      throw InputError(
          "read_dump: snapshot " + std::to_string(o.nstep) + " of '" + o.file + "' has no column for field " +
          name + " (looked for '" + label_for(name) + "'" +
          (f <= Z && !o.labels.count(name) ? ", " + name + "s, " + name + "u, " + name + "su" : "") +
          "); name it with label " + name + " COLUMN");
  }
  {
    // the x, y, z fields read must agree on scaled and wrapped (as LIGGGHTS)
    int first = -1;
    for (int f = X; f <= Z; ++f) {
      if (col[f] < 0) continue;
      if (first < 0) first = f;
      if (scaled[f] != scaled[first] || unwrapped[f] != unwrapped[first])
        throw InputError(
            "read_dump: the coordinate columns read differ in being scaled or unwrapped (e.g. xs and yu)");
    }
  }
  // rows by id
  std::unordered_map<tagint, long long> row_of;
  row_of.reserve(static_cast<std::size_t>(s.nrows) * 2);
  for (long long r = 0; r < s.nrows; ++r) {
    const double v = s.values[static_cast<std::size_t>(r) * nc + cid];
    if (!(v >= 1.0) || v != std::floor(v))
      throw InputError("read_dump: snapshot " + std::to_string(o.nstep) + " of '" + o.file + "': atom id " +
                       std::to_string(v) + " is not a positive integer");
    if (!row_of.emplace(static_cast<tagint>(v), r).second)
      throw InputError("read_dump: snapshot " + std::to_string(o.nstep) + " of '" + o.file +
                       "' holds atom id " + std::to_string(static_cast<tagint>(v)) + " twice");
  }
  if (ctype >= 0 && o.add) {
    for (long long r = 0; r < s.nrows; ++r) {
      const double t = s.values[static_cast<std::size_t>(r) * nc + ctype];
      if (t < 1 || t > p.ntypes || t != std::floor(t))
        throw InputError("read_dump: snapshot " + std::to_string(o.nstep) + " of '" + o.file +
                         "': atom type " + std::to_string(t) + " is not one of 1.." +
                         std::to_string(p.ntypes));
    }
  }
  if (col[Radius] >= 0) {
    for (long long r = 0; r < s.nrows; ++r)
      if (!(s.values[static_cast<std::size_t>(r) * nc + col[Radius]] > 0.0))
        throw InputError("read_dump: snapshot " + std::to_string(o.nstep) + " of '" + o.file +
                         "': a radius is not positive");
  }

  // the box
  if (o.box) {
    Vec3 lo(s.lo[0], s.lo[1], s.lo[2]), hi(s.hi[0], s.hi[1], s.hi[2]);
    for (int d = 0; d < 3; ++d)
      if (!(hi[d] > lo[d]))
        throw InputError("read_dump: the snapshot's box is empty along " + std::string(1, "xyz"[d]));
    dom.set_box(lo, hi);
    dom.reset_box();
    e.comm->setup(0.0);  // the subdomains of the new box
  }
  if (!o.xyz) {
    std::istringstream bs(s.bounds);
    std::string w, mine;
    std::string theirs;
    while (bs >> w)
      theirs += w;
    for (int d = 0; d < 3; ++d)
      mine += std::string(1, dom.boundary[d][0]) + dom.boundary[d][1];
    if (!theirs.empty() && theirs != mine)
      e.logger->warning("read_dump: the snapshot's boundary '" + s.bounds +
                        "' differs from the current one; the "
                        "current boundary applies");
  }

  // the coordinates of row r, unscaled with the snapshot's box, and whether given
  auto value = [&](long long r, int f) { return s.values[static_cast<std::size_t>(r) * nc + col[f]]; };
  auto apply = [&](int i, long long r) {
    Vec3 x = p.x[i];
    bool moved = false;
    for (int d = 0; d < 3; ++d) {
      if (col[X + d] < 0) continue;
      double v = value(r, X + d);
      if (scaled[d]) v = s.lo[d] + v * (s.hi[d] - s.lo[d]);
      x[d] = v;
      moved = true;
    }
    int ix, iy, iz;
    Particles::image_unpack(p.image[i], ix, iy, iz);
    int img[3] = {ix, iy, iz};
    for (int d = 0; d < 3; ++d) {
      if (col[X + d] >= 0 && unwrapped[d]) img[d] = 0;
      if (col[Ix + d] >= 0) img[d] = static_cast<int>(std::lround(value(r, Ix + d)));
    }
    p.image[i] = Particles::image_pack(img[0], img[1], img[2]);
    if (moved) p.x[i] = x;
    for (int d = 0; d < 3; ++d)
      if (col[Vx + d] >= 0) p.v[i][d] = value(r, Vx + d);
    if (col[Radius] >= 0) {
      const double rad = value(r, Radius);
      p.radius[i] = rad;
      p.rmass[i] = p.density[i] * 4.0 / 3.0 * M_PI * rad * rad * rad;
    }
  };

  p.clear_ghosts();
  // purge; then trim and replace on the owned particles. New atoms take ids
  // from the largest id after the purge, before the trim (as LIGGGHTS 3.8)
  long long replaced = 0, removed = 0;
  if (o.purge) {
    removed = p.nlocal;
    while (p.nlocal > 0)
      p.remove_local(p.nlocal - 1);
  }
  const tagint first_new_id = next_id(e);
  std::vector<char> seen(static_cast<std::size_t>(s.nrows), 0);
  for (int i = p.nlocal - 1; i >= 0; --i) {
    auto it = row_of.find(p.id[i]);
    if (o.trim && it == row_of.end()) {
      p.remove_local(i);
      ++removed;
      continue;
    }
    if (it == row_of.end()) continue;
    seen[static_cast<std::size_t>(it->second)] = 1;
    if (o.replace) {
      apply(i, it->second);
      ++replaced;
    }
  }
  // the rows already in the system (on any rank): not added
  MPI_Allreduce(MPI_IN_PLACE, seen.data(), static_cast<int>(seen.size()), MPI_CHAR, MPI_MAX, e.world);
  long long added = 0, lost = 0, to_add = 0;
  if (o.add) {
    tagint id = first_new_id;
    for (long long r = 0; r < s.nrows; ++r) {
      if (seen[static_cast<std::size_t>(r)]) continue;
      const tagint new_id = id++;  // ids as create_atoms gives them, in the snapshot's order
      Vec3 x(0, 0, 0);
      for (int d = 0; d < 3; ++d) {
        if (col[X + d] < 0) continue;
        x[d] = value(r, X + d);
        if (scaled[d]) x[d] = s.lo[d] + x[d] * (s.hi[d] - s.lo[d]);
      }
      Vec3 xw = x;
      int image = Particles::image_pack(0, 0, 0);
      dom.remap(xw, image);
      if (!dom.inside_box(xw)) {
        if (e.rank == 0) ++lost;  // every rank sees it: counted once
        continue;
      }
      ++to_add;
      if (!owns_point(dom, xw)) continue;
      const int type = static_cast<int>(s.values[static_cast<std::size_t>(r) * nc + ctype]);
      const int i = p.add_local(new_id, type, x, 0.5 * kDefaultDiameter, kDefaultDensity);
      apply(i, r);
      ++added;
    }
  }
  // every particle into the box: periodic directions wrap (image flags
  // counted), particles outside a non-periodic box are lost
  for (int i = p.nlocal - 1; i >= 0; --i) {
    dom.remap(p.x[i], p.image[i]);
    if (!dom.inside_box(p.x[i])) {
      p.remove_local(i);
      ++lost;
    }
  }
  if (sum_all(e, added) != to_add)
    throw RunError(
        "read_dump: " + std::to_string(sum_all(e, added)) + " of " + std::to_string(to_add) +
        " new atoms were placed on a rank (a point on a subdomain boundary was lost or claimed twice)");
  replaced = sum_all(e, replaced);
  removed = sum_all(e, removed);
  added = sum_all(e, added);
  lost = sum_all(e, lost);
  particles_changed(e);
  e.update->atime = e.update->time();  // as reset_timestep
  e.update->ntimestep = o.nstep;
  e.update->atimestep = o.nstep;
  if (lost > 0)
    e.logger->warning("read_dump: " + std::to_string(lost) +
                      " particle(s) lie outside the box in a non-periodic direction and were removed");
  e.logger->print("Reading dump file " + o.file + " at step " + std::to_string(o.nstep) + "\n  " +
                  std::to_string(s.nrows) + " atoms in snapshot\n  " + std::to_string(removed) +
                  " atoms purged or trimmed\n  " + std::to_string(replaced) + " atoms replaced\n  " +
                  std::to_string(added) + " atoms added\n  " + std::to_string(p.natoms) +
                  " atoms in system\n");
  // particles go to the ranks that own them at the next run's start
}

}  // namespace

GRANARY_COMMAND("read_dump", cmd_read_dump);

}  // namespace granary
