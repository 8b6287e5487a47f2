// Computes ke, erotate/sphere, property/atom, reduce, reduce/region and
// count/region on small configurations with known answers.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "script_engine.h"
#include "compute/compute.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/input.h"
#include "core/logger.h"
#include "core/modify.h"
#include "core/variable.h"
#include "particles/particles.h"

using Catch::Matchers::Contains;
using granary::Engine;
using granary::InputError;

namespace {

struct Sim : granary::test::ScriptEngine {
  Sim() : ScriptEngine(MPI_COMM_WORLD) {}
  double value(const std::string& id, int index = 0) { return e.compute_value(id, index); }
};

// Four particles with known properties:
//   id  x          d     rho   v            omega
//   1   (1,1,1)    0.2   1000  (1,0,0)      (0,0,10)
//   2   (2,3,4)    0.4   2000  (0,-2,0)     (1,2,2)
//   3   (5,5,5)    0.2   1000  (3,4,0)      (0,0,0)
//   4   (8,1,2)    0.6   500   (-1,-1,-1)   (0,5,0)
struct Particle {
  double x[3], d, rho, v[3], w[3];
};
const std::vector<Particle> kParticles = {
    {{1, 1, 1}, 0.2, 1000, {1, 0, 0}, {0, 0, 10}},
    {{2, 3, 4}, 0.4, 2000, {0, -2, 0}, {1, 2, 2}},
    {{5, 5, 5}, 0.2, 1000, {3, 4, 0}, {0, 0, 0}},
    {{8, 1, 2}, 0.6, 500, {-1, -1, -1}, {0, 5, 0}},
};

double mass(const Particle& p) {
  return 4.0 / 3.0 * M_PI * std::pow(0.5 * p.d, 3) * p.rho;
}
double v2(const Particle& p) {
  return p.v[0] * p.v[0] + p.v[1] * p.v[1] + p.v[2] * p.v[2];
}
double w2(const Particle& p) {
  return p.w[0] * p.w[0] + p.w[1] * p.w[1] + p.w[2] * p.w[2];
}

void setup(Sim& s) {
  s.cmds({"units si", "atom_style granular", "boundary f f f", "region box block 0 10 0 10 0 10",
          "create_box 2 box"});
  int id = 1;
  for (const auto& p : kParticles) {
    char line[512];
    std::snprintf(line, sizeof line, "create_atoms 1 single %g %g %g", p.x[0], p.x[1], p.x[2]);
    s.cmd(line);
    std::snprintf(line, sizeof line, "set atom %d diameter %g density %g vx %g vy %g vz %g omega %g %g %g",
                  id, p.d, p.rho, p.v[0], p.v[1], p.v[2], p.w[0], p.w[1], p.w[2]);
    s.cmd(line);
    ++id;
  }
  s.cmd("set atom 4 type 2");
  s.cmd("group two id 2 4");
}

}  // namespace

TEST_CASE("compute ke and erotate/sphere", "[compute]") {
  Sim s;
  setup(s);
  s.cmds({"compute ke all ke", "compute rot all erotate/sphere", "compute ke2 two ke",
          "compute rot2 two erotate/sphere"});
  double ke = 0, rot = 0, ke2 = 0, rot2 = 0;
  for (std::size_t k = 0; k < kParticles.size(); ++k) {
    const auto& p = kParticles[k];
    const double m = mass(p), r = 0.5 * p.d;
    ke += 0.5 * m * v2(p);
    rot += 0.5 * 0.4 * m * r * r * w2(p);
    if (k == 1 || k == 3) {
      ke2 += 0.5 * m * v2(p);
      rot2 += 0.5 * 0.4 * m * r * r * w2(p);
    }
  }
  CHECK(s.value("ke") == Approx(ke).epsilon(1e-12));
  CHECK(s.value("rot") == Approx(rot).epsilon(1e-12));
  CHECK(s.value("ke2") == Approx(ke2).epsilon(1e-12));
  CHECK(s.value("rot2") == Approx(rot2).epsilon(1e-12));
  auto* c = s.e.modify->find_compute("ke");
  CHECK(c->scalar_flag);
  CHECK(c->extensive);
  CHECK_THROWS_WITH(s.cmd("compute bad all ke extra"), Contains("usage"));

  // region keyword: particles whose centre lies in x < 4 (ids 1 and 2), within the group
  s.cmds({"region low block 0 4 0 10 0 10", "compute kel all ke region low",
          "compute rotl all erotate/sphere region low", "compute ke2l two ke region low"});
  double kel = 0, rotl = 0;
  for (std::size_t k = 0; k < 2; ++k) {
    const auto& p = kParticles[k];
    const double m = mass(p), r = 0.5 * p.d;
    kel += 0.5 * m * v2(p);
    rotl += 0.5 * 0.4 * m * r * r * w2(p);
  }
  CHECK(s.value("kel") == Approx(kel).epsilon(1e-12));
  CHECK(s.value("rotl") == Approx(rotl).epsilon(1e-12));
  CHECK(s.value("ke2l") == Approx(0.5 * mass(kParticles[1]) * v2(kParticles[1])).epsilon(1e-12));
  CHECK_THROWS_WITH(s.cmd("compute bad all ke region nowhere"), Contains("nowhere"));
  CHECK_THROWS_WITH(s.cmd("compute bad all erotate/sphere regio low"), Contains("usage"));
}

