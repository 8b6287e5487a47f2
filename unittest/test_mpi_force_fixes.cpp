// Fixes whose action needs sums over all ranks: aveforce (the mean force of
// the group) and momentum (the group's centre-of-mass velocity and orbital
// angular momentum). Run at 1, 2 and 4 ranks: the results must match the
// analytic values and a single-rank engine particle by particle.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "core/engine.h"
#include "particles/particles.h"
#include "script_engine.h"

using granary::Vec3;

namespace {

constexpr int kN = 64;

// 64 free spheres of two sizes on a lattice in a box periodic in x, moving
// with velocities that differ from particle to particle (no pair style: the
// fixes alone act).
std::vector<std::string> scene() {
  std::vector<std::string> s = {"units si",         "atom_style granular",
                                "boundary p f f",   "region box block -0.01 0.01 -0.01 0.01 -0.01 0.01",
                                "create_box 2 box", "timestep 1e-4"};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 4; ++k) {
        char line[160];
        std::snprintf(line, sizeof line, "create_atoms %d single %.6f %.6f %.6f", 1 + (i + j + k) % 2,
                      -0.0075 + 0.005 * i, -0.0075 + 0.005 * j, -0.0075 + 0.005 * k);
        s.push_back(line);
      }
  s.push_back("set type 1 diameter 0.001 density 2500");
  s.push_back("set type 2 diameter 0.0015 density 2500");
  s.push_back("variable vx atom 0.3*sin(1.3*id)");
  s.push_back("variable vy atom 0.2*cos(0.7*id)");
  s.push_back("variable vz atom 0.1*sin(0.3*id+1)");
  s.push_back("velocity all set v_vx v_vy v_vz");
  s.push_back("fix i all nve/sphere");
  return s;
}

struct Totals {
  double mass = 0;
  Vec3 p{0, 0, 0}, l{0, 0, 0}, xcm{0, 0, 0};
};

/// Mass, momentum and orbital angular momentum about the centre of mass of
/// all particles (unwrapped positions), over the ranks.
Totals totals(granary::Engine& e) {
  const auto& p = *e.particles;
  double local[10] = {0}, all[10];
  for (int i = 0; i < p.nlocal; ++i) {
    int ix, iy, iz;
    granary::Particles::image_unpack(p.image[i], ix, iy, iz);
    const Vec3 xu = p.x[i] + Vec3(ix * 0.02, 0, 0);
    local[0] += p.rmass[i];
    for (int d = 0; d < 3; ++d) {
      local[1 + d] += p.rmass[i] * p.v[i][d];
      local[4 + d] += p.rmass[i] * xu[d];
    }
    const Vec3 l = p.rmass[i] * xu.cross(p.v[i]);
    for (int d = 0; d < 3; ++d)
      local[7 + d] += l[d];
  }
  MPI_Allreduce(local, all, 10, MPI_DOUBLE, MPI_SUM, e.world);
  Totals t;
  t.mass = all[0];
  t.p = Vec3(all[1], all[2], all[3]);
  t.xcm = Vec3(all[4], all[5], all[6]) / t.mass;
  t.l = Vec3(all[7], all[8], all[9]) - t.xcm.cross(t.p);  // about the centre of mass
  return t;
}

/// Velocities by particle id, gathered from every rank.
std::map<long long, Vec3> velocities(granary::Engine& e) {
  std::vector<double> local(4 * kN, 0.0), all(4 * kN);
  const auto& p = *e.particles;
  for (int i = 0; i < p.nlocal; ++i) {
    const auto k = static_cast<std::size_t>(p.id[i] - 1);
    for (int d = 0; d < 3; ++d)
      local[4 * k + d] = p.v[i][d];
    local[4 * k + 3] = 1;
  }
  MPI_Allreduce(local.data(), all.data(), 4 * kN, MPI_DOUBLE, MPI_SUM, e.world);
  std::map<long long, Vec3> v;
  for (int k = 0; k < kN; ++k) {
    REQUIRE(all[4 * k + 3] == 1.0);
    v[k + 1] = Vec3(all[4 * k], all[4 * k + 1], all[4 * k + 2]);
  }
  return v;
}

