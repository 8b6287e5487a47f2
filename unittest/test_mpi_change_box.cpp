// The change_box command on 1, 2 and 4 ranks (run by ctest at each count):
// the new bounds of final, delta, scale and volume; remap from the box before
// the command or the one saved by set; new boundaries with shrink-wrapping;
// the particles on their ranks in the next run; the errors.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/input.h"
#include "core/variable.h"
#include "domain/domain.h"
#include "particles/particles.h"
#include "script_engine.h"

using Catch::Matchers::Contains;
using granary::Vec3;

namespace {

// Eight spheres at (+-0.25, +-0.25, +-0.25) in the box -0.5..0.5, no forces
// between them (far apart), no gravity: they stay where change_box puts them.
void scene(granary::test::ScriptEngine& s, const std::string& boundary = "f f f") {
  s.cmds({"units si", "atom_style granular", "atom_modify map array", "boundary " + boundary, "newton off",
          "communicate single vel yes", "region box block -0.5 0.5 -0.5 0.5 -0.5 0.5 units box",
          "create_box 1 box", granary::test::materials(1, 5e6, 0.45, 0.5, 0.3),
          "pair_style gran model hertz tangential history", "pair_coeff * *", "timestep 1e-4",
          "neighbor 0.01 bin"});
  for (double x : {-0.25, 0.25})
    for (double y : {-0.25, 0.25})
      for (double z : {-0.25, 0.25})
        s.cmd("create_atoms 1 single " + std::to_string(x) + " " + std::to_string(y) + " " +
              std::to_string(z) + " units box");
  s.cmds({"set group all diameter 0.02 density 2500", "fix integr all nve/sphere"});
}

Vec3 position(granary::Engine& e, long long id) {
  Vec3 x, v;
  REQUIRE(granary::test::particle_state(e, id, x, v));
  return x;
}

void check_box(const granary::Domain& d, const Vec3& lo, const Vec3& hi) {
  for (int k = 0; k < 3; ++k) {
    CHECK(d.boxlo[k] == Approx(lo[k]).margin(1e-15));
    CHECK(d.boxhi[k] == Approx(hi[k]).margin(1e-15));
    CHECK(d.prd[k] == Approx(hi[k] - lo[k]).margin(1e-15));
  }
}

}  // namespace

TEST_CASE("change_box: LIGGGHTS 3.8's boxes and remapped positions for the same commands",
          "[change_box][mpi][liggghts]") {
  // unittest/scripts/change_box/in.change_box, line by line; after each
  // change_box the box LIGGGHTS printed last (unittest/reference/
  // change_box.liggghts.log), and the positions it printed after the remaps.
  // (The shrink-wrapped bounds of the last line differ by convention:
  // Granary wraps the spheres' surfaces, LIGGGHTS their centres.)
  const std::filesystem::path root(GRANARY_SOURCE_DIR);
  std::ifstream log(root / "unittest/reference/change_box.liggghts.log");
  std::vector<std::vector<double>> boxes;
  std::vector<double> printed;
  std::string line;
  while (std::getline(log, line)) {
    if (line.rfind("change_box", 0) == 0) boxes.emplace_back();
    if (line.rfind("  orthogonal box = (", 0) == 0) {
      std::string t = line.substr(20);
      for (char& c : t)
        if (c == '(' || c == ')') c = ' ';
      std::istringstream in(t);
      std::vector<double> b(6);
      std::string to;
      in >> b[0] >> b[1] >> b[2] >> to >> b[3] >> b[4] >> b[5];
      REQUIRE(!boxes.empty());
      boxes.back() = b;
    }
    std::istringstream in(line);
    std::string key;
    double v;
    while (in >> key >> v)
      if (key == "X1" || key == "X2" || key == "Y1") printed.push_back(v);
  }
  REQUIRE(boxes.size() == 5);
  REQUIRE(printed.size() == 3);
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  std::ifstream script(root / "unittest/scripts/change_box/in.change_box");
  std::size_t k = 0;
  while (std::getline(script, line)) {
    if (line.empty() || line[0] == '#' || line.rfind("print", 0) == 0) continue;
    s.cmd(line);
    if (line.rfind("change_box", 0) != 0 || k >= 4) continue;
    INFO(line);
    check_box(*s.e.domain, Vec3(boxes[k][0], boxes[k][1], boxes[k][2]),
              Vec3(boxes[k][3], boxes[k][4], boxes[k][5]));
    ++k;
  }
  REQUIRE(k == 4);
  auto& var = s.e.input->variables();
  CHECK(var.compute_equal("x1") == Approx(printed[0]).margin(1e-12));
  CHECK(var.compute_equal("x2") == Approx(printed[1]).margin(1e-12));
  CHECK(var.compute_equal("y1") == Approx(printed[2]).margin(1e-12));
}

