// Data files (LAMMPS/LIGGGHTS text format): the read_data and write_data
// commands for atom_style granular (sphere).
//
// A data file has a title line, a header (counts and box bounds, one per line,
// the values first: "514 atoms", "-0.01 0.17 xlo xhi") and sections whose
// first line is the section name, then one line per item (blank lines and
// "#" comments are skipped anywhere). Granary reads the header keywords and
// the Atoms and Velocities sections of the sphere layout:
//   Atoms:      atom-ID atom-type diameter density x y z [nx ny nz]
//   Velocities: atom-ID vx vy vz wx wy wz
// and refuses everything a granular sphere cannot hold (bonds, ellipsoids,
// triclinic boxes, per-type masses, pair coefficients) with the line that
// asks for it. Rank 0 reads the file, every rank parses the same text, so an
// error is the same everywhere and nothing is created unless the whole file
// is good. write_data writes the same layout (values with 17 significant
// digits, so reading the file back gives the same numbers), through a
// temporary file renamed over the final name. See doc/commands/read_data.md.
#include <mpi.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <unordered_map>
#include <vector>

#include "comm/collectives.h"
#include "comm/comm.h"
#include "core/atomic_file.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/logger.h"
#include "core/registry.h"
#include "core/update.h"
#include "domain/domain.h"
#include "output/restart.h"
#include "particles/particles.h"

namespace granary {

namespace {

/// One particle of the Atoms section, with its velocities once read.
struct AtomLine {
  long long id = 0;
  int type = 0;
  double diameter = 0.0, density = 0.0;
  Vec3 x{0.0, 0.0, 0.0}, v{0.0, 0.0, 0.0}, omega{0.0, 0.0, 0.0};
  int image[3] = {0, 0, 0};
  int line = 0;
};

struct DataFile {
  long long natoms = 0;
  long long ntypes = 0;
  bool has_box[3] = {false, false, false};
  Vec3 lo{-0.5, -0.5, -0.5}, hi{0.5, 0.5, 0.5};
  std::vector<AtomLine> atoms;
};

std::vector<std::string> words(const std::string& s) {
  std::vector<std::string> out;
  std::istringstream in(s);
  std::string w;
  while (in >> w)
    out.push_back(w);
  return out;
}

std::string strip_comment(const std::string& s) {
  const std::size_t hash = s.find('#');
  std::string t = hash == std::string::npos ? s : s.substr(0, hash);
  const std::size_t b = t.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  const std::size_t e = t.find_last_not_of(" \t\r");
  return t.substr(b, e - b + 1);
}

// Header lines whose count must be 0 for granular spheres, with what they ask for.
const std::map<std::string, std::string>& unsupported_counts() {
  static const std::map<std::string, std::string> m = {
      {"bonds", "bonds"},
      {"angles", "angles"},
      {"dihedrals", "dihedrals"},
      {"impropers", "impropers"},
      {"bond types", "bond types"},
      {"angle types", "angle types"},
      {"dihedral types", "dihedral types"},
      {"improper types", "improper types"},
      {"extra bond per atom", "room for bonds"},
      {"extra angle per atom", "room for angles"},
      {"extra dihedral per atom", "room for dihedrals"},
      {"extra improper per atom", "room for impropers"},
      {"extra special per atom", "room for special neighbours"},
      {"ellipsoids", "ellipsoids"},
      {"lines", "line segments"},
      {"triangles", "triangles"},
      {"bodies", "bodies"},
  };
  return m;
}

// Sections of the LAMMPS/LIGGGHTS format that granular spheres cannot use.
const std::vector<std::string>& other_sections() {
  static const std::vector<std::string> s = {"Masses",
                                             "Ellipsoids",
                                             "Lines",
                                             "Triangles",
                                             "Bodies",
                                             "Bonds",
                                             "Angles",
                                             "Dihedrals",
                                             "Impropers",
                                             "Pair Coeffs",
                                             "PairIJ Coeffs",
                                             "Bond Coeffs",
                                             "Angle Coeffs",
                                             "Dihedral Coeffs",
                                             "Improper Coeffs",
                                             "BondBond Coeffs",
                                             "BondAngle Coeffs",
                                             "MiddleBondTorsion Coeffs",
                                             "EndBondTorsion Coeffs",
                                             "AngleTorsion Coeffs",
                                             "AngleAngleTorsion Coeffs",
                                             "BondBond13 Coeffs",
                                             "AngleAngle Coeffs"};
  return s;
}

class Parser {
 public:
  Parser(const std::string& file, const std::string& text, int max_types)
      : file_(file), max_types_(max_types) {
    std::istringstream in(text);
    std::string l;
    while (std::getline(in, l))
      lines_.push_back(l);
  }