TEST_CASE("compute reduce sum, min, max, ave and friends", "[compute]") {
  Sim s;
  setup(s);
  s.cmds({"compute sum all reduce sum vx mass x", "compute mn all reduce min x vy radius",
          "compute mx all reduce max y vx omegaz", "compute av all reduce ave z vx",
          "compute sq all reduce sumsq vy", "compute aq all reduce avesq vx",
          "compute sa all reduce sumabs vz", "compute aa all reduce aveabs vy",
          "compute one two reduce sum vy"});
  double msum = 0;
  for (const auto& p : kParticles)
    msum += mass(p);
  CHECK(s.value("sum", 1) == Approx(3.0));
  CHECK(s.value("sum", 2) == Approx(msum).epsilon(1e-12));
  CHECK(s.value("sum", 3) == Approx(16.0));
  CHECK(s.value("mn", 1) == Approx(1.0));
  CHECK(s.value("mn", 2) == Approx(-2.0));
  CHECK(s.value("mn", 3) == Approx(0.1));
  CHECK(s.value("mx", 1) == Approx(5.0));
  CHECK(s.value("mx", 2) == Approx(3.0));
  CHECK(s.value("mx", 3) == Approx(10.0));
  CHECK(s.value("av", 1) == Approx(3.0));
  CHECK(s.value("av", 2) == Approx(0.75));
  CHECK(s.value("sq") == Approx(4 + 16 + 1));
  CHECK(s.value("aq") == Approx((1 + 9 + 1) / 4.0));
  CHECK(s.value("sa") == Approx(1.0));
  CHECK(s.value("aa") == Approx((2 + 4 + 1) / 4.0));
  CHECK(s.value("one") == Approx(-3.0));  // group two: ids 2 and 4
  auto* sum = s.e.modify->find_compute("sum");
  CHECK(sum->size_vector == 3);
  CHECK_FALSE(sum->scalar_flag);
  CHECK(sum->extensive);
  CHECK_FALSE(s.e.modify->find_compute("av")->extensive);
  CHECK(s.e.modify->find_compute("sq")->scalar_flag);
}

TEST_CASE("compute reduce over computes, variables and with replace", "[compute]") {
  Sim s;
  setup(s);
  s.cmds({"compute pa all property/atom id mass vx", "compute pv all property/atom vy",
          "variable e atom 0.5*mass*(vx*vx+vy*vy+vz*vz)", "compute r all reduce sum c_pa[2] c_pv v_e",
          "compute all3 all reduce max c_pa[*]", "compute who all reduce max vx id replace 2 1",
          "compute low all reduce min vy x replace 2 1", "compute ke all ke"});
  double msum = 0;
  for (const auto& p : kParticles)
    msum += mass(p);
  CHECK(s.value("r", 1) == Approx(msum).epsilon(1e-12));
  CHECK(s.value("r", 2) == Approx(1.0));
  CHECK(s.value("r", 3) == Approx(s.value("ke")).epsilon(1e-12));
  CHECK(s.e.modify->find_compute("all3")->size_vector == 3);
  CHECK(s.value("all3", 1) == Approx(4.0));
  CHECK(s.value("all3", 3) == Approx(3.0));
  CHECK(s.value("who", 1) == Approx(3.0));
  CHECK(s.value("who", 2) == Approx(3.0));  // particle 3 has the largest vx
  CHECK(s.value("low", 2) == Approx(2.0));  // particle 2 has the smallest vy, at x = 2

  CHECK_THROWS_WITH(s.cmd("compute b1 all reduce mean vx"), Contains("ave"));
  CHECK_THROWS_WITH(s.cmd("compute b2 all reduce sum velx"), Contains("velx"));
  CHECK_THROWS_WITH(s.cmd("compute b3 all reduce sum c_ke"), Contains("per-atom"));
  CHECK_THROWS_WITH(s.cmd("compute b4 all reduce sum c_pa"), Contains("c_pa[i]"));
  CHECK_THROWS_WITH(s.cmd("compute b5 all reduce sum c_pa[4]"), Contains("3 per-atom columns"));
  CHECK_THROWS_WITH(s.cmd("compute b6 all reduce sum c_nope"), Contains("nope"));
  CHECK_THROWS_WITH(s.cmd("compute b7 all reduce sum v_nope"), Contains("nope"));
  CHECK_THROWS_WITH(s.cmd("compute b8 all reduce sum vx vy replace 1 2"), Contains("min or max"));
  CHECK_THROWS_WITH(s.cmd("compute b9 all reduce max vx vy replace 1 3"), Contains("1..2"));
  CHECK_THROWS_WITH(s.cmd("compute b10 all reduce sum"), Contains("input"));
}

