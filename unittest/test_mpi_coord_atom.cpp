// compute coord/atom: the particles within a cutoff of each particle, on any
// number of ranks (periodic lattice: the counts cross rank and periodic
// boundaries), the values LIGGGHTS 3.8 gives for the same script, and the
// refusal of a cutoff longer than the ghost shell.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <string>
#include <vector>

#include "core/engine.h"
#include "script_engine.h"

using Catch::Matchers::Contains;

namespace {

// A simple cubic lattice of spheres (d = 2 mm, 3 mm apart) in a cubic box of
// `side` (the lattice points in [lo, hi] of each direction), type 2 (and group
// low) below x = half; `boundary` decides whether it is periodic.
// LIGGGHTS 3.8 refuses a cutoff longer than its neighbour cutoff (here
// 2 mm + skin 2 mm); Granary needs the ghost shell to reach cutoff + skin on a
// periodic box or several ranks (comm_modify cutoff).
std::vector<std::string> lattice(const std::string& boundary, double side, double lo, double hi,
                                 double half) {
  const std::string b = std::to_string(side), h = std::to_string(hi), l = std::to_string(lo);
  return {"units si",
          "atom_style granular",
          "boundary " + boundary,
          "region box block 0 " + b + " 0 " + b + " 0 " + b + " units box",
          "create_box 2 box",
          "neighbor 0.002 bin",
          "comm_modify cutoff 0.006",
          granary::test::materials(2, 5e6, 0.45, 0.9, 0.5),
          "pair_style gran model hertz tangential history",
          "pair_coeff * *",
          "timestep 1e-5",
          "lattice sc 0.003",
          "region inner block " + l + " " + h + " " + l + " " + h + " " + l + " " + h + " units box",
          "create_atoms 1 region inner",
          "set group all diameter 0.002 density 2500",
          "region half block INF " + std::to_string(half) + " INF INF INF INF units box",
          "set region half type 2",
          "group low region half",
          "fix integr all nve/sphere",
          "compute c1 all coord/atom 0.0035",
          "compute c2 all coord/atom 0.0039 mix yes",
          "compute c3 low coord/atom 0.0039 1 2 *",
          "compute s all reduce sum c_c1 c_c2 c_c3[1] c_c3[2] c_c3[3]",
          "thermo_style custom step atoms c_s[1] c_s[2] c_s[3] c_s[4] c_s[5]",
          "run 0"};
}

}  // namespace

TEST_CASE("compute coord/atom: LIGGGHTS 3.8's counts on a lattice", "[coord_atom][mpi]") {
  // The same 4 x 4 x 4 lattice with fixed walls, LIGGGHTS 3.8 (run 0):
  // sums 288, 32, 16, 128, 144 (each interior sphere has 6 neighbours within
  // 3.5 mm; 16 type-2/type-1 pairs face each other across the middle plane).
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds(lattice("f f f", 0.015, 0.001, 0.0149, 0.0075));
  REQUIRE(s.e.compute_value("s", 1) == 288.0);
  CHECK(s.e.compute_value("s", 2) == 32.0);
  CHECK(s.e.compute_value("s", 3) == 16.0);
  CHECK(s.e.compute_value("s", 4) == 128.0);
  CHECK(s.e.compute_value("s", 5) == 144.0);
}

TEST_CASE("compute coord/atom: periodic lattice, every count across the boundaries", "[coord_atom][mpi]") {
  // 512 spheres at 0, 3, ..., 21 mm, periodic in all three directions (box
  // 24 mm): every sphere has 6 neighbours (3072). Type 2 at x = 0 to 9 mm: the
  // planes x = 0 and 9 mm have one neighbour of the other type each (x = 0
  // sees 21 mm across the periodic boundary), as have x = 12 and 21 mm, so
  // mix yes gives 256; the 256 type-2 spheres (group low) see 128 of type 1,
  // 1408 of type 2, 1536 in all.
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds(lattice("p p p", 0.024, -0.001, 0.0239, 0.0105));
  REQUIRE(s.e.compute_value("s", 1) == 3072.0);
  CHECK(s.e.compute_value("s", 2) == 256.0);
  CHECK(s.e.compute_value("s", 3) == 128.0);
  CHECK(s.e.compute_value("s", 4) == 1408.0);
  CHECK(s.e.compute_value("s", 5) == 1536.0);
  // a cutoff beyond the ghost shell is refused with the way out
  s.cmd("compute far all coord/atom 0.05");
  s.cmd("compute sf all reduce sum c_far");
  CHECK_THROWS_WITH(s.e.compute_value("sf", 0), Contains("ghost shell") && Contains("comm_modify cutoff"));
}
