// The neighbour list against all pairs: every pair within (r_i + r_j) + skin
// is listed once, nothing else, in a periodic box (ghosts) of large and many
// small spheres. The bins are crowded there, so from the second build on the
// list leaves out the neighbouring bins beyond each particle's reach
// (Neighbor::pruned_bins()); the lists must be those of all pairs either way.
// And with clumps of 50 overlapping sub-spheres beside free spheres: the
// pairs within one clump are left out as the candidates are tested.
#include <catch2/catch.hpp>

#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "core/engine.h"
#include "neighbor/neighbor.h"
#include "particles/particles.h"
#include "script_engine.h"

namespace {

// For each owned particle, its partners as (id, index), in the list's order,
// and the same found by testing every pair (the list's rule: an owned partner
// of higher index; any ghost but i's own images, with newton on only those of
// higher id).
using Partners = std::vector<std::vector<std::pair<granary::tagint, int>>>;

Partners listed(const granary::Engine& e) {
  const granary::Particles& p = *e.particles;
  const granary::Neighbor& list = *e.neighbor;
  Partners out(p.nlocal);
  for (int i = 0; i < p.nlocal; ++i)
    for (int k = list.offset[i]; k < list.offset[i + 1]; ++k)
      out[i].emplace_back(p.id[list.neigh[k]], list.neigh[k]);
  return out;
}

Partners all_pairs(const granary::Engine& e, bool newton) {
  const granary::Particles& p = *e.particles;
  const granary::Neighbor& list = *e.neighbor;
  Partners out(p.nlocal);
  for (int i = 0; i < p.nlocal; ++i) {
    for (int j = i + 1; j < p.size(); ++j) {
      if (j >= p.nlocal && (p.id[j] == p.id[i] || (newton && p.id[j] < p.id[i]))) continue;
      if (p.body[i] >= 0 && p.body[i] == p.body[j]) continue;  // sub-spheres of one clump
      const double rc = (p.radius[i] + p.radius[j]) * list.range_factor + list.skin;
      if ((p.x[i] - p.x[j]).squaredNorm() < rc * rc) out[i].emplace_back(p.id[j], j);
    }
    std::sort(out[i].begin(), out[i].end());
  }
  return out;
}

std::size_t count(const Partners& lists) {
  std::size_t n = 0;
  for (const auto& l : lists)
    n += l.size();
  return n;
}

}  // namespace

TEST_CASE("Neighbour list: all pairs within the cutoff, with and without the crowded bins' pruning",
          "[neighbor]") {
  for (const std::string newton : {"off", "on"}) {
    granary::test::ScriptEngine s;
    s.cmds({"atom_style granular", "atom_modify map array", "boundary p p p", "newton " + newton,
            "communicate single vel yes", "units si", "region domain block 0 0.02 0 0.02 0 0.02 units box",
            "create_box 2 domain", "neighbor 0.0002 bin", "neigh_modify delay 0",
            "fix m1 all property/global youngsModulus peratomtype 5.e6 5.e6",
            "fix m2 all property/global poissonsRatio peratomtype 0.45 0.45",
            "fix m3 all property/global coefficientRestitution peratomtypepair 2 0.5 0.5 0.5 0.5",
            "fix m4 all property/global coefficientFriction peratomtypepair 2 0.5 0.5 0.5 0.5",
            "pair_style gran model hertz tangential history", "pair_coeff * *", "timestep 0.000001",
            // 600 spheres of 2 mm and 5000 of 0.25 mm at random points: bins
            // 2.2 mm wide, about 7.5 particles in each
            "create_atoms 1 random 600 4711 NULL", "create_atoms 2 random 5000 4712 NULL",
            "set type 1 diameter 0.002 density 2500", "set type 2 diameter 0.00025 density 2500",
            "fix integr all nve/sphere", "run 0"});
    const granary::Engine& e = s.e;
    INFO("newton " << newton);
    REQUIRE(e.particles->size() > e.particles->nlocal);  // periodic images: ghosts
    {
      const Partners b = all_pairs(e, newton == "on");
      INFO(count(b) << " pairs within the cutoff");
      REQUIRE(count(b) > 4000);
      REQUIRE(listed(e) == b);
    }
    // the first build found the bins crowded: the next ones prune
    REQUIRE(!e.neighbor->pruned_bins());
    s.cmd("run 0");
    REQUIRE(e.neighbor->pruned_bins());
    CHECK(listed(e) == all_pairs(e, newton == "on"));
    // and after the particles moved (some across the periodic boundaries)
    s.cmd("displace_atoms all random 0.003 0.003 0.003 977 units box");
    s.cmd("run 0");
    REQUIRE(e.neighbor->pruned_bins());
    CHECK(listed(e) == all_pairs(e, newton == "on"));
  }
}

TEST_CASE("Neighbour list: all pairs of sub-spheres of different clumps and free spheres within the cutoff",
          "[neighbor]") {
  for (const std::string newton : {"off", "on"}) {
    granary::test::ScriptEngine s;
    s.cmds(
        {"atom_style granular",
         "atom_modify map array",
         "boundary p p f",
         "newton " + newton,
         "communicate single vel yes",
         "units si",
         "region domain block -0.012 0.012 -0.012 0.012 0 0.024 units box",
         "create_box 2 domain",
         "neighbor 0.0008 bin",
         "neigh_modify delay 0",
         "fix m1 all property/global youngsModulus peratomtype 5.e6 5.e6",
         "fix m2 all property/global poissonsRatio peratomtype 0.45 0.45",
         "fix m3 all property/global coefficientRestitution peratomtypepair 2 0.5 0.5 0.5 0.5",
         "fix m4 all property/global coefficientFriction peratomtypepair 2 0.5 0.5 0.5 0.5",
         "pair_style gran model hertz tangential history",
         "pair_coeff * *",
         "timestep 0.000001",
         std::string("fix cyl all particletemplate/multisphere 15485863 atom_type 1 density constant 1190 "
                     "nspheres 50 ntry 1000000 spheres file ") +
             GRANARY_SOURCE_DIR + "/potentials/cylinder_ellipse_50.clump scale 1.0 type 1",
         "fix glass all particletemplate/sphere 15485867 atom_type 2 density constant 2500 radius constant "
         "0.0005",
         "fix mix all particledistribution/discrete 49979687 2 cyl 0.9 glass 0.1",
         "fix ms all multisphere",
         "fix integr all nve/sphere",
         "region fill block -0.012 0.012 -0.012 0.012 0.001 0.023 units box",
         "fix ins all insert/pack seed 32452867 distributiontemplate mix maxattempt 200 insert_every once "
         "overlapcheck yes all_in yes orientation random region fill volumefraction_region 0.3",
         "run 1"});
    const granary::Engine& e = s.e;
    INFO("newton " << newton);
    const granary::Particles& p = *e.particles;
    REQUIRE(p.size() > p.nlocal);  // periodic images in x and y: ghosts
    int sub = 0;
    for (int i = 0; i < p.nlocal; ++i)
      sub += p.body[i] >= 0;
    INFO(sub << " sub-spheres of " << p.nlocal << " particles");
    REQUIRE(sub > 2000);
    REQUIRE(p.nlocal - sub > 50);
    // the clumps' bins are crowded: prune from the next build on
    s.cmd("run 0");
    REQUIRE(e.neighbor->pruned_bins());
    const Partners b = all_pairs(e, newton == "on");
    INFO(count(b) << " pairs within the cutoff");
    REQUIRE(count(b) > 5000);
    CHECK(listed(e) == b);
  }
}