TEST_CASE("compute property/atom gives per-atom vectors and arrays", "[compute]") {
  Sim s;
  setup(s);
  s.cmds(
      {"compute pa two property/atom id type diameter x vy omegaz", "compute one all property/atom density"});
  auto* pa = s.e.modify->find_compute("pa");
  CHECK(pa->peratom_flag);
  CHECK(pa->peratom_cols == 6);
  CHECK(s.e.modify->find_compute("one")->peratom_cols == 0);
  std::vector<double> id, type, diam, x, vy, wz, rho;
  s.e.compute_peratom("pa", 1, id);
  s.e.compute_peratom("pa", 2, type);
  s.e.compute_peratom("pa", 3, diam);
  s.e.compute_peratom("pa", 4, x);
  s.e.compute_peratom("pa", 5, vy);
  s.e.compute_peratom("pa", 6, wz);
  s.e.compute_peratom("one", 0, rho);
  const auto& p = *s.e.particles;
  for (int i = 0; i < p.nlocal; ++i) {
    const auto& ref = kParticles[p.id[i] - 1];
    CHECK(rho[i] == ref.rho);
    if (p.id[i] == 2 || p.id[i] == 4) {
      CHECK(id[i] == p.id[i]);
      CHECK(type[i] == (p.id[i] == 4 ? 2 : 1));
      CHECK(diam[i] == Approx(ref.d));
      CHECK(x[i] == ref.x[0]);
      CHECK(vy[i] == ref.v[1]);
      CHECK(wz[i] == ref.w[2]);
    } else {  // outside the group
      CHECK(id[i] == 0.0);
      CHECK(diam[i] == 0.0);
    }
  }
  CHECK_THROWS_WITH(s.cmd("compute bad all property/atom radiuss"), Contains("radius"));
  CHECK_THROWS_AS(s.cmd("compute bad all property/atom"), InputError);
}

