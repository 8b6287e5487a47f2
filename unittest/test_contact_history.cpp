// The contact history's slots (src/neighbor/contact_history.h): a slot number
// per neighbour-list entry and the values of the contacts only. A slot taken
// again after its contact ended starts at zero; the set-aside state of a run's
// setup comes back whatever the setup's evaluation did; on a bed after a pair
// computation exactly the touching entries hold a slot, each its own.
#include <catch2/catch.hpp>

#include <cstddef>
#include <set>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/force.h"
#include "neighbor/contact_history.h"
#include "neighbor/neighbor.h"
#include "pair/pair.h"
#include "script_engine.h"

using granary::ContactHistory;

TEST_CASE("contact history: a slot is taken when a contact begins and given back when it ends", "[history]") {
  ContactHistory h;
  h.configure(3, {-1.0, -1.0, -1.0});
  h.reset(10);
  REQUIRE(h.entries() == 10);
  REQUIRE(h.contacts() == 0);
  for (std::size_t k = 0; k < 10; ++k)
    REQUIRE(h.find(k) == nullptr);

  double* a = h.values(3);  // a contact begins: zeros
  CHECK(a[0] == 0.0);
  CHECK(a[2] == 0.0);
  a[0] = 1.5;
  a[2] = -2.0;
  h.values(6)[1] = 7.0;
  CHECK(h.contacts() == 2);
  CHECK(h.touched(3));
  CHECK_FALSE(h.touched(4));
  CHECK(h.values(3)[0] == 1.5);  // an entry with a slot keeps it

  h.forget(3);  // the contact ended
  CHECK_FALSE(h.touched(3));
  CHECK(h.find(3) == nullptr);
  CHECK(h.contacts() == 1);
  const double* b = h.values(8);  // takes the slot entry 3 gave back, cleared
  CHECK(b[0] == 0.0);
  CHECK(b[1] == 0.0);
  CHECK(b[2] == 0.0);
  CHECK(h.contacts() == 2);
  CHECK(h.find(6)[1] == 7.0);

  h.reset(4);  // a new list: no contact
  CHECK(h.entries() == 4);
  CHECK(h.contacts() == 0);
}

TEST_CASE("contact history: put_back restores the contacts set aside by hold", "[history]") {
  ContactHistory h;
  h.configure(2, {-1.0, 1.0});
  h.reset(12);
  h.values(2)[0] = 0.25;
  h.values(2)[1] = -4.0;
  h.values(9)[1] = 3.0;
  h.hold();
  // the setup's evaluation: one contact ends, one begins, one changes
  h.forget(2);
  h.values(5)[0] = 11.0;
  h.values(9)[1] = 30.0;
  h.put_back();
  CHECK(h.contacts() == 2);
  REQUIRE(h.touched(2));
  CHECK(h.find(2)[0] == 0.25);
  CHECK(h.find(2)[1] == -4.0);
  CHECK_FALSE(h.touched(5));
  REQUIRE(h.touched(9));
  CHECK(h.find(9)[0] == 0.0);
  CHECK(h.find(9)[1] == 3.0);
  // a contact beginning after put_back starts at zero
  CHECK(h.values(5)[0] == 0.0);
}

TEST_CASE("contact history on a bed: exactly the touching list entries hold a slot, each its own",
          "[history][pair]") {
  granary::test::ScriptEngine s;
  s.cmds({"atom_style granular",
          "atom_modify map array",
          "boundary m m m",
          "newton off",
          "communicate single vel yes",
          "region domain block -0.006 0.006 -0.006 0.006 0.0 0.03 units box",
          "create_box 1 domain",
          "neighbor 0.0004 bin",
          "neigh_modify delay 0",
          "fix m1 all property/global youngsModulus peratomtype 5.e6",
          "fix m2 all property/global poissonsRatio peratomtype 0.45",
          "fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5",
          "fix m4 all property/global coefficientFriction peratomtypepair 1 0.5",
          "fix m5 all property/global coefficientRollingFriction peratomtypepair 1 0.1",
          "pair_style gran model hertz tangential history rolling_friction cdt",
          "pair_coeff * *",
          "timestep 0.00001",
          "fix gravi all gravity 9.81 vector 0.0 0.0 -1.0",
          "fix zwall all wall/gran model hertz tangential history primitive type 1 zplane 0.0",
          "fix xw1 all wall/gran model hertz tangential history primitive type 1 xplane -0.006",
          "fix xw2 all wall/gran model hertz tangential history primitive type 1 xplane 0.006",
          "fix yw1 all wall/gran model hertz tangential history primitive type 1 yplane -0.006",
          "fix yw2 all wall/gran model hertz tangential history primitive type 1 yplane 0.006",
          "lattice sc 0.0021",
          "region fill block -0.005 0.005 -0.005 0.005 0.002 0.028 units box",
          "create_atoms 1 region fill",
          "set group all diameter 0.002 density 2500",
          "velocity all set 0.05 -0.03 -0.3 units box",
          "fix integr all nve/sphere"});
  auto check = [&](const std::string& when) {
    granary::Engine& e = s.e;
    granary::Particles& p = *e.particles;
    e.force->pair->compute();  // the history of the current positions
    const ContactHistory& h = *e.force->pair->history();
    const granary::Neighbor& list = *e.neighbor;
    REQUIRE(h.entries() == list.neigh.size());
    std::size_t touching = 0;
    std::set<const double*> slots;
    for (int i = 0; i < p.nlocal; ++i)
      for (int k = list.offset[i]; k < list.offset[i + 1]; ++k) {
        const int j = list.neigh[k];
        const double rsum = p.radius[i] + p.radius[j];
        const bool t = (p.x[i] - p.x[j]).squaredNorm() < rsum * rsum;
        INFO(when << ": list entry " << k);
        REQUIRE(h.touched(k) == t);
        touching += t;
        if (t) REQUIRE(slots.insert(h.find(k)).second);
      }
    INFO(when << ": " << touching << " contacts, " << list.neigh.size() << " list entries");
    CHECK(h.contacts() == touching);
    return touching;
  };
  s.cmd("run 3000");  // falling and landing: contacts begin and end
  const std::size_t landing = check("landing");
  s.cmd("run 12000");
  const std::size_t settled = check("settled");
  CHECK(landing > 0);
  CHECK(settled > 0);
}
