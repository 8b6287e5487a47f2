// The neighbour list against all pairs: every pair within (r_i + r_j) + skin
// is listed once, nothing else, in a periodic box (ghosts) of large and many
// small spheres. The bins are crowded there, so from the second build on the
// list leaves out the neighbouring bins beyond each particle's reach
// (Neighbor::pruned_bins()); the lists must be those of all pairs either way.
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
      const double rc = (p.radius[i] + p.radius[j]) * list.range_factor + list.skin;
      if ((p.x[i] - p.x[j]).squaredNorm() < rc * rc) out[i].emplace_back(p.id[j], j);
    }
    std::sort(out[i].begin(), out[i].end());
  }
  return out;
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
      const Partners a = listed(e), b = all_pairs(e, newton == "on");
      std::size_t pairs = 0;
      for (const auto& l : b)
        pairs += l.size();
      INFO(pairs << " pairs within the cutoff");
      REQUIRE(pairs > 4000);
      REQUIRE(a == b);
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
