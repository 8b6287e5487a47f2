// fix massflow/mesh/sieve on 1, 2 and 4 ranks (run by ctest at each count):
// spheres of three diameters settle onto a horizontal sieve; the number of
// each size that passes (and is counted and deleted) is binomial with the
// open-area probability pi (S - d)^2 / (4 A^2); the spheres with d >= S all
// rest on the sieve, pressed into it by their weight (overlap m g / K), and
// the sieve carries their weight; the same spheres pass on any number of
// ranks (each rank also runs the scene alone); clumps pass only with
// sieveMultiSphereCanPass; the errors.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/modify.h"
#include "fix/fix.h"
#include "mesh_files.h"
#include "particles/particles.h"
#include "script_engine.h"

using Catch::Matchers::Contains;
using granary::Vec3;

namespace {

namespace fs = std::filesystem;
constexpr double kPi = 3.14159265358979323846;
constexpr double kG = 9.81;

using granary::test::world_rank;
using granary::test::world_size;

// The sieve: the square -70..70 mm in x and y at z = 2.2 mm, two triangles
// whose shared diagonal runs under a row of spheres; written once per rank
// count (ctest may run the counts at once).
constexpr double kSieveZ = 0.0022;
std::string sieve_dir() {
  const std::string dir = "sieve_np" + std::to_string(world_size());
  if (world_rank() == 0) {
    fs::create_directories(dir);
    std::vector<mesh_files::Triangle> sieve;
    mesh_files::add_rectangle(sieve, Vec3(-0.07, -0.07, kSieveZ), Vec3(0.14, 0, 0), Vec3(0, 0.14, 0), 1, 1);
    mesh_files::write_ascii(dir + "/sieve.stl", sieve);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  return dir;
}

// Sieve parameters: holes of S = 3 mm on a square pitch A = 3 mm; spring K
// and dashpot C.
constexpr double kS = 0.003, kA = 0.003, kK = 100.0, kC = 0.2;
double pass_probability(double d) {
  return d < kS ? kPi * (kS - d) * (kS - d) / (4 * kA * kA) : 0.0;
}

// Every sphere has the mass of a 2 mm sphere of density 2500, so that one
// dashpot damps them all alike: C = 0.2 is three times the critical damping
// 2 sqrt(K m) = 0.065, so no sphere bounces off the sieve (each contact has
// a single first step, at which it draws once).
const double kMass = 2500 * 4.0 / 3.0 * kPi * 1e-9;
double density(double d) {
  return kMass / (kPi / 6 * d * d * d);
}

// 1089 spheres on a 4 mm lattice (centres at z = 4 mm) over the sieve: the 11
// columns x < -22 mm of d = 1 mm (type 1), the 11 middle ones of 2 mm (type
// 2), the 11 at x > 22 mm of 3 mm = S (type 3); they fall onto it. Spheres
// that pass are counted and deleted.
std::vector<std::string> sieve_scene(const std::string& dir, const std::string& extra) {
  auto num = [](double v) {
    char b[40];
    std::snprintf(b, sizeof b, "%.17g", v);
    return std::string(b);
  };
  return {"units si",
          "atom_style granular",
          "atom_modify map array",
          "boundary f f f",
          "newton off",
          "communicate single vel yes",
          "region domain block -0.07 0.07 -0.07 0.07 -0.03 0.01 units box",
          "create_box 3 domain",
          "neighbor 0.0005 bin",
          "neigh_modify delay 0",
          granary::test::materials(3, 5.e6, 0.45, 0.5, 0.5),
          "pair_style gran model hertz tangential history",
          "pair_coeff * *",
          "timestep 0.00001",
          "fix gravi all gravity 9.81 vector 0.0 0.0 -1.0",
          "fix sieve all mesh/surface file " + dir + "/sieve.stl type 1",
          "lattice sc 0.004",
          "region r1 block -0.066 -0.022 -0.066 0.066 0.003 0.005 units box",
          "region r2 block -0.022 0.022 -0.066 0.066 0.003 0.005 units box",
          "region r3 block 0.022 0.066 -0.066 0.066 0.003 0.005 units box",
          "create_atoms 1 region r1",
          "create_atoms 2 region r2",
          "create_atoms 3 region r3",
          "set type 1 diameter 0.001 density " + num(density(0.001)),
          "set type 2 diameter 0.002 density " + num(density(0.002)),
          "set type 3 diameter 0.003 density " + num(density(0.003)),
          "fix integr all nve/sphere",
          "fix mf all massflow/mesh/sieve mesh sieve point_at_outlet 0 0 -1 count once delete_atoms yes "
          "sieveSize 0.003 sieveSpacing 0.003 sieveStiffness 100 sieveDamping 0.2" +
              extra};
}

// What is left after the run: id -> (type, z, |v|) of every sphere, on every rank.
struct Left {
  int type;
  double z, speed;
};
std::map<long long, Left> left_over(granary::Engine& e) {
  const auto& p = *e.particles;
  std::vector<double> mine;
  for (int i = 0; i < p.nlocal; ++i)
    mine.insert(mine.end(),
                {static_cast<double>(p.id[i]), static_cast<double>(p.type[i]), p.x[i][2], p.v[i].norm()});
  int n = static_cast<int>(mine.size()), nprocs = 1;
  MPI_Comm_size(e.world, &nprocs);
  std::vector<int> counts(nprocs), displs(nprocs, 0);
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, e.world);
  for (int r = 1; r < nprocs; ++r)
    displs[r] = displs[r - 1] + counts[r - 1];
  std::vector<double> all(displs.back() + counts.back());
  MPI_Allgatherv(mine.data(), n, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE, e.world);
  std::map<long long, Left> out;
  for (std::size_t k = 0; k + 4 <= all.size(); k += 4)
    out[static_cast<long long>(all[k])] = {static_cast<int>(all[k + 1]), all[k + 2], all[k + 3]};
  return out;
}

double fval(granary::Engine& e, const std::string& id, int k) {
  return e.modify->find_fix(id)->compute_vector(k - 1);
}

struct Outcome {
  std::map<long long, Left> left;
  double counted = 0, deleted = 0, mass = 0;
  Vec3 force = Vec3::Zero();
};

Outcome run_sieve(MPI_Comm comm, const std::string& dir, int steps) {
  granary::test::ScriptEngine s(comm);
  s.cmds(sieve_scene(dir, ""));
  REQUIRE(s.e.particles->natoms == 1089);
  s.cmd("run " + std::to_string(steps));
  Outcome o;
  o.left = left_over(s.e);
  o.mass = fval(s.e, "mf", 1);
  o.counted = fval(s.e, "mf", 2);
  o.deleted = fval(s.e, "mf", 6);
  o.force = Vec3(fval(s.e, "mf", 7), fval(s.e, "mf", 8), fval(s.e, "mf", 9));
  return o;
}

}  // namespace