void same_as_one_rank(granary::Engine& world, granary::Engine& self) {
  const auto a = velocities(world), b = velocities(self);
  for (const auto& [id, v] : a) {
    INFO("particle " << id << ": " << v.transpose() << " on all ranks, " << b.at(id).transpose()
                     << " on one");
    CHECK((v - b.at(id)).norm() <= 1e-12 * (1.0 + v.norm()));
  }
}

}  // namespace

TEST_CASE("fix aveforce: one mean force for the group on any number of ranks", "[aveforce][mpi]") {
  const std::vector<std::string> more = {"velocity all set 0 0 0",
                                         "group low type 1",
                                         "variable fx atom 1e-6*id",
                                         "variable fy atom 1e-6*sin(id)",
                                         "fix push all addforce v_fx v_fy 0",
                                         "fix ave low aveforce 0.0 0.0 NULL",
                                         "run 200"};
  granary::test::ScriptEngine world(MPI_COMM_WORLD), self(MPI_COMM_SELF);
  world.cmds(scene());
  world.cmds(more);
  self.cmds(scene());
  self.cmds(more);
  same_as_one_rank(world.e, self.e);
  // the particles of type 1 (on every rank) move as one under the mean of their forces
  double fx = 0, fy = 0, n = 0;
  std::vector<long long> low;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 4; ++k) {
        const long long id = 1 + 16 * i + 4 * j + k;
        if ((i + j + k) % 2 != 0) continue;
        low.push_back(id);
        fx += 1e-6 * id;
        fy += 1e-6 * std::sin(static_cast<double>(id));
        ++n;
      }
  const auto v = velocities(world.e);
  const auto& p = *world.e.particles;
  double mass_local = 0, mass = 0;
  for (int i = 0; i < p.nlocal; ++i)
    if (p.id[i] == low[0]) mass_local = p.rmass[i];
  MPI_Allreduce(&mass_local, &mass, 1, MPI_DOUBLE, MPI_SUM, world.e.world);
  const double t = 0.02;
  for (long long id : low) {
    CHECK(v.at(id)[0] == Approx(fx / n / mass * t).epsilon(1e-10));
    CHECK(v.at(id)[1] == Approx(fy / n / mass * t).epsilon(1e-10));
    CHECK(v.at(id)[2] == 0.0);
  }
  CHECK(world.e.fix_value("ave", 1) == Approx(fx).epsilon(1e-12));
}

TEST_CASE("fix momentum: zero total momentum and angular momentum on any number of ranks",
          "[momentum][mpi]") {
  granary::test::ScriptEngine world(MPI_COMM_WORLD), self(MPI_COMM_SELF);
  world.cmds(scene());
  self.cmds(scene());
  const Totals before = totals(world.e);
  REQUIRE(before.p.norm() > 1e-6);
  REQUIRE(before.l.norm() > 1e-10);

  // linear 1 1 0: x and y momentum removed, z kept (no forces: nothing else changes it)
  for (auto* s : {&world, &self})
    s->cmds({"fix mom all momentum 10 linear 1 1 0", "run 25"});
  Totals t = totals(world.e);
  const double pscale = before.mass * 0.3;
  CHECK(std::abs(t.p[0]) < 1e-14 * pscale);
  CHECK(std::abs(t.p[1]) < 1e-14 * pscale);
  CHECK(t.p[2] == Approx(before.p[2]).epsilon(1e-12));
  same_as_one_rank(world.e, self.e);

  // linear and angular: both zero after the fix fires at step 100 (x periodic:
  // some particles have crossed and are counted at their unwrapped positions)
  for (auto* s : {&world, &self})
    s->cmds({"unfix mom", "fix mom all momentum 100 linear 1 1 1 angular", "run 75"});
  int crossed = 0, crossed_all = 0;
  for (int i = 0; i < world.e.particles->nlocal; ++i) {
    int ix, iy, iz;
    granary::Particles::image_unpack(world.e.particles->image[i], ix, iy, iz);
    if (ix != 0) ++crossed;
  }
  MPI_Allreduce(&crossed, &crossed_all, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  REQUIRE(crossed_all > 0);
  t = totals(world.e);
  CHECK(t.p.norm() < 1e-14 * pscale);
  CHECK(t.l.norm() < 1e-10 * before.l.norm());
  same_as_one_rank(world.e, self.e);
}
