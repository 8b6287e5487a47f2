// fix multicontact/halfspace with "surface multicontact" (pair_style gran and
// fix wall/gran):
//  * two soft spheres stacked on a floor settle where the model's closed form
//    puts them: the lower sphere's radius grows at each contact by the
//    Boussinesq shift s = gamma (1 + nu)(3 - 2 nu) F / (2 pi Y d) that its
//    other contact (at distance d, on the same line) causes, and each
//    contact's overlap is the Hertz overlap of its load for the new radii
//    minus s; without the model the overlaps are the plain Hertz ones;
//  * a small compressed bed of soft spheres ends at the same positions on 1, 2
//    and 4 ranks (the contact records reach the ghosts), and through a restart
//    file (the records are written with the particles);
//  * errors: the fix missing, newton on, a second fix, a bad prefactor, the
//    local contact computes (they would recompute forces without the model).
// Run by ctest at 1, 2 and 4 ranks (processors 1 1 *: the stack's contact
// and many of the bed's cross the ranks' boundaries).
#include <mpi.h>

#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/error.h"
#include "particles/particles.h"
#include "script_engine.h"

using Catch::Matchers::Contains;
using granary::Vec3;

namespace {

constexpr double kR = 0.01, kRho = 1000.0, kY = 23.3e3, kYwall = 5e7, kNu = 0.5, kGamma = 1.125, kG = 9.81;

std::vector<std::string> head(const std::string& surface, const std::string& zhi) {
  const std::string model = "model hertz tangential history" + surface;
  std::vector<std::string> s = granary::test::liggghts_head("-0.03 0.03 -0.03 0.03 0.0 " + zhi, 2);
  s.insert(s.end() - 2, "processors 1 1 *");  // before the box
  s.insert(s.end(), {"neighbor 0.002 bin", "neigh_modify delay 0",
                     "fix m1 all property/global youngsModulus peratomtype 23.3e3 5e7",
                     "fix m2 all property/global poissonsRatio peratomtype 0.5 0.5",
                     "fix m3 all property/global coefficientRestitution peratomtypepair 2 0.5 0.5 0.5 0.5",
                     "fix m4 all property/global coefficientFriction peratomtypepair 2 0.3 0.3 0.3 0.3",
                     "pair_style gran " + model, "pair_coeff * *",
                     "fix floor all wall/gran " + model + " primitive type 2 zplane 0.0",
                     "fix grav all gravity 9.81 vector 0 0 -1"});
  return s;
}

// The settled stack in closed form: floor contact (sphere-wall, R* = r) and
// sphere-sphere contact (R* = r/2) with the Hertz overlaps of their loads
// 2 m g and m g, each reduced by the shift of the other contact; d, the
// distance between the lower sphere's contact points, follows from them.
struct StackOverlaps {
  double floor, pair;
};
StackOverlaps stack_closed_form(bool multicontact) {
  const double m = 4.0 / 3.0 * M_PI * kR * kR * kR * kRho;
  const double Fp = m * kG, Ff = 2.0 * m * kG;
  const double Y_wall = 1.0 / ((1.0 - kNu * kNu) / kY + (1.0 - kNu * kNu) / kYwall);
  const double Y_pair = 1.0 / (2.0 * (1.0 - kNu * kNu) / kY);
  // F = 4/3 Y* sqrt(R*) delta^(3/2)
  auto hertz = [](double F, double Ystar, double Rstar) {
    return std::pow(3.0 * F / (4.0 * Ystar * std::sqrt(Rstar)), 2.0 / 3.0);
  };
  StackOverlaps o{hertz(Ff, Y_wall, kR), hertz(Fp, Y_pair, 0.5 * kR)};
  if (!multicontact) return o;
  // the lower sphere's radius grows by s_f at the floor contact (caused by the
  // upper contact's force) and by s_p at the upper contact (caused by the
  // floor's); the upper sphere's has no other contact: R* = r + s_f at the
  // floor, (r + s_p) r / (2 r + s_p) between the spheres
  for (int it = 0; it < 100; ++it) {
    const double d = 2.0 * kR - 0.5 * (o.floor + o.pair);
    const double c = kGamma * (1.0 + kNu) * (3.0 - 2.0 * kNu) / (2.0 * M_PI * kY * d);
    const double s_f = c * Fp, s_p = c * Ff;
    o.floor = hertz(Ff, Y_wall, kR + s_f) - s_f;
    o.pair = hertz(Fp, Y_pair, (kR + s_p) * kR / (2.0 * kR + s_p)) - s_p;
  }
  return o;
}

StackOverlaps settle_stack(MPI_Comm comm, bool multicontact) {
  granary::test::ScriptEngine s(comm);
  // slabs 0.0225 m high (above the ghost cutoff 0.022 m): on 2 and more ranks
  // the two spheres lie on ranks 0 and 1
  int nprocs = 1;
  MPI_Comm_size(comm, &nprocs);
  s.cmds(head(multicontact ? " surface multicontact" : "", std::to_string(0.0225 * std::max(2, nprocs))));
  if (multicontact) s.cmd("fix mc all multicontact/halfspace");  // default prefactor 1.125
  s.cmds({"create_atoms 1 single 0 0 0.0100 units box", "create_atoms 1 single 0 0 0.0302 units box",
          "set group all diameter 0.02 density 1000", "fix damp all viscous 0.5", "fix integr all nve/sphere",
          "timestep 5e-5", "run 8000"});
  const auto x = granary::test::positions_by_id(s.e, 2);
  return {kR - x.at(1)[2], 2.0 * kR - (x.at(2)[2] - x.at(1)[2])};
}

/// A 3 x 3 x 4 block of soft spheres (0.5 % overlaps, offsets that break the
/// lattice's symmetry) on the floor, pressed by a lid wall at z = 0.0785
/// (1.3 mm into the top layer).
std::vector<std::string> bed_script(bool multicontact) {
  std::vector<std::string> s = head(multicontact ? " surface multicontact" : "", "0.09");
  const std::string model =
      std::string("model hertz tangential history") + (multicontact ? " surface multicontact" : "");
  s.push_back("fix lid all wall/gran " + model + " primitive type 2 zplane 0.0785");
  if (multicontact) s.push_back("fix mc all multicontact/halfspace geometric_prefactor 1.5");
  int id = 0;
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) {
        ++id;
        const double dx = 0.0004 * std::sin(1.7 * id), dy = 0.0004 * std::cos(2.3 * id);
        char line[160];
        std::snprintf(line, sizeof line, "create_atoms 1 single %.6f %.6f %.6f units box",
                      (i - 1) * 0.0199 + dx, (j - 1) * 0.0199 + dy, 0.0101 + k * 0.0199);
        s.push_back(line);
      }
  s.push_back("set group all diameter 0.02 density 1000");
  s.push_back("fix integr all nve/sphere");
  s.push_back("timestep 2e-5");
  return s;
}