// LIGGGHTS 3.8 with this sieve (1089 spheres of 1 mm, one size per run)
// passes 386 of 1089 (P = 0.349, 380 +- 16 expected) at the first contacts;
// of 2 mm spheres 94 (95 +- 9); with the pitch 4 mm, 219 of the 1 mm spheres
// (214 +- 13): the same open-area probability.
TEST_CASE("fix massflow/mesh/sieve: the open-area fraction passes, the rest rests on the sieve",
          "[massflow][sieve][mpi]") {
  const std::string dir = sieve_dir();
  // the falls take at most 1.8 mm (18 ms), settling on the spring-dashpot
  // (time constant C / K = 2 ms) is complete to 1e-6 by 40 ms
  const int steps = 4000;
  const Outcome ref = run_sieve(MPI_COMM_SELF, dir, steps);
  const Outcome par = run_sieve(MPI_COMM_WORLD, dir, steps);

  // 363 spheres of each size; the passed ones were deleted
  std::map<int, int> created = {{1, 363}, {2, 363}, {3, 363}}, rest;
  for (const auto& [id, l] : par.left)
    ++rest[l.type];
  double passed_total = 0;
  for (int type = 1; type <= 3; ++type) {
    const double d = 0.001 * type;
    const double prob = pass_probability(d);
    const int n = created[type];
    const int passed = n - rest[type];
    passed_total += passed;
    // binomial: within 4 standard deviations of the mean
    const double mean = n * prob, sd = std::sqrt(n * prob * (1 - prob));
    INFO("d = " << d << ": " << passed << " of " << n << " passed, expected " << mean << " +- " << sd);
    CHECK(std::abs(passed - mean) <= 4 * sd);
    if (type == 3) CHECK(passed == 0);  // d = S never passes
  }
  // the passed spheres were counted once each (and deleted)
  CHECK(par.counted == passed_total);
  CHECK(par.deleted == passed_total);
  CHECK(par.mass == Approx(passed_total * kMass).epsilon(1e-12));
  // every sphere left rests on the sieve: the spring carries its weight,
  // overlap m g / K (1.03 um), to 1e-3 of it
  const double overlap = kMass * kG / kK;
  double worst = 0, fastest = 0;
  for (const auto& [id, l] : par.left) {
    const double r = 0.0005 * l.type;
    worst = std::max(worst, std::abs((kSieveZ + r - l.z) / overlap - 1));
    fastest = std::max(fastest, l.speed);
  }
  INFO("largest relative deviation of the overlap from m g / K: " << worst << ", fastest sphere " << fastest
                                                                  << " m/s");
  CHECK(worst < 1e-3);
  CHECK(fastest < 1e-5);
  // the sieve carries the weight of what rests on it
  const double weight = par.left.size() * kMass * kG;
  CHECK(par.force[2] == Approx(-weight).epsilon(1e-6));
  CHECK(std::abs(par.force[0]) < 1e-12 * weight);
  CHECK(std::abs(par.force[1]) < 1e-12 * weight);

  // the same spheres pass when one rank runs the scene alone
  CHECK(ref.counted == par.counted);
  std::set<long long> ref_ids, par_ids;
  for (const auto& [id, l] : ref.left)
    ref_ids.insert(id);
  for (const auto& [id, l] : par.left)
    par_ids.insert(id);
  CHECK(ref_ids == par_ids);
}

