// On one rank without ghosts the contact history is set aside in list order
// at a rebuild and, when no particle changed its index, handed from each
// entry of the old list to the same pair's entry of the new one; otherwise
// (spatial sort, particles lost or inserted) it goes through the keyed store
// as on several ranks. Both ways must give the same values, so a run must be
// the same to the last bit with the hand-over allowed and forbidden.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <map>
#include <string>
#include <vector>

#include "script_engine.h"
#include "core/engine.h"
#include "core/force.h"
#include "neighbor/contact_history.h"
#include "neighbor/neighbor.h"
#include "particles/particles.h"

using granary::Vec3;

namespace {

struct Result {
  std::map<long long, Vec3> x, v, omega;
  long long hand_overs = 0, builds = 0;
  std::size_t created = 0;  // beads placed by create_atoms
};

// 70 beads of two sizes poured onto a plane wall between four side walls,
// Hertz with tangential history (the history handed over: the shear
// spring). `sort` is atom_modify's sort interval (0: never); with `spill`
// gravity has a sideways part and the wall at x = 0.008 is left out, so
// that the bed slides off the floor and the beads that leave the box are
// deleted during the run.
Result pour(bool in_place, int sort, bool spill) {
  granary::test::ScriptEngine s(MPI_COMM_SELF);
  const std::string wall = "wall/gran model hertz tangential history primitive type 1 ";
  s.cmds(granary::test::liggghts_head("0 0.008 0 0.008 0 0.06", 2));
  s.cmds({"atom_modify sort " + std::to_string(sort) + " 0.0",
          "neighbor 0.0005 bin",
          "neigh_modify delay 0",
          granary::test::materials(2, 5.e6, 0.45, 0.5, 0.5),
          "pair_style gran model hertz tangential history",
          "pair_coeff * *",
          "timestep 2e-5",
          "region fill block 0.0006 0.0074 0.0006 0.0074 0.001 0.025 units box",
          "create_atoms 1 random 45 2711 fill overlap 0.0021 maxtry 200",
          "create_atoms 2 random 25 2713 fill overlap 0.0021 maxtry 200",
          "set type 1 diameter 0.002 density 2500",
          "set type 2 diameter 0.0014 density 2500",
          "velocity all set 0.0 0.0 -0.5",
          std::string("fix gravi all gravity 9.81 vector ") + (spill ? "0.4" : "0.0") + " 0.0 -1.0",
          "fix zwall all " + wall + "zplane 0.0",
          "fix xwall1 all " + wall + "xplane 0.0",
          "fix ywall1 all " + wall + "yplane 0.0",
          "fix ywall2 all " + wall + "yplane 0.008",
          "fix integr all nve/sphere",
          "thermo_modify lost ignore"});
  if (!spill) s.cmd("fix xwall2 all " + wall + "xplane 0.008");
  const std::size_t created = static_cast<std::size_t>(s.p().nlocal);
  granary::ContactHistory* history = s.e.force->contact_history();
  REQUIRE(history != nullptr);
  history->in_place_allowed = in_place;
  s.cmd("run 1500");
  s.cmd("run 500");  // a second run: its set-up restores from the store saved at the end of the first
  Result out;
  out.created = created;
  const auto& p = s.p();
  for (int i = 0; i < p.nlocal; ++i) {
    out.x[p.id[i]] = p.x[i];
    out.v[p.id[i]] = p.v[i];
    out.omega[p.id[i]] = p.omega[i];
  }
  out.hand_overs = history->hand_overs();
  out.builds = s.e.neighbor->nbuilds;
  return out;
}

// Bit for bit: every component equal (==, not within a tolerance).
void require_same(const Result& a, const Result& b) {
  REQUIRE(a.x.size() == b.x.size());
  for (const auto& [id, xa] : a.x) {
    REQUIRE(b.x.count(id) == 1);
    INFO("particle " << id);
    for (int d = 0; d < 3; ++d) {
      CHECK(xa[d] == b.x.at(id)[d]);
      CHECK(a.v.at(id)[d] == b.v.at(id)[d]);
      CHECK(a.omega.at(id)[d] == b.omega.at(id)[d]);
    }
  }
}

}  // namespace

TEST_CASE("contact history handed over in list order equals the keyed store", "[history][neighbor]") {
  SECTION("no sort: every rebuild hands over in place") {
    const Result a = pour(true, 0, false), b = pour(false, 0, false);
    INFO(a.hand_overs << " hand-overs in " << a.builds << " builds");
    REQUIRE(a.created > 50);
    REQUIRE(a.x.size() == a.created);  // none lost
    CHECK(b.hand_overs == 0);
    // every build of the runs but their set-ups
    CHECK(a.hand_overs == a.builds - 2);
    CHECK(a.builds > 20);
    require_same(a, b);
  }
  SECTION("spatial sort every 100 steps: those rebuilds go through the store") {
    const Result a = pour(true, 100, false), b = pour(false, 100, false);
    INFO(a.hand_overs << " hand-overs in " << a.builds << " builds");
    REQUIRE(a.x.size() == a.created);
    CHECK(a.hand_overs > 0);
    // of the 15 + 5 sorting steps' builds, at least ten reordered the particles
    CHECK(a.hand_overs < a.builds - 2 - 10);
    require_same(a, b);
  }
  SECTION("beads leaving the box: deleted between saving and restoring") {
    const Result a = pour(true, 0, true), b = pour(false, 0, true);
    INFO(a.hand_overs << " hand-overs in " << a.builds << " builds, " << a.x.size() << " of " << a.created
                      << " beads left");
    CHECK(a.x.size() < a.created);
    CHECK(a.x.size() > 10);
    CHECK(a.hand_overs > 0);
    CHECK(a.hand_overs < a.builds - 2);
    require_same(a, b);
  }
}
