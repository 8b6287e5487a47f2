// fix heat/gran and fix property/atom: the temperatures LIGGGHTS 3.8 gives
// for four spheres in contact (three contact-area modes, a particle outside
// the group, a heat source), on any number of ranks with newton on and off;
// two spheres against the exact solution of the explicit Euler steps, with
// the thermal energy conserved; temperatures and heat sources through a
// restart file; property/atom defaults for new particles, set, and errors.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/error.h"
#include "core/modify.h"
#include "fix/fix.h"
#include "particles/particles.h"
#include "script_engine.h"

using Catch::Matchers::Contains;

namespace {

int nprocs() {
  int n = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &n);
  return n;
}

/// Per-atom values of f_ID by particle id (1..n), gathered from every rank.
std::vector<double> by_id(granary::Engine& e, const std::string& fix, int n) {
  std::vector<double> values;
  e.fix_peratom(fix, 0, values);
  const auto& p = *e.particles;
  std::vector<double> local(2 * n, 0.0), all(2 * n);
  for (int i = 0; i < p.nlocal; ++i) {
    const auto k = static_cast<std::size_t>(p.id[i] - 1);
    local[2 * k] = values[i];
    local[2 * k + 1] += 1.0;
  }
  MPI_Allreduce(local.data(), all.data(), 2 * n, MPI_DOUBLE, MPI_SUM, e.world);
  std::vector<double> out(n);
  for (int k = 0; k < n; ++k) {
    REQUIRE(all[2 * k + 1] == 1.0);  // owned by exactly one rank
    out[k] = all[2 * k];
  }
  return out;
}

/// The scene of the LIGGGHTS 3.8 reference runs (script in the test below).
std::vector<std::string> four_spheres(const std::string& newton, const std::string& fix) {
  return {"atom_style granular",
          "atom_modify map array",
          "boundary f f f",
          "newton " + newton,
          "units si",
          "region reg block -0.05 0.05 -0.05 0.05 -0.05 0.05 units box",
          "create_box 2 reg",
          "neighbor 0.002 bin",
          "neigh_modify delay 0",
          "fix m1 all property/global youngsModulus peratomtype 5.e6 5.e6",
          "fix m2 all property/global poissonsRatio peratomtype 0.45 0.3",
          "fix m3 all property/global coefficientRestitution peratomtypepair 2 0.7 0.7 0.7 0.7",
          "fix m4 all property/global coefficientFriction peratomtypepair 2 0.05 0.05 0.05 0.05",
          "fix m5 all property/global youngsModulusOriginal peratomtype 5.e9 7.e10",
          "pair_style gran model hertz tangential history",
          "pair_coeff * *",
          "timestep 0.00001",
          "create_atoms 1 single 0 0 0 units box",
          "create_atoms 2 single 0.0075 0.001 0 units box",
          "create_atoms 1 single -0.0078 0 0.0 units box",
          "create_atoms 2 single -0.0078 0 0.0075 units box",
          "set atom 1 diameter 0.008 density 8000",
          "set atom 2 diameter 0.008 density 2500",
          "set atom 3 diameter 0.008 density 8000",
          "set atom 4 diameter 0.0072 density 2500",
          "group hot id 1 2 3",
          "fix ftco all property/global thermalConductivity peratomtype 100. 20.",
          "fix ftca all property/global thermalCapacity peratomtype 10. 30.",
          fix,
          "run 0",
          "set atom 2 property/atom Temp 800.",
          "set atom 4 property/atom Temp 1000.",
          "set atom 3 property/atom heatSource 0.5",
          "run 100"};
}

}  // namespace