// Dumbbells of two 1 mm spheres (each would pass alone with P = 0.349) lie
// on the sieve: none passes unless sieveMultiSphereCanPass.
TEST_CASE("fix massflow/mesh/sieve: clumps pass only with sieveMultiSphereCanPass",
          "[massflow][sieve][mpi][multisphere]") {
  const std::string dir = sieve_dir();
  for (const bool can_pass : {false, true}) {
    INFO("sieveMultiSphereCanPass " << can_pass);
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    std::vector<std::string> lines = sieve_scene(dir, can_pass ? " sieveMultiSphereCanPass" : "");
    // no lattice spheres, no deletion (a clump cannot lose spheres), a floor
    // that catches what falls through: 60 dumbbells along x, 2 mm above the
    // sieve
    std::vector<std::string> scene;
    for (const std::string& l : lines) {
      if (l.rfind("create_atoms", 0) == 0 || l.rfind("set type", 0) == 0) continue;
      if (l.rfind("fix mf", 0) == 0) {
        std::string m = l;
        m.replace(m.find(" delete_atoms yes"), 17, "");
        // the dashpot of a clump acts on its two spheres together; 0.05 is
        // 2.2 times critical damping for the clump (and c dt / m small)
        m.replace(m.find("sieveDamping 0.2"), 16, "sieveDamping 0.05");
        scene.push_back(
            "fix dumb all particletemplate/multisphere 15485867 atom_type 1 density constant 2500 "
            "nspheres 2 ntry 200000 spheres -0.0005 0 0 0.0005 0.0005 0 0 0.0005 type 1");
        scene.push_back("fix ms all multisphere");
        scene.push_back(
            "fix floor all wall/gran model hertz tangential history primitive type 1 zplane -0.02");
        scene.push_back(m);
        continue;
      }
      if (l == "fix integr all nve/sphere") continue;  // fix multisphere moves the clumps
      scene.push_back(l);
    }
    s.cmds(scene);
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < 10; ++j) {
        char line[120];
        std::snprintf(line, sizeof line, "create_clump dumb %.4f %.4f %.4f", -0.05 + 0.02 * i,
                      -0.05 + 0.011 * j, kSieveZ + 0.0005 + 0.002);
        s.cmd(line);
      }
    REQUIRE(s.e.particles->natoms == 120);
    s.cmd("run 4000");
    const double counted = fval(s.e, "mf", 2);
    if (!can_pass) {
      CHECK(counted == 0.0);
      // every sphere rests on the sieve
      for (const auto& [id, l] : left_over(s.e))
        CHECK(l.z > kSieveZ + 0.0005 - 1e-5);
      const double weight = 120 * 2500 * 4.0 / 3.0 * kPi * 0.0005 * 0.0005 * 0.0005 * kG;
      CHECK(fval(s.e, "mf", 9) == Approx(-weight).epsilon(1e-3));  // some still rock a little
    } else {
      // each sphere of a clump draws like a free sphere (P = 0.349): some
      // clumps fall through, some hang in the sieve by one sphere. Every
      // sphere below the sieve was counted (a sphere counts as half a
      // particle, its share of the clump's mass)
      CHECK(counted > 0.0);
      int below = 0;
      for (const auto& [id, l] : left_over(s.e))
        below += l.z < kSieveZ;
      CHECK(below > 0);
      CHECK(below <= 2 * counted);
    }
  }
}

