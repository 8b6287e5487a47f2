// The pair loop of pair_style gran (pair/pair_loop.h: lane::Wide contacts at a time,
// in blocks across particles) against a plain loop over the same neighbour
// list that calls contact::evaluate (the same formulas on one lane) pair by
// pair in the list's order: on a settled, partly sliding bed of two kinds of
// spheres both must give the same forces, torques, histories and contact
// flags to the last bit, for compiled hot kernels and run-time slots alike.
// The pair loop over its near list (the entries that can touch before it is
// remade) gives the trajectories of a scan of every list entry, to the last bit.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "contact/contact_model.h"
#include "core/engine.h"
#include "core/update.h"
#include "neighbor/neighbor.h"
#include "core/force.h"
#include "pair/pair_granular.h"
#include "same_bits.h"
#include "script_engine.h"

using granary::Vec3;
using granary::test::ScriptEngine;

namespace {

using granary::test::same_bits;

// A bed of 2 mm spheres (type 1) and 1.6 mm lighter ones (type 2, other
// material) poured into a box of plane walls.
void pour(ScriptEngine& s, const std::string& pair_words, const std::string& newton,
          const std::string& run = "run 15000") {
  s.cmds({"atom_style granular",
          "atom_modify map array",
          "boundary m m m",
          "newton " + newton,
          "communicate single vel yes",
          "units si",
          "region domain block -0.01 0.01 -0.01 0.01 0.0 0.04 units box",
          "create_box 2 domain",
          "neighbor 0.0005 bin",
          "neigh_modify delay 0",
          "fix m1 all property/global youngsModulus peratomtype 5.e6 2.e6",
          "fix m2 all property/global poissonsRatio peratomtype 0.45 0.3",
          "fix m3 all property/global coefficientRestitution peratomtypepair 2 0.9 0.7 0.7 0.5",
          "fix m4 all property/global coefficientFriction peratomtypepair 2 0.5 0.3 0.3 0.2",
          "fix m5 all property/global coefficientRollingFriction peratomtypepair 2 0.1 0.05 0.05 0.02",
          "fix m6 all property/global characteristicVelocity scalar 0.5",
          "fix m7 all property/global cohesionEnergyDensity peratomtypepair 2 300 200 200 100",
          "pair_style " + pair_words,
          "pair_coeff * *",
          "timestep 0.00001",
          "fix gravi all gravity 9.81 vector 0.0 0.0 -1.0",
          "fix zwall all wall/gran model hertz tangential history primitive type 1 zplane 0.0",
          "fix xw1 all wall/gran model hertz tangential history primitive type 1 xplane -0.01",
          "fix xw2 all wall/gran model hertz tangential history primitive type 1 xplane 0.01",
          "fix yw1 all wall/gran model hertz tangential history primitive type 1 yplane -0.01",
          "fix yw2 all wall/gran model hertz tangential history primitive type 1 yplane 0.01",
          "lattice bcc 0.0025",
          "region fill block -0.0085 0.0085 -0.0085 0.0085 0.0051 0.0301 units box",
          "create_atoms 1 region fill",
          "set group all diameter 0.002 density 2500",
          "region small block -0.0085 0.0085 -0.0085 0.0 0.0051 0.0301 units box",
          "set region small type 2",
          "set region small diameter 0.0016 density 1800",
          "velocity all set 0.1 0.0 -0.5 units box",
          "fix integr all nve/sphere",
          run});
}

// Forces, torques and history of one pair computation by the loop of the pair style.
struct Snapshot {
  std::vector<Vec3> f, torque;
  std::vector<double> hist;
  std::vector<std::uint8_t> touch;
  int sliding = 0;  // contacts at the Coulomb limit (pair by pair only)
};

// The history of every list entry in list order (zeros without a contact), and
// which entries hold a contact.
std::vector<double> dense_history(granary::PairGranular& pair) {
  const granary::ContactHistory& h = *pair.history();
  const int nh = pair.history_size();
  std::vector<double> out(h.entries() * nh, 0.0);
  for (std::size_t k = 0; k < h.entries(); ++k)
    if (const double* v = h.find(k)) std::copy_n(v, nh, &out[k * nh]);
  return out;
}

std::vector<std::uint8_t> touched_entries(granary::PairGranular& pair) {
  const granary::ContactHistory& h = *pair.history();
  std::vector<std::uint8_t> out(h.entries());
  for (std::size_t k = 0; k < h.entries(); ++k)
    out[k] = h.touched(k);
  return out;
}

Snapshot compute_with_style(ScriptEngine& s) {
  granary::Particles& p = *s.e.particles;
  for (int i = 0; i < p.size(); ++i) {
    p.f[i].setZero();
    p.torque[i].setZero();
  }
  s.e.force->pair->compute();
  auto* pair = dynamic_cast<granary::PairGranular*>(s.e.force->pair.get());
  return {p.f, p.torque, dense_history(*pair), touched_entries(*pair), 0};
}

// The same with contact::evaluate, pair by pair in the list's order.
Snapshot compute_pair_by_pair(ScriptEngine& s) {
  granary::Engine& e = s.e;
  granary::Particles& p = *e.particles;
  auto* pair = dynamic_cast<granary::PairGranular*>(e.force->pair.get());
  const granary::Neighbor& list = *e.neighbor;
  granary::ContactHistory& hist = *pair->history();
  const int nh = pair->history_size();
  const bool newton = e.force->newton_pair;
  for (int i = 0; i < p.size(); ++i) {
    p.f[i].setZero();
    p.torque[i].setZero();
  }
  granary::contact::ContactState c;
  granary::contact::ContactResult res;
  c.dt = e.update->history_dt();
  int sliding = 0;
  for (int i = 0; i < p.nlocal; ++i) {
    Vec3 fi = p.f[i], ti = p.torque[i];
    for (int k = list.offset[i]; k < list.offset[i + 1]; ++k) {
      const int j = list.neigh[k];
      const Vec3 d = p.x[i] - p.x[j];
      const double rsum = p.radius[i] + p.radius[j];
      const double r2 = d.squaredNorm();
      if (!(r2 < rsum * rsum && r2 != 0.0)) {
        if (hist.touched(k)) hist.forget(k);
        continue;
      }
      const double r = std::sqrt(r2);
      const double inv_r = 1.0 / r;
      c.n = d * inv_r;
      c.overlap = rsum - r;
      c.r_i = p.radius[i];
      c.r_j = p.radius[j];
      c.r_eff = p.radius[i] * p.radius[j] / rsum;
      c.m_eff = p.rmass[i] * p.rmass[j] / (p.rmass[i] + p.rmass[j]);
      c.v_rel = p.v[i] - p.v[j];
      c.omega_i = p.omega[i];
      c.omega_j = p.omega[j];
      const granary::contact::PairMaterial& mat = pair->materials()(p.type[i], p.type[j]);
      granary::contact::evaluate(pair->spec(), c, mat, hist.values(k), res);
      sliding += res.ft.norm() >= (1.0 - 1e-9) * mat.friction * std::abs(res.fn);
      fi += res.force;
      ti += res.torque_i;
      if (newton || j < p.nlocal) {
        p.f[j] -= res.force;
        p.torque[j] += res.torque_j;
      }
    }
    p.f[i] = fi;
    p.torque[i] = ti;
  }
  return {p.f, p.torque, dense_history(*pair), touched_entries(*pair), sliding};
}

void compare_loops(const std::string& pair_words, const std::string& newton) {
  ScriptEngine s;
  pour(s, pair_words, newton);
  auto* pair = dynamic_cast<granary::PairGranular*>(s.e.force->pair.get());
  REQUIRE(pair != nullptr);
  // both start from the history of the last step
  const granary::ContactHistory hist0 = *pair->history();
  const Snapshot lanes = compute_with_style(s);
  *pair->history() = hist0;
  const Snapshot plain = compute_pair_by_pair(s);

  const granary::Particles& p = s.p();
  int contacts = 0;
  for (std::size_t k = 0; k < plain.touch.size(); ++k)
    contacts += plain.touch[k];
  INFO(pair_words << ", newton " << newton << ": " << p.nlocal << " particles, " << contacts << " contacts, "
                  << plain.sliding << " sliding");
  REQUIRE(contacts > p.nlocal);  // a settled bed
  // some contacts slide, most stick: both branches of the kernel ran
  REQUIRE(plain.sliding > 0);
  REQUIRE(plain.sliding < contacts / 2);
  for (int i = 0; i < p.nlocal; ++i) {
    for (int d = 0; d < 3; ++d) {
      INFO("particle " << i << " component " << d);
      REQUIRE(same_bits(lanes.f[i][d], plain.f[i][d]));
      REQUIRE(same_bits(lanes.torque[i][d], plain.torque[i][d]));
    }
  }
  REQUIRE(lanes.touch == plain.touch);
  REQUIRE(lanes.hist.size() == plain.hist.size());
  for (std::size_t q = 0; q < plain.hist.size(); ++q) {
    INFO("history value " << q);
    REQUIRE(same_bits(lanes.hist[q], plain.hist[q]));
  }
}

}  // namespace