TEST_CASE("fix heat/gran: four spheres as LIGGGHTS 3.8 gives them, on any number of ranks",
          "[heat_gran][mpi]") {
  // LIGGGHTS 3.8 (Debian liggghts 3.8.0) on one rank, the script of
  // four_spheres() with newton off, communicate single vel yes and
  //   thermo_style custom step atoms f_heattransfer
  //   dump d all custom 100 post/X.txt id f_Temp[0] f_heatFlux[0]
  //   dump_modify d format "%d %.15g %.15g" sort id
  // Temp of particles 1..4 and f_heattransfer at step 100. Particle 4 is
  // outside the group (keeps its temperature); particle 3 has a heat source.
  struct Reference {
    const char* fix;
    double temp[4];
    double energy0, energy100;
  };
  const Reference refs[] = {
      {"fix heattransfer hot heat/gran initial_temperature 300.",
       {303.544115989797, 796.210586303548, 302.394033015759, 1000},
       43.6103325800721,
       43.6614950381907},
      {"fix heattransfer hot heat/gran initial_temperature 300. contact_area projection",
       {310.914151090059, 788.508226294354, 315.143431067864, 1000},
       43.6103325800721,
       43.9381234541357},
      {"fix heattransfer hot heat/gran/conduction initial_temperature 300. area_correction yes",
       {300.288694164661, 799.691999952602, 300.212417115815, 1000},
       43.6103325800721,
       43.6148870077989},
  };
  for (const auto& ref : refs) {
    for (const char* newton : {"off", "on"}) {
      INFO(ref.fix << ", newton " << newton << ", " << nprocs() << " rank(s)");
      granary::test::ScriptEngine s(MPI_COMM_WORLD);
      s.cmds(four_spheres(newton, ref.fix));
      const std::vector<double> temp = by_id(s.e, "Temp", 4);
      for (int k = 0; k < 4; ++k) {
        INFO("particle " << k + 1);
        CHECK(temp[k] == Approx(ref.temp[k]).epsilon(1e-12));
      }
      // LIGGGHTS 3.8 sums m c T over every particle, also those outside the group
      granary::Fix* f = s.e.modify->find_fix("heattransfer");
      REQUIRE(f != nullptr);
      CHECK(f->compute_scalar() == Approx(ref.energy100).epsilon(1e-12));
      // the energy gained is the heat source's work plus what particle 4 (fixed
      // at 1000 K) gave: the flows between the group's particles cancel
      CHECK(ref.energy100 - ref.energy0 > 0.0);
    }
  }
}

TEST_CASE("fix heat/gran: two spheres relax as the exact solution of the Euler steps, energy conserved",
          "[heat_gran][mpi]") {
  // spheres of radius 4 mm 7.6 mm apart, one each side of x = 0 (on two
  // ranks they are owned by two ranks); no time integration: they stay put
  for (const char* newton : {"off", "on"}) {
    INFO("newton " << newton << ", " << nprocs() << " rank(s)");
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    s.cmds({"units si",
            "atom_style granular",
            "boundary f f f",
            std::string("newton ") + newton,
            "region reg block -0.02 0.02 -0.02 0.02 -0.02 0.02",
            "create_box 2 reg",
            "fix m1 all property/global youngsModulus peratomtype 5.e6 5.e6",
            "fix m2 all property/global poissonsRatio peratomtype 0.3 0.3",
            "fix m3 all property/global coefficientRestitution peratomtypepair 2 0.7 0.7 0.7 0.7",
            "fix m4 all property/global coefficientFriction peratomtypepair 2 0.5 0.5 0.5 0.5",
            "pair_style gran model hertz tangential history",
            "pair_coeff * *",
            "timestep 5e-5",
            "create_atoms 1 single -0.0038 0 0",
            "create_atoms 2 single 0.0038 0 0",
            "set atom 1 diameter 0.008 density 8000",
            "set atom 2 diameter 0.008 density 2000",
            "fix k all property/global thermalConductivity peratomtype 5e4 2e3",
            "fix c all property/global thermalCapacity peratomtype 500. 800.",
            "fix heat all heat/gran initial_temperature 293.15",
            "set atom 1 property/atom Temp 400",
            "run 1000"});
    const std::vector<double> temp = by_id(s.e, "Temp", 2);
    const double pi = 3.14159265358979323846;
    const double r = 0.004, a2 = r * r - 0.0038 * 0.0038;  // contact circle radius^2
    const double h = 4.0 * 5e4 * 2e3 / 5.2e4 * std::sqrt(pi * a2);
    const double c1 = 4.0 / 3.0 * pi * r * r * r * 8000 * 500, c2 = 4.0 / 3.0 * pi * r * r * r * 2000 * 800;
    const double factor = std::pow(1.0 - h * 5e-5 * (1.0 / c1 + 1.0 / c2), 1000);
    const double dt0 = 400.0 - 293.15;
    CHECK(temp[0] - temp[1] == Approx(dt0 * factor).epsilon(1e-9));
    CHECK(factor < 0.2);  // the difference relaxed noticeably
    CHECK(c1 * temp[0] + c2 * temp[1] == Approx(c1 * 400.0 + c2 * 293.15).epsilon(1e-13));
    CHECK(s.e.modify->find_fix("heat")->compute_scalar() == Approx(c1 * 400.0 + c2 * 293.15).epsilon(1e-13));
  }
}