TEST_CASE("fix massflow/mesh/sieve: errors say what to change", "[massflow][sieve][mpi][errors]") {
  const std::string dir = sieve_dir();
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  std::vector<std::string> scene = sieve_scene(dir, "");
  scene.pop_back();
  s.cmds(scene);
  const std::string f = "fix mf all massflow/mesh/sieve mesh sieve point_at_outlet 0 0 -1 count once ";
  CHECK_THROWS_WITH(s.cmd(f), Contains("sieveSize") && Contains("sieveStiffness"));
  CHECK_THROWS_WITH(s.cmd(f + "sieveSize 0.003 sieveSpacing 0.003"), Contains("sieveStiffness"));
  CHECK_THROWS_WITH(s.cmd(f + "sieveSize 0.003 sieveSpacing 0.002 sieveStiffness 100"),
                    Contains("at least") && Contains("overlap"));
  CHECK_THROWS_WITH(s.cmd(f + "sieveSize 0 sieveSpacing 0.003 sieveStiffness 100"), Contains("positive"));
  CHECK_THROWS_WITH(s.cmd(f + "sieveSize 0.003 sieveSpacing 0.003 sieveStiffness 100 sieveDamping -1"),
                    Contains("negative"));
  CHECK_THROWS_WITH(s.cmd(f + "sieveSize 0.003 sieveSpacing 0.003 sieveStiffness 100 seed 0"),
                    Contains("positive integer"));
  CHECK_THROWS_WITH(s.cmd(f + "sieveSize 0.003 sieveSpacing 0.003 sieveStiffness 100 sieveHoles 3"),
                    Contains("'sieveHoles'") && Contains("sieveMultiSphereCanPass"));
  CHECK_THROWS_WITH(s.cmd(f + "sieveSize"), Contains("sieveSize needs a value"));
  // fix massflow/mesh knows no sieve
  CHECK_THROWS_WITH(s.cmd("fix m2 all massflow/mesh mesh sieve vec_side 0 0 -1 sieveSize 0.003"),
                    Contains("unknown keyword") && Contains("'sieveSize'"));
  s.cmd(f + "sieveSize 0.003 sieveSpacing 0.003 sieveStiffness 100 seed 7");
  CHECK(s.e.modify->find_fix("mf")->size_vector == 9);
}
