// read_data and write_data: a data file written and read back gives the same
// particles bit for bit on any number of ranks; a hand-written file in the
// LAMMPS/LIGGGHTS layout (comments, blank lines, image flags, zero topology
// counts, velocities, coordinates outside a periodic box) gives the particles
// it describes, which then fly as they must; every malformed file is refused
// with its file name and line, and leaves no box behind. (LIGGGHTS reading
// Granary's files: test_liggghts_data_file.cpp.)
#include <mpi.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "core/engine.h"
#include "domain/domain.h"
#include "particles/particles.h"
#include "script_engine.h"

using Catch::Matchers::Contains;
using granary::Vec3;

namespace {

using granary::test::world_rank;
using granary::test::world_size;

void write_text(const std::string& path, const std::string& text) {
  if (world_rank() == 0) std::ofstream(path) << text;
  MPI_Barrier(MPI_COMM_WORLD);
}

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Every particle's state by id, gathered on every rank:
/// type radius density rmass x(3) v(3) omega(3) ix iy iz.
std::map<long long, std::vector<double>> states(granary::Engine& e) {
  const auto& p = *e.particles;
  std::vector<double> mine;
  for (int i = 0; i < p.nlocal; ++i) {
    int im[3];
    granary::Particles::image_unpack(p.image[i], im[0], im[1], im[2]);
    const double rec[18] = {static_cast<double>(p.id[i]),
                            static_cast<double>(p.type[i]),
                            p.radius[i],
                            p.density[i],
                            p.rmass[i],
                            p.x[i][0],
                            p.x[i][1],
                            p.x[i][2],
                            p.v[i][0],
                            p.v[i][1],
                            p.v[i][2],
                            p.omega[i][0],
                            p.omega[i][1],
                            p.omega[i][2],
                            static_cast<double>(im[0]),
                            static_cast<double>(im[1]),
                            static_cast<double>(im[2]),
                            0.0};
    mine.insert(mine.end(), rec, rec + 18);
  }
  int n = static_cast<int>(mine.size()), nprocs = world_size();
  std::vector<int> counts(nprocs), displs(nprocs, 0);
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, e.world);
  for (int r = 1; r < nprocs; ++r)
    displs[r] = displs[r - 1] + counts[r - 1];
  std::vector<double> all(static_cast<std::size_t>(displs.back() + counts.back()));
  MPI_Allgatherv(mine.data(), n, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE, e.world);
  std::map<long long, std::vector<double>> out;
  for (std::size_t k = 0; k + 17 < all.size(); k += 18)
    out[static_cast<long long>(all[k])] = std::vector<double>(all.begin() + k + 1, all.begin() + k + 17);
  return out;
}

/// The InputError message of `line` (collective: every rank must raise it).
std::string error_of(granary::test::ScriptEngine& s, const std::string& line) {
  try {
    s.cmd(line);
  } catch (const std::exception& err) {
    return err.what();
  }
  FAIL("'" << line << "' raised no error");
  return "";
}

const char* kHandWritten = R"(LIGGGHTS data file with what a user writes by hand

 5  atoms   # a comment after the count
 2  atom types
 0 bonds
 0 bond types

 0.0 0.1 xlo xhi
 0.0 0.1 ylo yhi
 0.0 0.2 zlo zhi

Atoms # sphere

3 2 0.004 2000 0.05 0.05 0.10 0 0 0
1 1 0.002 2500 0.01 0.02 0.03 0 0 0   # id 1
5 1 0.002 2500 0.125 0.02 0.15 1 0 0
2 1 0.003 2500 0.09 0.08 0.05 0 -1 0

4 2 0.004 2000 -0.03 0.05 0.18 0 0 0

Velocities

1 0.1 0.2 0.3 1 2 3
2 -0.1 0 0 0 0 0
3 0 0 0.5 0 0 -4
4 0 0 0 0 0 0
5 0.01 0.02 0.03 0 0 0
)";

}  // namespace