  DataFile parse() {
    DataFile d;
    std::size_t k = 1;  // line 1 is the title
    // ---- header
    for (; k < lines_.size(); ++k) {
      const std::string s = strip_comment(lines_[k]);
      if (s.empty()) continue;
      const std::vector<std::string> w = words(s);
      if (!is_number(w[0])) break;  // the body starts
      std::size_t nnum = 0;
      while (nnum < w.size() && is_number(w[nnum]))
        ++nnum;
      const std::string key = join(Args(w.begin() + nnum, w.end()));
      auto count = [&](const std::string& what) {
        if (nnum != 1)
          throw bad(k, "the header line '" + key + "' takes one number, got " + std::to_string(nnum));
        return whole(k, w[0], "the number of " + what);
      };
      if (key == "atoms") {
        d.natoms = count("atoms");
      } else if (key == "atom types") {
        d.ntypes = count("atom types");
        if (d.ntypes < 1 || d.ntypes > max_types_)
          throw bad(k,
                    "the number of atom types must be in 1.." + std::to_string(max_types_) + ", got " + w[0]);
      } else if (key == "xlo xhi" || key == "ylo yhi" || key == "zlo zhi") {
        const int dim = key[0] - 'x';
        if (nnum != 2) throw bad(k, "'" + key + "' takes two numbers (lower and upper bound)");
        d.lo[dim] = number(k, w[0], key);
        d.hi[dim] = number(k, w[1], key);
        if (!(d.lo[dim] < d.hi[dim]))
          throw bad(k, "the box bounds '" + key + "' must have lower < upper, got " + w[0] + " " + w[1]);
        d.has_box[dim] = true;
      } else if (key == "xy xz yz") {
        throw bad(k,
                  "triclinic boxes (xy xz yz) are not supported; Granary boxes are orthogonal (remove the "
                  "line when the tilts are 0)");
      } else if (unsupported_counts().count(key)) {
        if (count(key) != 0)
          throw bad(k, "granular particles (atom_style granular) have no " + unsupported_counts().at(key) +
                           "; set '" + key + "' to 0 or remove the line");
      } else {
        std::vector<std::string> known = {"atoms", "atom types", "xlo xhi", "ylo yhi", "zlo zhi"};
        for (const auto& kv : unsupported_counts())
          known.push_back(kv.first);
        const std::string hint = did_you_mean(key, known);
        throw bad(k, "unknown header keyword '" + key + "'" + (hint.empty() ? "" : "; " + hint));
      }
    }
    if (d.natoms < 0) throw bad(0, "the number of atoms must not be negative");
    if (d.ntypes == 0) throw bad(0, "the header has no 'atom types' line (the number of atom types)");
    // ---- body
    bool atoms_read = false, velocities_read = false;
    std::unordered_map<long long, std::size_t> index;
    for (; k < lines_.size(); ++k) {
      const std::string section = strip_comment(lines_[k]);
      if (section.empty()) continue;
      const std::size_t at = k;
      if (section == "Atoms") {
        if (atoms_read) throw bad(at, "a second Atoms section");
        k = read_atoms(k, d, index);
        atoms_read = true;
      } else if (section == "Velocities") {
        if (!atoms_read) throw bad(at, "the Velocities section must come after the Atoms section");
        if (velocities_read) throw bad(at, "a second Velocities section");
        k = read_velocities(k, d, index);
        velocities_read = true;
      } else if (section == "Masses") {
        throw bad(at,
                  "a Masses section cannot be used with atom_style granular: each particle's mass is its "
                  "density times its volume (set them in the Atoms section)");
      } else if (section == "Pair Coeffs" || section == "PairIJ Coeffs") {
        throw bad(at, "granular pair styles take no coefficients from a data file; remove the " + section +
                          " section (materials come from fix property/global)");
      } else if (std::find(other_sections().begin(), other_sections().end(), section) !=
                 other_sections().end()) {
        throw bad(at, "the " + section +
                          " section is not supported: granular particles are spheres without "
                          "bonds (atom_style granular)");
      } else if (is_number(words(section)[0])) {
        throw bad(at,
                  "a line of numbers where a section name is expected: the section before it has more lines "
                  "than the header announces (" +
                      std::to_string(d.natoms) + " atoms)");
      } else {
        std::vector<std::string> known = {"Atoms", "Velocities"};
        known.insert(known.end(), other_sections().begin(), other_sections().end());
        const std::string hint = did_you_mean(section, known);
        throw bad(at, "unknown section '" + section + "'" + (hint.empty() ? "" : "; " + hint) +
                          " (a header line must start with its numbers)");
      }
    }
    if (d.natoms > 0 && !atoms_read)
      throw bad(
          0, "the header announces " + std::to_string(d.natoms) + " atoms but the file has no Atoms section");
    return d;
  }