// One table of per-particle properties (core/atom_properties.h) behind
// compute property/atom, atom-style variables and dump custom: each name gives
// the same values through all three, the scaled and unwrapped positions and
// the image flags included.
TEST_CASE("per-atom property names mean the same in property/atom, variables and dumps", "[compute]") {
  Sim s;
  setup(s);
  s.cmds({"set atom 3 image 1 -2 0", "compute pa all property/atom xs xu ix iy body vz",
          "variable xs atom xs", "variable xu atom xu", "variable ix atom ix", "variable iy atom iy",
          "variable b atom body", "variable vz atom vz"});
  const char* names[] = {"xs", "xu", "ix", "iy", "b", "vz"};
  const auto& p = *s.e.particles;
  for (int c = 0; c < 6; ++c) {
    std::vector<double> from_compute, from_variable;
    s.e.compute_peratom("pa", c + 1, from_compute);
    s.e.input->variables().compute_atom(names[c], from_variable);
    INFO("property " << names[c]);
    REQUIRE(from_variable.size() == static_cast<std::size_t>(p.nlocal));
    for (int i = 0; i < p.nlocal; ++i)
      CHECK(from_compute[i] == from_variable[i]);
  }
  std::vector<double> xs, xu, ix, iy, body;
  s.e.compute_peratom("pa", 1, xs);
  s.e.compute_peratom("pa", 2, xu);
  s.e.compute_peratom("pa", 3, ix);
  s.e.compute_peratom("pa", 4, iy);
  s.e.compute_peratom("pa", 5, body);
  for (int i = 0; i < p.nlocal; ++i) {
    const auto& ref = kParticles[p.id[i] - 1];
    CHECK(xs[i] == Approx(ref.x[0] / 10.0));  // box 0..10
    CHECK(body[i] == -1.0);
    const bool moved = p.id[i] == 3;
    CHECK(ix[i] == (moved ? 1.0 : 0.0));
    CHECK(iy[i] == (moved ? -2.0 : 0.0));
    CHECK(xu[i] == Approx(ref.x[0] + (moved ? 10.0 : 0.0)));
  }
  // the dump writes the same numbers (x unwrapped of particle 3)
  const std::string file = "atom_properties_" + std::to_string(::getpid()) + ".txt";
  s.cmd("write_dump all custom " + file + " id xu ix modify sort id precision 17");
  std::ifstream in(file);
  std::string line, last;
  while (std::getline(in, line))
    if (line.rfind("3 ", 0) == 0) last = line;
  std::remove(file.c_str());
  CHECK(last == "3 15 1");
  CHECK_THROWS_WITH(s.cmd("compute bad all property/atom xuu"), Contains("xu"));
}

TEST_CASE("compute count/region and reduce/region", "[compute]") {
  Sim s;
  setup(s);
  s.cmds({"region left block 0 4.5 0 10 0 10", "region ball sphere 5 5 5 1",
          "compute n all count/region left", "compute n2 two count/region left",
          "compute nb all count/region ball", "compute rr all reduce/region left sum vy mass",
          "compute rm all reduce/region left max x"});
  CHECK(s.value("n") == 2.0);
  CHECK(s.value("n2") == 1.0);
  CHECK(s.value("nb") == 1.0);
  CHECK(s.value("rr", 1) == Approx(-2.0));
  CHECK(s.value("rr", 2) == Approx(mass(kParticles[0]) + mass(kParticles[1])).epsilon(1e-12));
  CHECK(s.value("rm") == Approx(2.0));
  CHECK(s.e.modify->find_compute("n")->extensive);
  CHECK_THROWS_WITH(s.cmd("compute bad all count/region nowhere"), Contains("nowhere"));
  CHECK_THROWS_WITH(s.cmd("compute bad all count/region"), Contains("usage"));
  CHECK_THROWS_WITH(s.cmd("compute bad all reduce/region nowhere sum vx"), Contains("nowhere"));
}

TEST_CASE("compute erotate of free spheres: LIGGGHTS 3.8's value", "[compute]") {
  // Two spheres (d = 4 mm, 2500 kg/m3, w = (10, -20, 5); d = 6 mm, 1000 kg/m3,
  // w = (0, 3, 40) rad/s): LIGGGHTS 3.8 prints 3.627383408799691e-07 J for
  // both erotate and erotate/sphere (%22.16g, run 0); the same to 1e-14.
  Sim s;
  s.cmds({"units si",
          "atom_style granular",
          "boundary f f f",
          "region box block -0.05 0.05 -0.05 0.05 -0.05 0.05 units box",
          "create_box 2 box",
          "neighbor 0.001 bin",
          granary::test::materials(2, 5e6, 0.45, 0.9, 0.5),
          "pair_style gran model hertz tangential history",
          "pair_coeff * *",
          "timestep 1e-5",
          "create_atoms 1 single 0.0 0.0 0.0 units box",
          "create_atoms 2 single 0.02 0.0 0.0 units box",
          "set atom 1 diameter 0.004 density 2500",
          "set atom 2 diameter 0.006 density 1000",
          "set atom 1 omegax 10 omegay -20 omegaz 5",
          "set atom 2 omegax 0 omegay 3 omegaz 40",
          "fix integr all nve/sphere",
          "compute er all erotate",
          "compute ers all erotate/sphere",
          "run 0"});
  CHECK(s.value("er") == Approx(3.627383408799691e-07).epsilon(1e-14));
  CHECK(s.value("ers") == Approx(3.627383408799691e-07).epsilon(1e-14));
  CHECK_THROWS_WITH(s.cmd("compute bad all erotate region box"), Catch::Matchers::Contains("usage"));
}