TEST_CASE("write_data then read_data gives the same particles on any rank count", "[data_file][mpi]") {
  const std::string dir = granary::test::shared_temp_dir("granary_data_");
  granary::test::ScriptEngine a(MPI_COMM_WORLD);
  a.cmds({"units si", "atom_style granular", "boundary p p f", "region reg block 0 0.1 0 0.1 0 0.1 units box",
          "create_box 3 reg", "lattice sc 0.01", "region fill block 0.02 0.08 0.02 0.08 0.02 0.06 units box",
          "create_atoms 2 region fill", "set atom * diameter 0.003 density 2500",
          "set type 2 type/fraction 3 0.3 7", "set type 3 diameter 0.0041 density 1234.5",
          "velocity all set 0.1 -0.2 0.05", "displace_atoms all move 0.0731 -0.1234 0.0013 units box"});
  // angular velocities from the ids (no command sets them directly)
  auto& p = *a.e.particles;
  for (int i = 0; i < p.nlocal; ++i)
    p.omega[i] = Vec3(std::sin(p.id[i]), std::cos(0.5 * p.id[i]), 1e-3 * p.id[i]);
  const auto before = states(a.e);
  REQUIRE(before.size() == 7 * 7 * 5);
  bool wrapped = false;  // the move crossed the periodic faces: image flags are not all 0
  for (const auto& kv : before)
    wrapped |= kv.second[13] != 0.0 || kv.second[14] != 0.0;
  REQUIRE(wrapped);
  a.cmd("write_data " + dir + "/round.*.data");
  const std::string file = dir + "/round.0.data";
  REQUIRE(std::filesystem::exists(file));

  granary::test::ScriptEngine b(MPI_COMM_WORLD);
  b.cmds({"units si", "atom_style granular", "boundary p p f", "read_data " + file});
  CHECK(b.e.particles->ntypes == 3);
  for (int d = 0; d < 3; ++d) {
    CHECK(b.e.domain->boxlo[d] == a.e.domain->boxlo[d]);
    CHECK(b.e.domain->boxhi[d] == a.e.domain->boxhi[d]);
  }
  const auto after = states(b.e);
  REQUIRE(after.size() == before.size());
  for (const auto& kv : before) {
    INFO("particle " << kv.first);
    REQUIRE(after.count(kv.first) == 1);
    CHECK(after.at(kv.first) == kv.second);  // every value bit for bit
  }
  // and written again, the same text (ids in order, 17 significant digits)
  b.cmd("write_data " + dir + "/again.data");
  if (world_rank() == 0) CHECK(read_text(dir + "/again.data") == read_text(file));
  MPI_Barrier(MPI_COMM_WORLD);
  if (world_rank() == 0) std::filesystem::remove_all(dir);
}

TEST_CASE("read_data reads a hand-written LIGGGHTS data file and its particles fly as they must",
          "[data_file][mpi]") {
  const std::string dir = granary::test::shared_temp_dir("granary_data_");
  write_text(dir + "/hand.data", kHandWritten);
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds({"units si", "atom_style granular", "boundary p p f", "read_data " + dir + "/hand.data"});
  const auto st = states(s.e);
  REQUIRE(st.size() == 5);
  const double pi = 3.14159265358979323846;
  // particle 3: type 2, diameter 4 mm, density 2000, spin -4 about z
  CHECK(st.at(3)[0] == 2);
  CHECK(st.at(3)[1] == 0.002);
  CHECK(st.at(3)[3] == Approx(2000 * 4.0 / 3.0 * pi * 0.002 * 0.002 * 0.002).epsilon(1e-15));
  CHECK(st.at(3)[12] == -4);
  // particle 1: velocities from the Velocities section
  CHECK(st.at(1)[8] == 0.2);
  CHECK(st.at(1)[11] == 2);
  // particle 5 at x = 0.125 with nx = 1: mapped to x = 0.025, nx = 2
  CHECK(st.at(5)[4] == Approx(0.025).epsilon(1e-14));
  CHECK(st.at(5)[13] == 2);
  // particle 4 at x = -0.03: mapped to 0.07, nx = -1; particle 2 keeps ny = -1
  CHECK(st.at(4)[4] == Approx(0.07).epsilon(1e-14));
  CHECK(st.at(4)[13] == -1);
  CHECK(st.at(2)[14] == -1);
  // no contacts (the spheres are centimetres apart): free flight under gravity
  s.cmds({granary::test::materials(2, 5e6, 0.3, 0.9, 0.3), "pair_style gran model hertz tangential history",
          "pair_coeff * *", "timestep 1e-5", "fix gravi all gravity 9.81 vector 0 0 -1",
          "fix integr all nve/sphere", "run 1000"});
  const auto end = states(s.e);
  const double t = 1000 * 1e-5;
  // particle 3: starts at z = 0.1 with vz = 0.5
  CHECK(end.at(3)[6] == Approx(0.1 + 0.5 * t - 0.5 * 9.81 * t * t).epsilon(1e-12));
  CHECK(end.at(3)[12] == -4);
  // particle 1: x = 0.01 + 0.1 t (unwrapped with its image flag 0)
  CHECK(end.at(1)[4] == Approx(0.01 + 0.1 * t).epsilon(1e-12));
  MPI_Barrier(MPI_COMM_WORLD);
  if (world_rank() == 0) std::filesystem::remove_all(dir);
}

