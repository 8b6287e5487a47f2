// atom_modify sort: the order it gives (the sub-spheres of clumps first, body
// by body in sub-sphere order, then the free spheres, each part along the
// bins) and that it changes the physics by round-off only.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "script_engine.h"
#include "core/engine.h"
#include "core/update.h"
#include "domain/domain.h"
#include "neighbor/neighbor.h"
#include "particles/particles.h"

using granary::Vec3;

namespace {

struct Sim : granary::test::ScriptEngine {
  Sim() : ScriptEngine(MPI_COMM_WORLD) {}
};

// Three-sphere clumps (type 1) and free spheres (type 2) poured into a box of
// plane walls; `sort` is the atom_modify sort frequency.
void pour(Sim& s, int sort) {
  s.cmds(
      {"units si",
       "atom_style granular",
       "atom_modify map array",
       "atom_modify sort " + std::to_string(sort) + " 0.0",
       "boundary f f f",
       "newton off",
       "region box block -0.01 0.01 -0.01 0.01 0 0.04",
       "create_box 2 box",
       "neighbor 0.0005 bin",
       "neigh_modify delay 0",
       granary::test::materials(2, 5.e6, 0.45, 0.5, 0.5),
       "pair_style gran model hertz tangential history",
       "pair_coeff * *",
       "timestep 1e-5",
       "fix g all gravity 9.81 vector 0 0 -1",
       "fix zw all wall/gran model hertz tangential history primitive type 1 zplane 0.0",
       "fix xw1 all wall/gran model hertz tangential history primitive type 1 xplane -0.01",
       "fix xw2 all wall/gran model hertz tangential history primitive type 1 xplane 0.01",
       "fix yw1 all wall/gran model hertz tangential history primitive type 1 yplane -0.01",
       "fix yw2 all wall/gran model hertz tangential history primitive type 1 yplane 0.01",
       "fix tri all particletemplate/multisphere 15485863 atom_type 1 density constant 2500 nspheres 3 ntry "
       "1000000 spheres 0 0 0 0.001 0.0015 0 0 0.00075 0 0.00125 0 0.0005 type 1",
       "fix sph all particletemplate/sphere 32452843 atom_type 2 density constant 2500 radius constant "
       "0.0004",
       "fix mix all particledistribution/discrete 49979687 2 tri 0.6 sph 0.4",
       "fix ms all multisphere",
       "fix nve all nve/sphere",
       "region fill block -0.009 0.009 -0.009 0.009 0.001 0.039 units box",
       "fix ins all insert/pack seed 32452867 distributiontemplate mix maxattempt 200 insert_every once "
       "overlapcheck yes all_in yes orientation random vel constant 0 0 -0.3 region fill "
       "volumefraction_region 0.25"});
}

// Positions and velocities by id.
std::map<long, std::pair<Vec3, Vec3>> state(const granary::Particles& p) {
  std::map<long, std::pair<Vec3, Vec3>> s;
  for (int i = 0; i < p.nlocal; ++i)
    s[static_cast<long>(p.id[i])] = {p.x[i], p.v[i]};
  return s;
}

}  // namespace

TEST_CASE("atom_modify sort: sub-spheres body by body, then free spheres, each part along the bins",
          "[sort]") {
  Sim s;
  pour(s, 200);
  s.cmd("run 1000");  // sorted at steps 200, 400, ..., 1000 (the last in the run's last step)
  const granary::Particles& p = *s.e.particles;
  int nsub = 0, nfree = 0;
  for (int i = 0; i < p.nlocal; ++i)
    (p.body[i] >= 0 ? nsub : nfree) += 1;
  REQUIRE(nsub >= 150);
  REQUIRE(nfree >= 150);
  // the sub-spheres come first, then the free spheres
  for (int i = 0; i < p.nlocal; ++i)
    CHECK((p.body[i] >= 0) == (i < nsub));
  // a body's sub-spheres lie together, in id order
  std::map<long, int> last;
  for (int i = 0; i < nsub; ++i) {
    const long b = static_cast<long>(p.body[i]);
    if (last.count(b)) {
      CHECK(last[b] == i - 1);
      CHECK(p.id[i] > p.id[i - 1]);
    }
    last[b] = i;
  }
  // the free spheres along the bins (half the neighbour cutoff) of the owned
  // box: z slowest, x fastest; the bin index never decreases (the sort came
  // at the reneighbouring of step 1000, after the positions' last update)
  double prev = -1;
  const auto& dom = *s.e.domain;
  int nb[3];
  const double binsize = 0.5 * s.e.neighbor->cutneighmax;
  REQUIRE(binsize > 0.001);
  for (int d = 0; d < 3; ++d)
    nb[d] = std::clamp(static_cast<int>((dom.subhi[d] - dom.sublo[d]) / binsize), 1, 1 << 10);
  int decreasing = 0;
  for (int i = nsub; i < p.nlocal; ++i) {
    int c[3];
    for (int d = 0; d < 3; ++d) {
      const double f = (p.x[i][d] - dom.sublo[d]) / (dom.subhi[d] - dom.sublo[d]);
      c[d] = std::clamp(static_cast<int>(f * nb[d]), 0, nb[d] - 1);
    }
    const double key = (static_cast<double>(c[2]) * nb[1] + c[1]) * nb[0] + c[0];
    decreasing += key < prev;
    prev = key;
  }
  CHECK(decreasing == 0);
}

TEST_CASE("atom_modify sort: the pour with and without sorting agrees to round-off", "[sort]") {
  // Sorting only changes the order in which the contact forces on a particle
  // are added; over 1500 steps (15 sorts; the lowest particles reach the floor,
  // falling ones collide) the paths differ by round-off grown by the collisions:
  // 2.4e-12 m and 1.3e-8 m/s at most, checked against 1e-9 m and 1e-6 m/s. A
  // sort that broke the particles' records (a body's sub-spheres, the
  // contact history) would move them by their size.
  Sim a, b;
  pour(a, 100);
  pour(b, 0);
  a.cmd("run 1500");
  b.cmd("run 1500");
  const auto sa = state(*a.e.particles), sb = state(*b.e.particles);
  REQUIRE(sa.size() == sb.size());
  REQUIRE(sa.size() >= 300);
  double dx = 0, dv = 0, vmax = 0;
  for (const auto& [id, xv] : sa) {
    const auto& o = sb.at(id);
    dx = std::max(dx, (xv.first - o.first).norm());
    dv = std::max(dv, (xv.second - o.second).norm());
    vmax = std::max(vmax, xv.second.norm());
  }
  CHECK(vmax > 0.3);  // falling: the forces and the integration did something
  CAPTURE(dx, dv);
  CHECK(dx < 1e-9);
  CHECK(dv < 1e-6);
  CHECK(dx > 0);  // the order of the additions did change
}