TEST_CASE("fix heat/gran: temperatures and heat sources go through a restart file; new particles start at T0",
          "[heat_gran][mpi]") {
  const std::string file = "heat_gran_" + std::to_string(nprocs()) + ".restart";
  const std::vector<std::string> head = {
      "fix m1 all property/global youngsModulus peratomtype 5.e6",
      "fix m2 all property/global poissonsRatio peratomtype 0.3",
      "fix m3 all property/global coefficientRestitution peratomtypepair 1 0.7",
      "fix m4 all property/global coefficientFriction peratomtypepair 1 0.5",
      "pair_style gran model hertz tangential history",
      "pair_coeff * *",
      "timestep 1e-4",
      "fix k all property/global thermalConductivity peratomtype 50.",
      "fix c all property/global thermalCapacity peratomtype 500."};
  std::vector<double> before;
  {
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    s.cmds({"units si", "atom_style granular", "boundary f f f",
            "region reg block -0.02 0.02 -0.02 0.02 -0.02 0.02", "create_box 1 reg"});
    s.cmds(head);
    s.cmds({"create_atoms 1 single -0.0038 0 0", "create_atoms 1 single 0.0038 0 0",
            "set group all diameter 0.008 density 8000", "fix heat all heat/gran initial_temperature 300",
            "set atom 1 property/atom Temp 400", "set atom 2 property/atom heatSource 2.5", "run 200",
            "write_restart " + file});
    before = by_id(s.e, "Temp", 2);
    CHECK(before[0] < 400.0);
    CHECK(before[1] > 300.0);
  }
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds({"read_restart " + file});
  s.cmds(head);
  s.cmds({"fix heat all heat/gran initial_temperature 250", "run 0"});
  CHECK(by_id(s.e, "Temp", 2) == before);
  CHECK(by_id(s.e, "heatSource", 2) == std::vector<double>{0.0, 2.5});
  // a particle created after the fix starts at the fix's T0, far from the others
  s.cmds({"create_atoms 1 single 0 0.015 0", "set atom 3 diameter 0.004 density 8000", "run 10"});
  const std::vector<double> after = by_id(s.e, "Temp", 3);
  CHECK(after[2] == 250.0);
  CHECK(after[1] > before[1]);  // the source keeps heating particle 2
  if (s.e.rank == 0) std::remove(file.c_str());
}