TEST_CASE("read_data refuses a malformed file with its name and line and creates nothing",
          "[data_file][mpi]") {
  const std::string dir = granary::test::shared_temp_dir("granary_data_");
  const std::string head = "title\n\n2 atoms\n1 atom types\n0 1 xlo xhi\n0 1 ylo yhi\n0 1 zlo zhi\n\n";
  const std::string atoms = "Atoms\n\n1 1 0.1 1000 0.5 0.5 0.5\n2 1 0.1 1000 0.2 0.5 0.5\n";
  struct Case {
    std::string text, message;
  };
  const std::vector<Case> cases = {
      {head + "Atoms\n\n1 1 0.1 1000 0.5 0.5 0.5\n", "line 11: the Atoms section ends after 1 of 2 atoms"},
      {head + "Atoms\n\n1 1 0.1 1000 0.5 0.5 0.5\n1 1 0.1 1000 0.2 0.5 0.5\n",
       "line 12: the atom-ID 1 is used twice (also on line 11)"},
      {head + "Atoms\n\n1 3 0.1 1000 0.5 0.5 0.5\n2 1 0.1 1000 0.2 0.5 0.5\n",
       "line 11: the atom type 3 is outside 1..1"},
      {head + "Atoms\n\n1 1 0.1 1000 0.5 0.5 1.5\n2 1 0.1 1000 0.2 0.5 0.5\n",
       "line 11: atom 1 at z = 1.5 lies outside the box"},
      {head + "Atoms\n\n1 1 0 1000 0.5 0.5 0.5\n2 1 0.1 1000 0.2 0.5 0.5\n", "the diameter must be positive"},
      {head + "Atoms\n\n1 1 0.1 1000 0.5 0.5 0.5 0 0 0\n2 1 0.1 1000 0.2 0.5 0.5\n",
       "line 12: image flags must be given on all Atoms lines or on none"},
      {head + "Atoms\n\n1 1 0.1 1000 0.5 0.5\n2 1 0.1 1000 0.2 0.5 0.5\n", "line 11: an Atoms line"},
      {head + "Atoms\n\n1 1 0.1 abc 0.5 0.5 0.5\n2 1 0.1 1000 0.2 0.5 0.5\n",
       "line 11: the density must be a finite number, got 'abc'"},
      {head + "Masses\n\n1 2.5\n\n" + atoms,
       "line 9: a Masses section cannot be used with atom_style granular"},
      {head + "Bonds\n\n1 1 1 2\n", "line 9: the Bonds section is not supported"},
      {head + "Atomz\n\n", "line 9: unknown section 'Atomz'; did you mean 'Atoms'?"},
      {head + atoms + "\nVelocities\n\n1 0 0 0 0 0 0\n3 0 0 0 0 0 0\n",
       "line 17: the atom-ID 3 is not in the Atoms"},
      {head + "Velocities\n\n1 0 0 0 0 0 0\n", "line 9: the Velocities section must come after the Atoms"},
      {"title\n2 atoms\n1 atom types\n3 bonds\n",
       "line 4: granular particles (atom_style granular) have no bonds"},
      {"title\n2 atoms\n1 atom types\n0 1 0 xy xz yz\n",
       "line 4: triclinic boxes (xy xz yz) are not supported"},
      {"title\n2 atoms\n1 atom typs\n",
       "line 3: unknown header keyword 'atom typs'; did you mean 'atom types'?"},
      {"title\n2 atoms\n0 1 xlo xhi\n", "the header has no 'atom types' line"},
      {"title\n2 atoms\n1 atom types\n1 0 xlo xhi\n",
       "line 4: the box bounds 'xlo xhi' must have lower < upper"},
      {head, "the header announces 2 atoms but the file has no Atoms section"},
      {head + atoms + "3 1 0.1 1000 0.2 0.5 0.5\n",
       "line 13: a line of numbers where a section name is expected"},
      {std::string("title\n2 atoms\n\0", 16), "holds NUL bytes"},
  };
  int k = 0;
  for (const Case& c : cases) {
    INFO("case " << k << ": " << c.message);
    const std::string file = dir + "/bad" + std::to_string(k++) + ".data";
    write_text(file, c.text);
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    s.cmds({"units si", "atom_style granular", "boundary f f f"});
    const std::string msg = error_of(s, "read_data " + file);
    CHECK_THAT(msg, Contains("read_data") && Contains(c.message));
    if (c.message.rfind("line", 0) == 0) CHECK_THAT(msg, Contains("data file '" + file + "' " + c.message));
    CHECK_FALSE(s.e.domain->box_exist);
    CHECK(s.e.particles->nlocal == 0);
  }
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  CHECK_THAT(error_of(s, "read_data " + dir + "/missing.data"), Contains("cannot open data file"));
  CHECK_THAT(error_of(s, "read_data " + dir + "/x.data.gz"), Contains("unpack"));
  CHECK_THAT(error_of(s, "read_data a.data fix p NULL Stuff"), Contains("keyword 'fix' is not supported"));
  CHECK_THAT(error_of(s, "write_data " + dir + "/w.data"), Contains("write_data needs a box"));
  s.cmds({"region r block 0 1 0 1 0 1 units box", "create_box 1 r"});
  CHECK_THAT(error_of(s, "read_data " + dir + "/bad0.data"), Contains("must come before the box is created"));
  CHECK_THAT(error_of(s, "write_data " + dir + "/w.data pair xx"), Contains("pair takes ii or ij"));
  CHECK_THAT(error_of(s, "write_data " + dir + "/nosuchdir/w.data"), Contains("write_data: cannot write"));
  MPI_Barrier(MPI_COMM_WORLD);
  if (world_rank() == 0) std::filesystem::remove_all(dir);
}
