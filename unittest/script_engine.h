// An engine driven by script lines, quiet on screen: the common scaffolding of
// tests that set up a scene with commands.
#pragma once

#include <mpi.h>

#include <algorithm>
#include <charconv>
#include <limits>
#include <map>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/input.h"
#include "core/logger.h"
#include "particles/particles.h"

namespace granary::test {

/// Execute script lines in order on an engine (an element may hold several
/// lines, separated by newlines, e.g. materials()).
inline void run(granary::Engine& e, const std::vector<std::string>& lines) {
  for (const auto& l : lines) {
    std::size_t start = 0, end;
    do {
      end = l.find('\n', start);
      e.input->one(l.substr(start, end == std::string::npos ? std::string::npos : end - start));
      start = end + 1;
    } while (end != std::string::npos);
  }
}

struct ScriptEngine {
  granary::Engine e;
  explicit ScriptEngine(MPI_Comm comm = MPI_COMM_SELF) : e(comm) { e.logger->set_screen(false); }
  /// Execute one script line (or several, separated by newlines).
  void cmd(const std::string& line) { run(e, {line}); }
  /// Execute script lines in order (see run()).
  void cmds(const std::vector<std::string>& lines) { run(e, lines); }
  void lines(const std::vector<std::string>& script) { cmds(script); }
  const granary::Particles& p() const { return *e.particles; }
};

/// This process's rank in MPI_COMM_WORLD and the number of ranks.
inline int world_rank() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}
inline int world_size() {
  int n = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &n);
  return n;
}

/// The head of a script both Granary and LIGGGHTS 3.8 run: granular atoms,
/// fixed boundaries, newton off and ghost velocities (as LIGGGHTS' granular
/// pair styles require), and the box `region box block B units box` with
/// `ntypes` atom types.
inline std::vector<std::string> liggghts_head(const std::string& block, int ntypes) {
  return {"units si",
          "atom_style granular",
          "atom_modify map array",
          "boundary f f f",
          "newton off",
          "communicate single vel yes",
          "region box block " + block + " units box",
          "create_box " + std::to_string(ntypes) + " box"};
}

/// Position and velocity of particle `id`, wherever it lives (collective).
/// Returns false unless exactly one rank owns it.
inline bool particle_state(granary::Engine& e, long long id, granary::Vec3& x, granary::Vec3& v) {
  double local[7] = {0, 0, 0, 0, 0, 0, 0}, all[7];
  const auto& p = *e.particles;
  for (int i = 0; i < p.nlocal; ++i) {
    if (p.id[i] != id) continue;
    for (int d = 0; d < 3; ++d) {
      local[d] = p.x[i][d];
      local[3 + d] = p.v[i][d];
    }
    local[6] = 1;
  }
  MPI_Allreduce(local, all, 7, MPI_DOUBLE, MPI_SUM, e.world);
  x = granary::Vec3(all[0], all[1], all[2]);
  v = granary::Vec3(all[3], all[4], all[5]);
  return all[6] == 1.0;
}

/// Positions of particles 1..n by id, gathered from every rank (collective);
/// a particle that no rank holds is left out.
inline std::map<long long, granary::Vec3> positions_by_id(granary::Engine& e, long long n) {
  std::map<long long, granary::Vec3> out;
  for (long long id = 1; id <= n; ++id) {
    granary::Vec3 x, v;
    if (particle_state(e, id, x, v)) out[id] = x;
  }
  return out;
}

/// The largest distance between the positions of the same id in a and b
/// (infinite when b lacks an id of a).
inline double max_position_difference(const std::map<long long, granary::Vec3>& a,
                                      const std::map<long long, granary::Vec3>& b) {
  double d = 0.0;
  for (const auto& kv : a) {
    const auto it = b.find(kv.first);
    if (it == b.end()) return std::numeric_limits<double>::infinity();
    d = std::max(d, (kv.second - it->second).norm());
  }
  return d;
}