 private:
  InputError bad(std::size_t k, const std::string& what) const {
    return InputError("read_data: data file '" + file_ + "'" + (k ? " line " + std::to_string(k + 1) : "") +
                      ": " + what);
  }
  double number(std::size_t k, const std::string& w, const std::string& what) const {
    char* end = nullptr;
    const double v = std::strtod(w.c_str(), &end);
    if (!end || *end != '\0' || !std::isfinite(v))
      throw bad(k, what + " must be a finite number, got '" + w + "'");
    return v;
  }
  long long whole(std::size_t k, const std::string& w, const std::string& what) const {
    char* end = nullptr;
    errno = 0;
    const long long v = std::strtoll(w.c_str(), &end, 10);
    if (!end || *end != '\0' || errno == ERANGE) throw bad(k, what + " must be an integer, got '" + w + "'");
    return v;
  }

  // The next `n` non-blank lines after the section name and the skipped line;
  // returns the index of the last line read.
  template <class F>
  std::size_t section_lines(std::size_t k, long long n, const std::string& name, const std::string& item,
                            F&& f) {
    std::size_t j = k + 1;  // blank lines (the one after the section name too) are skipped
    for (long long m = 0; m < n; ++m) {
      while (j < lines_.size() && strip_comment(lines_[j]).empty())
        ++j;
      if (j >= lines_.size()) {
        throw bad(j - 1, "the " + name + " section ends after " + std::to_string(m) + " of " +
                             std::to_string(n) + " " + item +
                             "; the file is truncated or the header count is wrong");
      }
      f(j, words(strip_comment(lines_[j])));
      ++j;
    }
    return j - 1;
  }

  std::size_t read_atoms(std::size_t k, DataFile& d, std::unordered_map<long long, std::size_t>& index) {
    d.atoms.reserve(static_cast<std::size_t>(std::min<long long>(d.natoms, 1 << 24)));
    std::size_t columns = 0;
    std::size_t zero_ids = 0;
    const std::size_t last = section_lines(k, d.natoms, "Atoms", "atoms", [&](std::size_t j, const Args& w) {
      if (w.size() != 7 && w.size() != 10) {
        throw bad(j,
                  "an Atoms line of atom_style granular has 7 values (atom-ID atom-type diameter density x y "
                  "z) or 10 (with image flags nx ny nz), got " +
                      std::to_string(w.size()) +
                      (is_number(w[0]) ? "" : "; the header announces more atoms than the section holds"));
      }
      if (columns == 0) columns = w.size();
      if (w.size() != columns)
        throw bad(j, "image flags must be given on all Atoms lines or on none (this line has " +
                         std::to_string(w.size()) + " values, the first had " + std::to_string(columns) +
                         ")");
      AtomLine a;
      a.line = static_cast<int>(j + 1);
      a.id = whole(j, w[0], "the atom-ID");
      if (a.id < 0) throw bad(j, "the atom-ID must not be negative, got " + w[0]);
      const long long type = whole(j, w[1], "the atom type");
      if (type < 1 || type > d.ntypes)
        throw bad(j,
                  "the atom type " + w[1] + " is outside 1.." + std::to_string(d.ntypes) + " (atom types)");
      a.type = static_cast<int>(type);
      a.diameter = number(j, w[2], "the diameter");
      if (!(a.diameter > 0.0))
        throw bad(j, "the diameter must be positive, got " + w[2] + " (point particles are not supported)");
      a.density = number(j, w[3], "the density");
      if (!(a.density > 0.0)) throw bad(j, "the density must be positive, got " + w[3]);
      for (int c = 0; c < 3; ++c)
        a.x[c] = number(j, w[4 + c], std::string("the ") + "xyz"[c] + " coordinate");
      if (columns == 10) {
        for (int c = 0; c < 3; ++c) {
          const long long im = whole(j, w[7 + c], std::string("the image flag n") + "xyz"[c]);
          if (im < -511 || im > 511) throw bad(j, "image flags must lie in -511..511, got " + w[7 + c]);
          a.image[c] = static_cast<int>(im);
        }
      }
      if (a.id == 0) ++zero_ids;
      d.atoms.push_back(a);
    });
    if (zero_ids > 0 && zero_ids < d.atoms.size())
      throw bad(
          k, "atom-IDs must be all positive or all 0 (then Granary numbers the atoms 1..N in file order); " +
                 std::to_string(zero_ids) + " of " + std::to_string(d.atoms.size()) + " are 0");
    for (std::size_t n = 0; n < d.atoms.size(); ++n) {
      if (zero_ids) d.atoms[n].id = static_cast<long long>(n) + 1;
      auto ins = index.emplace(d.atoms[n].id, n);
      if (!ins.second)
        throw bad(static_cast<std::size_t>(d.atoms[n].line - 1),
                  "the atom-ID " + std::to_string(d.atoms[n].id) + " is used twice (also on line " +
                      std::to_string(d.atoms[ins.first->second].line) + ")");
    }
    return last;
  }