TEST_CASE("change_box: final, delta, scale and volume, in box and lattice units", "[change_box][mpi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  scene(s);
  s.cmd("change_box all x final -1 2 y delta -0.1 0.3 z scale 3 units box");
  check_box(*s.e.domain, Vec3(-1, -0.6, -1.5), Vec3(2, 0.8, 1.5));
  // volume: the volume before the command (3 x 1.4 x 3 = 12.6) kept by the last length
  s.cmd("change_box all x scale 2 z volume units box");
  const double lz = 12.6 / (6.0 * 1.4);
  check_box(*s.e.domain, Vec3(-2.5, -0.6, -lz / 2), Vec3(3.5, 0.8, lz / 2));
  // lattice units (the default, as in LAMMPS): spacings of 0.1 m
  s.cmds({"lattice sc 0.1", "change_box all x final -10 10 y final -10 10 z final -10 10"});
  check_box(*s.e.domain, Vec3(-1, -1, -1), Vec3(1, 1, 1));
  // without remap the particles stay where they were, and the next run keeps them all
  s.cmd("run 5");
  CHECK(s.e.particles->natoms == 8);
  CHECK(position(s.e, 8).isApprox(Vec3(0.25, 0.25, 0.25), 1e-12));
}

TEST_CASE("change_box remap: coordinates follow the box, from before the command or from set",
          "[change_box][mpi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  scene(s);
  s.cmds({"group low id 1 2 3 4", "change_box low x final -1 3 remap units box", "run 3"});
  // x -0.25 of -0.5..0.5 (a quarter) goes to a quarter of -1..3: 0; the others stay
  CHECK(position(s.e, 1).x() == Approx(0.0).margin(1e-12));
  CHECK(position(s.e, 4).x() == Approx(0.0).margin(1e-12));
  CHECK(position(s.e, 5).x() == Approx(0.25).margin(1e-12));
  CHECK(position(s.e, 8).x() == Approx(0.25).margin(1e-12));
  // set: remap from the box saved there, not from the one before the command
  s.cmd("change_box all y final -0.5 1.5 set y final -0.5 3.5 remap units box");
  s.cmd("run 3");
  // y was not remapped into -0.5..1.5 (no remap before set): it scales from
  // -0.5..1.5 to -0.5..3.5, -0.25 to 0 and 0.25 to 1
  CHECK(position(s.e, 1).y() == Approx(0.0).margin(1e-12));
  CHECK(position(s.e, 3).y() == Approx(1.0).margin(1e-12));
  CHECK(s.e.particles->natoms == 8);
}

TEST_CASE("change_box boundary: new boundaries, shrink-wrapped at once", "[change_box][mpi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  scene(s, "p p f");
  s.cmd("change_box all boundary s f m");
  const auto& d = *s.e.domain;
  CHECK_FALSE(d.periodic[0]);
  CHECK(d.boundary[0][0] == 's');
  CHECK(d.boundary[2][1] == 'm');
  // x shrink-wraps to the spheres (centres +-0.25, radius 0.01), y stays, z keeps at least its box
  CHECK(d.boxlo[0] == Approx(-0.26).margin(1e-5));
  CHECK(d.boxhi[0] == Approx(0.26).margin(1e-5));
  CHECK(d.boxlo[1] == -0.5);
  CHECK(d.boxlo[2] == -0.5);
  s.cmd("run 5");
  CHECK(s.e.particles->natoms == 8);
  CHECK(position(s.e, 1).isApprox(Vec3(-0.25, -0.25, -0.25), 1e-12));
}

TEST_CASE("change_box: errors name what is wrong", "[change_box][mpi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  scene(s);
  struct Case {
    std::string args, expect;
  };
  const std::vector<Case> cases = {
      {"all xy final 0.1 units box", "triclinic (tilted) boxes are not supported"},
      {"all triclinic", "triclinic (tilted) boxes are not supported"},
      {"all x final 0", "change_box x final needs 2 value(s)"},
      {"all x stretch 2", "change_box x 'stretch': expected final, delta, scale or volume"},
      {"all x final 0 1", "no lattice is defined; add 'units box'"},
      {"all x scale -1 units box", "scale must be positive"},
      {"all x final 1 0 units box", "the box would be empty"},
      {"all x final -1 1 remap x final 1 0 units box", "the box would be empty"},
      {"all boundary p f", "boundary needs three values"},
      {"all boundary p fp f", "a periodic boundary must be periodic on both sides"},
      {"all shear 1", "unknown keyword 'shear'"},
      {"nobody x scale 2", "nobody"},
  };
  for (const auto& c : cases) {
    INFO(c.args);
    CHECK_THROWS_WITH(s.cmd("change_box " + c.args), Contains(c.expect));
  }
  // nothing changed by the refused commands (a remap before an error neither)
  check_box(*s.e.domain, Vec3(-0.5, -0.5, -0.5), Vec3(0.5, 0.5, 0.5));
  CHECK(position(s.e, 1).isApprox(Vec3(-0.25, -0.25, -0.25), 1e-15));
  // spheres of clumps are not remapped one by one
  s.cmds(
      {"fix dumb all particletemplate/multisphere 15485867 atom_type 1 density constant 2500 nspheres 2 "
       "ntry 1000000 spheres -0.01 0 0 0.01 0.01 0 0 0.01 type 1",
       "fix ms all multisphere", "create_clump dumb 0 0 0"});
  CHECK_THROWS_WITH(s.cmd("change_box all x scale 2 remap"), Contains("sphere(s) of clumps"));
}