std::map<long long, Vec3> run_bed(MPI_Comm comm, bool multicontact, const std::vector<int>& runs) {
  granary::test::ScriptEngine s(comm);
  s.cmds(bed_script(multicontact));
  for (int n : runs)
    s.cmd("run " + std::to_string(n));
  return granary::test::positions_by_id(s.e, 36);
}

}  // namespace

TEST_CASE("multicontact: a settled stack of two soft spheres matches the closed form",
          "[multicontact][mpi]") {
  const StackOverlaps mc = settle_stack(MPI_COMM_WORLD, true);
  const StackOverlaps mc_exact = stack_closed_form(true);
  const StackOverlaps plain = settle_stack(MPI_COMM_WORLD, false);
  const StackOverlaps plain_exact = stack_closed_form(false);
  INFO("multicontact: floor " << mc.floor << " (closed form " << mc_exact.floor << "), pair " << mc.pair
                              << " (" << mc_exact.pair << "); Hertz: floor " << plain.floor << " ("
                              << plain_exact.floor << "), pair " << plain.pair << " (" << plain_exact.pair
                              << ")");
  // settled to well below the shift (7 and 11 % of the overlaps)
  CHECK(mc.floor == Approx(mc_exact.floor).epsilon(1e-4));
  CHECK(mc.pair == Approx(mc_exact.pair).epsilon(1e-4));
  CHECK(plain.floor == Approx(plain_exact.floor).epsilon(1e-4));
  CHECK(plain.pair == Approx(plain_exact.pair).epsilon(1e-4));
  CHECK(mc.pair < 0.95 * plain.pair);
  CHECK(mc.floor < 0.95 * plain.floor);
}