/// A closed 0.4 m box around the origin for two atom types, timestep 0.1 ms:
/// the scene of tests that follow single free particles.
inline std::vector<std::string> free_box() {
  return {"units si",         "atom_style granular",
          "boundary f f f",   "region box block -0.2 0.2 -0.2 0.2 -0.2 0.2",
          "create_box 2 box", "timestep 1e-4"};
}

/// The material lines most scenes need, as one string of four script lines:
/// fix m1..m4 property/global with one Young's modulus Y, Poisson ratio nu,
/// restitution e and friction mu for all `ntypes` types and pairs of types
/// (LIGGGHTS' property names; numbers written so that they read back exactly).
inline std::string materials(int ntypes, double Y, double nu, double e, double mu) {
  auto num = [](double v) {
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    return std::string(buf, r.ptr);
  };
  auto repeat = [&](double v, int n) {
    std::string out;
    for (int k = 0; k < n; ++k)
      out += " " + num(v);
    return out;
  };
  const std::string n = std::to_string(ntypes);
  return "fix m1 all property/global youngsModulus peratomtype" + repeat(Y, ntypes) +
         "\nfix m2 all property/global poissonsRatio peratomtype" + repeat(nu, ntypes) +
         "\nfix m3 all property/global coefficientRestitution peratomtypepair " + n +
         repeat(e, ntypes * ntypes) + "\nfix m4 all property/global coefficientFriction peratomtypepair " +
         n + repeat(mu, ntypes * ntypes);
}

}  // namespace granary::test

#include <stdlib.h>

#include <filesystem>
#include <stdexcept>

namespace granary::test {

/// A mkstemp/mkdtemp template ("<temp dir>/<prefix>XXXXXX") as a writable,
/// zero-terminated buffer.
inline std::vector<char> temp_template(const std::string& prefix) {
  const std::string t = (std::filesystem::temp_directory_path() / (prefix + "XXXXXX")).string();
  std::vector<char> buf(t.begin(), t.end());
  buf.push_back('\0');
  return buf;
}

/// A fresh directory made by rank 0 of MPI_COMM_WORLD, its name known to
/// every rank (collective). The caller removes it.
inline std::string shared_temp_dir(const std::string& prefix) {
  std::string dir;
  if (world_rank() == 0) {
    auto t = temp_template(prefix);
    if (mkdtemp(t.data())) dir = t.data();
  }
  int n = static_cast<int>(dir.size());
  MPI_Bcast(&n, 1, MPI_INT, 0, MPI_COMM_WORLD);
  dir.resize(n);
  if (n) MPI_Bcast(&dir[0], n, MPI_CHAR, 0, MPI_COMM_WORLD);
  if (dir.empty()) throw std::runtime_error("could not create a temporary directory for " + prefix);
  return dir;
}

/// "NAME_np<ranks>" in the working directory, emptied by rank 0 (collective):
/// the output folder of a test that runs at several rank counts.
inline std::string rank_count_dir(const std::string& name) {
  const std::string dir = name + "_np" + std::to_string(world_size());
  if (world_rank() == 0) {
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  return dir;
}

inline bool is_number(const std::string& w) {
  char* end = nullptr;
  std::strtod(w.c_str(), &end);
  return !w.empty() && end && *end == '\0';
}

/// Thermo data lines of a log: lines of exactly `columns` numbers.
inline std::vector<std::vector<double>> thermo_rows(const std::string& text, std::size_t columns) {
  std::vector<std::vector<double>> rows;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream ws(line);
    std::vector<std::string> words;
    std::string w;
    while (ws >> w)
      words.push_back(w);
    if (words.size() != columns) continue;
    bool all = true;
    for (const auto& x : words)
      all = all && is_number(x);
    if (!all) continue;
    std::vector<double> row;
    for (const auto& x : words)
      row.push_back(std::strtod(x.c_str(), nullptr));
    rows.push_back(row);
  }
  return rows;
}

}  // namespace granary::test
