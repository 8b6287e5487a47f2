// displace_atoms: move, ramp, random and rotate against the positions they
// must give, on any number of ranks (random: the same displacement for a
// particle whatever the rank count, reproduced from the seed), periodic
// remapping with image flags, and the errors.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "core/engine.h"
#include "particles/particles.h"
#include "script_engine.h"

using Catch::Matchers::Contains;
using granary::Vec3;

namespace {

/// Position and image flags of particle `id` (collective).
Vec3 where(granary::Engine& e, long long id, int* image = nullptr) {
  Vec3 x, v;
  REQUIRE(granary::test::particle_state(e, id, x, v));
  if (image) {
    int local = 0, all = 0;
    for (int i = 0; i < e.particles->nlocal; ++i)
      if (e.particles->id[i] == id) local = e.particles->image[i];
    MPI_Allreduce(&local, &all, 1, MPI_INT, MPI_SUM, e.world);
    *image = all;
  }
  return x;
}

std::vector<std::string> scene() {
  return {"units si",
          "atom_style granular",
          "boundary p f f",
          "region reg block 0 0.1 0 0.1 0 0.1 units box",
          "create_box 1 reg",
          "create_atoms 1 single 0.01 0.02 0.03 units box",
          "create_atoms 1 single 0.06 0.07 0.05 units box",
          "create_atoms 1 single 0.09 0.05 0.08 units box",
          "set atom * diameter 0.002 density 2500",
          "group two id 1 2"};
}

/// 343 particles on a simple cubic lattice of 1 cm (7 x 7 x 7) in a 0.1 m box.
std::vector<std::string> lattice_block() {
  return {"units si",
          "atom_style granular",
          "boundary f f f",
          "region reg block 0 0.1 0 0.1 0 0.1 units box",
          "create_box 1 reg",
          "lattice sc 0.01",
          "region fill block 0.02 0.08 0.02 0.08 0.02 0.08 units box",
          "create_atoms 1 region fill"};
}

}  // namespace

TEST_CASE("displace_atoms move, ramp and rotate give the positions they must", "[displace_atoms][mpi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds(scene());
  s.cmd("displace_atoms two move 0.005 -0.01 0.002 units box");
  CHECK((where(s.e, 1) - Vec3(0.015, 0.01, 0.032)).norm() < 1e-15);
  CHECK((where(s.e, 3) - Vec3(0.09, 0.05, 0.08)).norm() == 0.0);  // outside the group
  // ramp: x displaced 0 at z <= 0.04, 0.02 at z >= 0.08, linear between
  s.cmd("displace_atoms all ramp x 0.0 0.02 z 0.04 0.08 units box");
  CHECK(where(s.e, 1).x() == Approx(0.015).epsilon(1e-14));              // z = 0.032: none
  CHECK(where(s.e, 2).x() == Approx(0.065 + 0.006).epsilon(1e-14));      // z = 0.052: 30 %
  CHECK(where(s.e, 3).x() == Approx(0.09 + 0.02 - 0.1).epsilon(1e-12));  // z = 0.08: all, wrapped
  int image = 0;
  where(s.e, 3, &image);
  int ix, iy, iz;
  granary::Particles::image_unpack(image, ix, iy, iz);
  CHECK(ix == 1);
  // rotate 90 degrees about z through (0.05, 0.05, 0): (0.015, 0.01) -> (0.09, 0.015)
  s.cmd("displace_atoms two rotate 0.05 0.05 0 0 0 1 90 units box");
  CHECK((where(s.e, 1) - Vec3(0.09, 0.015, 0.032)).norm() < 1e-14);
  // a run afterwards moves every particle to its new owner
  s.cmds({"fix integr all nve/sphere", "run 1"});
  long long n = s.e.particles->nlocal, all = 0;
  MPI_Allreduce(&n, &all, 1, MPI_LONG_LONG, MPI_SUM, s.e.world);
  CHECK(all == 3);
}

TEST_CASE("displace_atoms random: uniform displacements from the seed, the same on any number of ranks",
          "[displace_atoms][mpi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds(lattice_block());
  s.cmd("set atom * diameter 0.002 density 2500");
  const int n = static_cast<int>(s.e.particles->natoms);
  REQUIRE(n > 100);
  std::vector<Vec3> before(n + 1), after(n + 1);
  for (int id = 1; id <= n; ++id)
    before[id] = where(s.e, id);
  // units lattice (the default): 0.5 spacings = 5 mm
  s.cmd("displace_atoms all random 0.5 0.25 0 48271");
  Vec3 sum(0, 0, 0), maxabs(0, 0, 0);
  for (int id = 1; id <= n; ++id) {
    after[id] = where(s.e, id);
    const Vec3 d = after[id] - before[id];
    sum += d;
    for (int k = 0; k < 3; ++k)
      maxabs[k] = std::max(maxabs[k], std::fabs(d[k]));
  }
  CHECK(maxabs.x() <= 0.005);
  CHECK(maxabs.x() > 0.004);
  CHECK(maxabs.y() <= 0.0025);
  CHECK(maxabs.z() == 0.0);
  CHECK(std::fabs(sum.x() / n) < 0.005 * 3 / std::sqrt(3.0 * n));  // mean 0 within 3 standard errors
  // the same seed from the same positions gives the same displacements
  granary::test::ScriptEngine t(MPI_COMM_WORLD);
  t.cmds(lattice_block());
  t.cmd("displace_atoms all random 0.005 0.0025 0 48271 units box");
  for (int id = 1; id <= n; id += 7)
    CHECK(where(t.e, id) == after[id]);
}

TEST_CASE("displace_atoms errors", "[displace_atoms][mpi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds(scene());
  CHECK_THROWS_WITH(s.cmd("displace_atoms all move 1 0 0"), Contains("add 'units box'"));
  CHECK_THROWS_WITH(s.cmd("displace_atoms all shift 1 0 0 units box"),
                    Contains("unknown displace_atoms style"));
  CHECK_THROWS_WITH(s.cmd("displace_atoms all move 1 0 units box"), Contains("needs 3 values"));
  CHECK_THROWS_WITH(s.cmd("displace_atoms all rotate 0 0 0 0 0 0 90 units box"),
                    Contains("must not be zero"));
  CHECK_THROWS_WITH(s.cmd("displace_atoms all ramp x 0 1 w 0 1 units box"), Contains("must be x, y or z"));
  CHECK_THROWS_WITH(s.cmd("displace_atoms all random 1 1 1 0 units box"), Contains("positive integer"));
  CHECK_THROWS_WITH(s.cmd("displace_atoms nosuch move 1 0 0 units box"), Contains("nosuch"));
  CHECK(where(s.e, 1) == Vec3(0.01, 0.02, 0.03));
}