TEST_CASE("multicontact: a compressed bed is the same on any number of ranks and through a restart file",
          "[multicontact][mpi]") {
  const auto self = run_bed(MPI_COMM_SELF, true, {3000});
  const auto world = run_bed(MPI_COMM_WORLD, true, {3000});
  const auto plain = run_bed(MPI_COMM_SELF, false, {3000});
  const double d_world = granary::test::max_position_difference(self, world);
  const double d_plain = granary::test::max_position_difference(self, plain);
  INFO("largest difference of a position: " << d_world << " m (ranks), " << d_plain
                                            << " m (without the model)");
  // round-off of the sums' order only (a dense bed; doc/architecture.md, Determinism)
  CHECK(d_world < 1e-9);
  CHECK(d_plain > 1e-5);  // the model moves the particles

  // a restart file written at step 1000, read into a fresh engine, run 2000 more
  const std::string file = "multicontact_test.restart";
  {
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    s.cmds(bed_script(true));
    s.cmds({"run 1000", "write_restart " + file});
  }
  granary::test::ScriptEngine r(MPI_COMM_WORLD);
  std::vector<std::string> script = bed_script(true);
  std::vector<std::string> cont = {
      "atom_style granular", "atom_modify map array", "newton off",         "communicate single vel yes",
      "processors 1 1 *",    "read_restart " + file,  "neighbor 0.002 bin", "neigh_modify delay 0"};
  for (const auto& line : script)
    if (line.rfind("fix ", 0) == 0 || line.rfind("pair_", 0) == 0 || line.rfind("timestep", 0) == 0)
      cont.push_back(line);
  r.cmds(cont);
  r.cmd("run 2000");
  const double d_restart =
      granary::test::max_position_difference(self, granary::test::positions_by_id(r.e, 36));
  INFO("through the restart file: " << d_restart << " m");
  CHECK(d_restart < 1e-9);
  if (granary::test::world_rank() == 0) std::remove(file.c_str());
}

TEST_CASE("multicontact: errors", "[multicontact][mpi][errors]") {
  auto failing = [](const std::vector<std::string>& extra) {
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    s.cmds(head(" surface multicontact", "0.09"));
    s.cmds({"create_atoms 1 single 0 0 0.0100 units box", "set group all diameter 0.02 density 1000",
            "fix integr all nve/sphere", "timestep 5e-5"});
    s.cmds(extra);
  };
  CHECK_THROWS_WITH(failing({"run 1"}), Contains("needs fix multicontact/halfspace"));
  CHECK_THROWS_WITH(failing({"fix mc all multicontact/halfspace", "newton on", "run 1"}),
                    Contains("needs 'newton off'"));
  CHECK_THROWS_WITH(failing({"fix mc all multicontact/halfspace", "fix mc2 all multicontact/halfspace"}),
                    Contains("there is already one"));
  CHECK_THROWS_WITH(failing({"fix mc all multicontact/halfspace geometric_prefactor -1"}),
                    Contains("geometric_prefactor must be > 0"));
  CHECK_THROWS_WITH(failing({"fix mc all multicontact/halfspace gamma 1"}),
                    Contains("unknown keyword 'gamma'"));
  // the local contact computes would report forces without the radius changes
  const std::string local = "multicontact_test_local.txt";
  for (const std::string compute : {"pair/gran/local", "wall/gran/local"})
    CHECK_THROWS_WITH(failing({"fix mc all multicontact/halfspace", "compute c all " + compute + " pos force",
                               "dump d all local 1 " + local + " c_c[1]", "run 1"}),
                      Contains("not supported with fix multicontact/halfspace"));
  if (granary::test::world_rank() == 0) std::remove(local.c_str());
}