TEST_CASE("fix property/atom: defaults for every particle, set, f_ID[0], and errors",
          "[property_atom][mpi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds({"units si", "atom_style granular", "boundary f f f",
          "region reg block -0.02 0.02 -0.02 0.02 -0.02 0.02", "create_box 1 reg",
          "create_atoms 1 single -0.01 0 0", "create_atoms 1 single 0.01 0 0",
          "fix tag all property/atom tag scalar yes no no 1.5",
          "fix uf all property/atom uf vector yes no no 0 1 2", "create_atoms 1 single 0 0.01 0",
          "set atom 2 property/atom tag 7", "set atom 3 property/peratom uf 3 4 5"});
  CHECK(by_id(s.e, "tag", 3) == std::vector<double>{1.5, 7.0, 1.5});
  std::vector<double> col;
  s.e.fix_peratom("uf", 2, col);  // the second column, 1-based
  double local = 0.0, sum = 0.0;
  for (double v : col)
    local += v;
  MPI_Allreduce(&local, &sum, 1, MPI_DOUBLE, MPI_SUM, s.e.world);
  CHECK(sum == 1.0 + 1.0 + 4.0);
  // f_ID[0] (the vector) in compute reduce and in atom-style variables
  s.cmds({"set atom * diameter 0.002 density 2500", "variable t2 atom 2*f_tag[0]",
          "compute red all reduce sum f_tag[0] v_t2 f_uf[3]", "run 0"});
  CHECK(s.e.compute_value("red", 1) == 1.5 + 7.0 + 1.5);
  CHECK(s.e.compute_value("red", 2) == 2 * (1.5 + 7.0 + 1.5));
  CHECK(s.e.compute_value("red", 3) == 2.0 + 2.0 + 5.0);
  s.cmd("uncompute red");
  // particles inserted by an insertion fix start with the defaults too, or
  // with the value of set_property
  s.cmds(
      {"set atom * diameter 0.002 density 2500",
       "fix pts all particletemplate/sphere 15485863 atom_type 1 density constant 2500 radius constant 0.001",
       "fix pdd all particledistribution/discrete 15485867 1 pts 1.0",
       "region ins block -0.015 0.015 -0.015 0.015 -0.015 -0.005",
       "fix ins all insert/pack seed 32452843 distributiontemplate pdd insert_every once overlapcheck yes "
       "all_in yes particles_in_region 20 region ins set_property tag 9",
       "run 1"});
  const std::vector<double> tags = by_id(s.e, "tag", 23);
  CHECK(tags[1] == 7.0);
  for (int k = 3; k < 23; ++k)
    CHECK(tags[k] == 9.0);
  std::vector<double> uf2;
  s.e.fix_peratom("uf", 2, uf2);
  for (double v : uf2)
    CHECK((v == 1.0 || v == 4.0));  // the default (1) and the one set (4)
  s.cmds({"unfix ins",
          "fix ins2 all insert/pack seed 32452843 distributiontemplate pdd insert_every once "
          "particles_in_region 30 region ins set_property uf 1"});
  CHECK_THROWS_WITH(s.cmd("run 1"), Contains("set_property uf names no scalar per-particle property"));
  s.cmd("unfix ins2");
  CHECK_THROWS_WITH(s.cmd("set atom 1 property/atom nosuch 1"),
                    Contains("no per-particle property 'nosuch'"));
  CHECK_THROWS_WITH(s.cmd("set atom 1 property/atom uf 1 2"), Contains("needs 3 value(s)"));
  CHECK_THROWS_WITH(s.cmd("fix bad all property/atom x2 scalar yes no no 1 2"), Contains("takes one value"));
  CHECK_THROWS_WITH(s.cmd("fix bad all property/atom x2 matrix yes no no 1"), Contains("scalar or vector"));
  CHECK_THROWS_WITH(s.cmd("fix bad all property/atom x2 scalar maybe no no 1"), Contains("yes or no"));
  CHECK_THROWS_WITH(s.cmd("fix tag2 all property/atom tag vector yes no no 1 2"),
                    Contains("values per particle"));
  // heat/gran needs the thermal properties, named in the error
  s.cmds({"fix h all heat/gran initial_temperature 300"});
  CHECK_THROWS_WITH(s.cmd("run 0"), Contains("thermalConductivity"));
  CHECK_THROWS_WITH(s.cmd("fix h2 all heat/gran initial_temperature 300 contact_area sphere"),
                    Contains("overlap, projection or constant"));
  CHECK_THROWS_WITH(s.cmd("fix h3 all heat/gran 300"), Contains("initial_temperature"));
}