TEST_CASE("Pair loop equals contact::evaluate pair by pair (run-time slots: epsd2, cohesion)",
          "[pair][lanes]") {
  compare_loops("gran model hertz tangential history rolling_friction epsd2 cohesion sjkr", "off");
}

TEST_CASE("Pair loop equals contact::evaluate pair by pair (run-time slots: mindlin_deresiewicz, epsd2)",
          "[pair][lanes]") {
  compare_loops("gran model hertz tangential mindlin_deresiewicz rolling_friction epsd2", "off");
}

TEST_CASE("Pair loop equals contact::evaluate pair by pair (run-time slots: hooke)", "[pair][lanes]") {
  compare_loops("gran model hooke tangential history rolling_friction cdt", "on");
}

TEST_CASE("Lane pair loop equals the scalar kernel pair by pair (cdt rolling)", "[pair][lanes]") {
  compare_loops("gran model hertz tangential history rolling_friction cdt", "off");
}

TEST_CASE("Lane pair loop equals the scalar kernel pair by pair (no rolling, limitForce, newton on)",
          "[pair][lanes]") {
  compare_loops("gran model hertz tangential history limitForce on", "on");
}

// The pour with the near list and with a scan of every list entry: the same
// positions, velocities and spins to the last bit after 15,000 steps of
// falling, bouncing and settling (the near list was remade many times). With
// the default neigh_modify the neighbour list's watch tells when to remake
// it (and bounds the displacement since the last build: the builds must come
// at the same steps as without it); with `every 2` the pair style checks for
// itself at the steps where decide() does not look.
TEST_CASE("The pair loop's near list gives the trajectories of a full scan", "[pair][near]") {
  for (const std::string every : {"1", "2"}) {
    for (const std::string words :
         {"gran model hertz tangential history rolling_friction cdt",
          "gran model hertz tangential mindlin_deresiewicz rolling_friction epsd2"}) {
      INFO(words << ", neigh_modify every " << every);
      ScriptEngine a, b;
      pour(a, words, "off", "run 0");
      pour(b, words, "off", "neigh_modify delay 0");
      dynamic_cast<granary::PairGranular&>(*b.e.force->pair).near_list = false;
      b.cmd("run 0");
      a.cmd("neigh_modify delay 0 every " + every);
      b.cmd("neigh_modify delay 0 every " + every);
      a.cmd("run 15000");
      b.cmd("run 15000");
      REQUIRE(a.p().nlocal == b.p().nlocal);
      REQUIRE(a.p().nlocal > 100);
      int differ = 0;
      for (int i = 0; i < a.p().nlocal; ++i)
        differ += !same_bits(a.p().x[i], b.p().x[i]) || !same_bits(a.p().v[i], b.p().v[i]) ||
                  !same_bits(a.p().omega[i], b.p().omega[i]);
      CHECK(differ == 0);
      const granary::Neighbor &na = *a.e.neighbor, &nb = *b.e.neighbor;
      CHECK(na.nbuilds == nb.nbuilds);
      // the watch advanced between builds (the near list was remade on its word)
      const std::int64_t between = na.watch_epoch() - na.nbuilds;
      INFO(na.nbuilds << " builds, " << between << " near-list epochs between them");
      CHECK(nb.watch_epoch() == nb.nbuilds);
      CHECK(between > 10);
    }
  }
}