  std::size_t read_velocities(std::size_t k, DataFile& d,
                              const std::unordered_map<long long, std::size_t>& index) {
    std::vector<char> seen(d.atoms.size(), 0);
    return section_lines(k, d.natoms, "Velocities", "atoms", [&](std::size_t j, const Args& w) {
      if (w.size() != 7) {
        throw bad(j,
                  "a Velocities line of atom_style granular has 7 values (atom-ID vx vy vz wx wy wz), got " +
                      std::to_string(w.size()));
      }
      const long long id = whole(j, w[0], "the atom-ID");
      auto it = index.find(id);
      if (it == index.end()) throw bad(j, "the atom-ID " + w[0] + " is not in the Atoms section");
      if (seen[it->second]) throw bad(j, "a second velocity for atom " + w[0]);
      seen[it->second] = 1;
      AtomLine& a = d.atoms[it->second];
      for (int c = 0; c < 3; ++c) {
        a.v[c] = number(j, w[1 + c], std::string("v") + "xyz"[c]);
        a.omega[c] = number(j, w[4 + c], std::string("w") + "xyz"[c]);
      }
    });
  }

  std::string file_;
  int max_types_;
  std::vector<std::string> lines_;
};

std::string fmt(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

void cmd_read_data(Engine& e, const Args& a) {
  const char* usage = "read_data FILE";
  if (a.empty()) throw InputError(std::string("wrong number of arguments; usage: ") + usage);
  if (a.size() > 1) {
    throw InputError("read_data keyword '" + a[1] +
                     "' is not supported (the fix keyword passes extra sections to " +
                     "fixes, which Granary's fixes do not read); usage: " + usage);
  }
  if (e.domain->box_exist) {
    throw InputError(
        "read_data must come before the box is created (create_box, read_restart or another "
        "read_data); use clear first to start over");
  }
  const std::string& file = a[0];
  if (file.size() > 3 && file.compare(file.size() - 3, 3, ".gz") == 0)
    throw InputError("read_data: gzipped data files are not read; unpack '" + file + "' with gunzip first");
  std::string text, problem;
  if (e.rank == 0) {
    std::ifstream in(file, std::ios::binary);
    if (!in) {
      problem = "read_data: cannot open data file '" + file + "': " + std::strerror(errno);
    } else {
      std::ostringstream s;
      s << in.rdbuf();
      text = s.str();
      if (text.find('\0') != std::string::npos)
        problem = "read_data: '" + file +
                  "' is not a text data file (it holds NUL bytes; a restart file is "
                  "read with read_restart)";
    }
  }
  // every rank parses the same text: the same error everywhere, or the same particles
  bcast_string(e.world, problem);
  if (!problem.empty()) throw InputError(problem);
  bcast_string(e.world, text);
  DataFile d = Parser(file, text, Particles::kMaxTypes).parse();
  text.clear();
  text.shrink_to_fit();

  Domain& dom = *e.domain;
  // positions: inside the box in non-periodic directions, mapped into it in periodic ones
  for (AtomLine& at : d.atoms) {
    for (int c = 0; c < 3; ++c) {
      const bool inside = at.x[c] >= d.lo[c] && at.x[c] <= d.hi[c];
      if (dom.periodic[c]) {
        const double len = d.hi[c] - d.lo[c];
        const double shift = std::floor((at.x[c] - d.lo[c]) / len);
        if (std::fabs(shift) > 511)
          throw InputError("read_data: data file '" + file + "' line " + std::to_string(at.line) +
                           ": the atom lies too many periodic images away from the box");
        at.x[c] -= shift * len;
        if (at.x[c] >= d.hi[c]) at.x[c] = d.lo[c];  // rounding at the upper face
        at.image[c] += static_cast<int>(shift);
        if (at.image[c] < -511 || at.image[c] > 511)
          throw InputError("read_data: data file '" + file + "' line " + std::to_string(at.line) +
                           ": the atom lies too many periodic images away from the box");
      } else if (!inside) {
        throw InputError("read_data: data file '" + file + "' line " + std::to_string(at.line) + ": atom " +
                         std::to_string(at.id) + " at " + "xyz"[c] + " = " + fmt(at.x[c]) +
                         " lies outside the box (" + "xyz"[c] + "lo " + "xyz"[c] + "hi " + fmt(d.lo[c]) +
                         " " + fmt(d.hi[c]) + ") in the non-periodic " + "xyz"[c] +
                         " direction; enlarge the box in the header");
      }
    }
  }

  e.update->particles_changed();
  dom.set_box(d.lo, d.hi);
  e.particles->ntypes = static_cast<int>(d.ntypes);
  e.comm->setup(0.0);
  Particles& p = *e.particles;
  p.clear_ghosts();
  for (const AtomLine& at : d.atoms) {
    if (e.comm->owner_of(at.x) != e.rank) continue;
    const int i = p.add_local(static_cast<tagint>(at.id), at.type, at.x, 0.5 * at.diameter, at.density);
    p.v[i] = at.v;
    p.omega[i] = at.omega;
    p.image[i] = Particles::image_pack(at.image[0], at.image[1], at.image[2]);
  }
  long long local = p.nlocal, all = 0;
  MPI_Allreduce(&local, &all, 1, MPI_LONG_LONG, MPI_SUM, e.world);
  p.natoms = static_cast<tagint>(all);
  p.map_clear();
  if (all != static_cast<long long>(d.atoms.size())) {
    throw RunError(
        "read_data: " + std::to_string(all) + " of " + std::to_string(d.atoms.size()) +
        " atoms were placed on a rank (an atom on a subdomain boundary was lost or claimed twice)");
  }
  char buf[512];
  std::snprintf(
      buf, sizeof buf,
      "Reading data file %s\n  orthogonal box = (%g %g %g) to (%g %g %g)\n  %d by %d by %d MPI processor "
      "grid\n  %lld atoms\n",
      file.c_str(), d.lo[0], d.lo[1], d.lo[2], d.hi[0], d.hi[1], d.hi[2], e.comm->procgrid[0],
      e.comm->procgrid[1], e.comm->procgrid[2], all);
  e.logger->print(buf);
  for (int c = 0; c < 3; ++c)
    if (!d.has_box[c])
      e.logger->warning(std::string("read_data: '") + file + "' has no '" + "xyz"[c] + "lo " + "xyz"[c] +
                        "hi' line; the box spans -0.5 to 0.5 in " + "xyz"[c] + " (the format's default)");
}

void cmd_write_data(Engine& e, const Args& a) {
  const char* usage = "write_data FILE [pair ii|ij]";
  if (a.empty() || (a.size() != 1 && a.size() != 3))
    throw InputError(std::string("wrong number of arguments; usage: ") + usage);
  if (a.size() == 3) {
    if (a[1] != "pair") throw InputError("unknown write_data keyword '" + a[1] + "'; usage: " + usage);
    if (a[2] != "ii" && a[2] != "ij") throw InputError("write_data pair takes ii or ij, got '" + a[2] + "'");
    // granular pair styles have no coefficients to write: both forms write none
  }
  if (!e.domain->box_exist)
    throw InputError("write_data needs a box and particles: create_box, read_data or read_restart first");
  const Particles& p = *e.particles;
  long long bodies = 0, local_bodies = 0;
  for (int i = 0; i < p.nlocal; ++i)
    if (p.body[i] >= 0) ++local_bodies;
  MPI_Allreduce(&local_bodies, &bodies, 1, MPI_LONG_LONG, MPI_SUM, e.world);
  if (bodies > 0) {
    throw InputError("write_data cannot write clumps (" + std::to_string(bodies) +
                     " sub-spheres belong to fix multisphere bodies, which a data file cannot hold); use "
                     "write_restart");
  }
  const std::string file = expand_step(a[0], e.update->ntimestep);
  // id type diameter density x y z nx ny nz vx vy vz wx wy wz
  constexpr std::size_t kPer = 16;
  std::vector<double> mine;
  mine.reserve(kPer * static_cast<std::size_t>(p.nlocal));
  for (int i = 0; i < p.nlocal; ++i) {
    int im[3];
    Particles::image_unpack(p.image[i], im[0], im[1], im[2]);
    const double rec[kPer] = {static_cast<double>(p.id[i]),
                              static_cast<double>(p.type[i]),
                              2.0 * p.radius[i],
                              p.density[i],
                              p.x[i][0],
                              p.x[i][1],
                              p.x[i][2],
                              static_cast<double>(im[0]),
                              static_cast<double>(im[1]),
                              static_cast<double>(im[2]),
                              p.v[i][0],
                              p.v[i][1],
                              p.v[i][2],
                              p.omega[i][0],
                              p.omega[i][1],
                              p.omega[i][2]};
    mine.insert(mine.end(), rec, rec + kPer);
  }
  const std::vector<double> all = gather_to_root(e.world, mine);
  std::string problem;
  long long count = 0;
  if (e.rank == 0) {
    count = static_cast<long long>(all.size() / kPer);
    std::vector<std::size_t> order(static_cast<std::size_t>(count));
    for (std::size_t n = 0; n < order.size(); ++n)
      order[n] = n;
    std::sort(order.begin(), order.end(),
              [&](std::size_t x, std::size_t y) { return all[x * kPer] < all[y * kPer]; });
    const Domain& d = *e.domain;
    problem = replace_file(file, [&](std::FILE* f) {
      std::fprintf(f, "Granary data file via write_data, atom_style granular, units %s, timestep = %lld\n\n",
                   d.units.c_str(), static_cast<long long>(e.update->ntimestep));
      std::fprintf(f, "%lld atoms\n%d atom types\n\n", count, p.ntypes);
      for (int c = 0; c < 3; ++c)
        std::fprintf(f, "%.16e %.16e %clo %chi\n", d.boxlo[c], d.boxhi[c], "xyz"[c], "xyz"[c]);
      if (count == 0) return;
      std::fprintf(f, "\nAtoms\n\n");
      for (std::size_t n : order) {
        const double* r = &all[n * kPer];
        std::fprintf(f, "%lld %d %.16e %.16e %.16e %.16e %.16e %d %d %d\n", static_cast<long long>(r[0]),
                     static_cast<int>(r[1]), r[2], r[3], r[4], r[5], r[6], static_cast<int>(r[7]),
                     static_cast<int>(r[8]), static_cast<int>(r[9]));
      }
      std::fprintf(f, "\nVelocities\n\n");
      for (std::size_t n : order) {
        const double* r = &all[n * kPer];
        std::fprintf(f, "%lld %.16e %.16e %.16e %.16e %.16e %.16e\n", static_cast<long long>(r[0]), r[10],
                     r[11], r[12], r[13], r[14], r[15]);
      }
    });
    if (!problem.empty()) problem = "write_data: " + problem;
  }
  bcast_string(e.world, problem);
  if (!problem.empty()) throw InputError(problem);
  MPI_Bcast(&count, 1, MPI_LONG_LONG, 0, e.world);
  e.logger->print("Wrote data file " + file + ": " + std::to_string(count) + " atoms at step " +
                  std::to_string(e.update->ntimestep) + "\n");
}

}  // namespace

GRANARY_COMMAND("read_data", cmd_read_data);
GRANARY_COMMAND("write_data", cmd_write_data);

}  // namespace granary
