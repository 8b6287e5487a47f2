// Mesh walls give the same physics on 1, 2 and 4 MPI ranks.
//
// Run by ctest at 1, 2 and 4 ranks. A few hundred spheres are poured into a
// box made of one STL mesh: four side walls and a floor with a slit narrower
// than the spheres, so that they rest on faces, in concave corners and on the
// convex edges of the slit. Every rank first runs the whole system alone
// (MPI_COMM_SELF) as the reference, then all ranks run it together.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "comm/collectives.h"
#include "core/engine.h"
#include "core/input.h"
#include "core/logger.h"
#include "mesh_files.h"
#include "particles/particles.h"
#include "script_engine.h"

using granary::Vec3;

namespace {

// The common start of the scenes: two types of one material (friction mu,
// rolling friction mu_r), the Hertz pair style, a box of fixed boundaries.
std::vector<std::string> scene(const std::string& processors, const std::string& box, const std::string& mu,
                               const std::string& mu_r, const std::string& timestep) {
  return {"units si",
          "atom_style granular",
          "boundary f f f",
          "processors " + processors,
          "region box block " + box + " units box",
          "create_box 2 box",
          "neighbor 0.0005 bin",
          "neigh_modify delay 0",
          "fix m1 all property/global youngsModulus peratomtype 5.e6 5.e6",
          "fix m2 all property/global poissonsRatio peratomtype 0.45 0.45",
          "fix m3 all property/global coefficientRestitution peratomtypepair 2 0.5 0.5 0.5 0.5",
          "fix m4 all property/global coefficientFriction peratomtypepair 2 " + mu + " " + mu + " " + mu +
              " " + mu,
          "fix m5 all property/global coefficientRollingFriction peratomtypepair 2 " + mu_r + " " + mu_r +
              " " + mu_r + " " + mu_r,
          "pair_style gran model hertz tangential history rolling_friction cdt",
          "pair_coeff * *",
          "timestep " + timestep};
}

// An STL file written by rank 0 into a temporary directory; every rank learns its name.
std::string shared_mesh_file(const std::string& name, const std::vector<mesh_files::Triangle>& t) {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  char buf[512] = {};
  if (rank == 0) {
    const std::string f = mesh_files::temp_dir() + "/" + name;
    mesh_files::write_binary(f, t);
    std::snprintf(buf, sizeof buf, "%s", f.c_str());
  }
  MPI_Bcast(buf, sizeof buf, MPI_CHAR, 0, MPI_COMM_WORLD);
  return buf;
}

std::string box_file() {
  static const std::string name = [] {
    std::vector<mesh_files::Triangle> t;
    const double a = 0.01, g = 0.00075, h = 0.03;
    // floor with a slit |x| < g, the slit's side faces, and the four walls
    mesh_files::add_rectangle(t, Vec3(-a, -a, 0), Vec3(a - g, 0, 0), Vec3(0, 2 * a, 0), 3, 4);
    mesh_files::add_rectangle(t, Vec3(g, -a, 0), Vec3(a - g, 0, 0), Vec3(0, 2 * a, 0), 3, 4);
    mesh_files::add_rectangle(t, Vec3(-g, -a, 0), Vec3(0, 0, -0.004), Vec3(0, 2 * a, 0), 1, 4);
    mesh_files::add_rectangle(t, Vec3(g, -a, 0), Vec3(0, 0, -0.004), Vec3(0, 2 * a, 0), 1, 4);
    mesh_files::add_rectangle(t, Vec3(-a, -a, 0), Vec3(0, 2 * a, 0), Vec3(0, 0, h), 4, 3);
    mesh_files::add_rectangle(t, Vec3(a, -a, 0), Vec3(0, 2 * a, 0), Vec3(0, 0, h), 4, 3);
    mesh_files::add_rectangle(t, Vec3(-a, -a, 0), Vec3(2 * a, 0, 0), Vec3(0, 0, h), 4, 3);
    mesh_files::add_rectangle(t, Vec3(-a, a, 0), Vec3(2 * a, 0, 0), Vec3(0, 0, h), 4, 3);
    return shared_mesh_file("slit_box.stl", t);
  }();
  return name;
}

struct Snapshot {
  long long natoms = 0;
  double ke = 0.0, fz = 0.0;
  std::map<long long, Vec3> x;
};

Snapshot run_box(MPI_Comm comm, const std::string& file) {
  granary::Engine e(comm);
  e.logger->set_screen(false);
  std::vector<std::string> script =
      scene("* * 1", "-0.011 0.011 -0.011 0.011 -0.005 0.03", "0.5", "0.1", "2e-5");
  for (const auto& l : std::vector<std::string>{
           "region fill block -0.0088 0.0088 -0.0088 0.0088 0.0012 0.025 units box",
           "create_atoms 1 random 300 4711 fill overlap 0.0021 maxtry 200",
           "set type 1 diameter 0.002 density 2500",
           "velocity all set 0.1 -0.05 -0.5",
           "fix gravi all gravity 9.81 vector 0.0 0.0 -1.0",
           "fix cad all mesh/surface file " + file + " type 2",
           "fix walls all wall/gran model hertz tangential history rolling_friction cdt mesh n_meshes 1 "
           "meshes "
           "cad",
           "fix integr all nve/sphere",
           "thermo 500",
           "run 1200",
       })
    script.push_back(l);
  granary::test::run(e, script);
  Snapshot s;
  const auto& p = *e.particles;
  std::vector<double> mine;
  for (int i = 0; i < p.nlocal; ++i) {
    mine.push_back(static_cast<double>(p.id[i]));
    for (int d = 0; d < 3; ++d)
      mine.push_back(p.x[i][d]);
  }
  const std::vector<double> all = granary::allgather(comm, mine);
  for (std::size_t k = 0; k + 3 < all.size(); k += 4)
    s.x[static_cast<long long>(all[k])] = Vec3(all[k + 1], all[k + 2], all[k + 3]);
  s.natoms = static_cast<long long>(s.x.size());
  bool found = false;
  s.ke = e.thermo_keyword("ke", found);
  s.fz = e.fix_value("walls", 3);
  return s;
}

}  // namespace

TEST_CASE("spheres poured into a mesh box with a slit give the same result on every rank count", "[mesh]") {
  const std::string file = box_file();
  const Snapshot ref = run_box(MPI_COMM_SELF, file);
  const Snapshot par = run_box(MPI_COMM_WORLD, file);
  REQUIRE(ref.natoms == 300);
  REQUIRE(par.natoms == ref.natoms);
  // the bed rests on the mesh: it carries most of the weight (300 spheres of 10.5 mg)
  const double weight = 300 * 2500 * 4.0 / 3.0 * M_PI * 1e-9 * 9.81;
  INFO("force on the mesh " << ref.fz << " N, weight " << weight << " N");
  CHECK(-ref.fz > 0.5 * weight);
  // spheres sit on the slit's edges
  int on_slit = 0;
  for (const auto& kv : ref.x)
    on_slit += std::fabs(kv.second[0]) < 0.0012 && kv.second[2] < 0.001 ? 1 : 0;
  CHECK(on_slit > 0);
  CHECK(par.ke == Approx(ref.ke).epsilon(1e-6));
  CHECK(par.fz == Approx(ref.fz).epsilon(1e-6));
  double worst = 0.0;
  for (const auto& kv : ref.x) {
    auto it = par.x.find(kv.first);
    REQUIRE(it != par.x.end());
    worst = std::max(worst, (it->second - kv.second).norm());
  }
  INFO("largest position difference " << worst << " m");
  CHECK(worst < 1e-9);
}

namespace {

// A channel along x whose side walls (y = +-w, w = 2^-10 m, exact in the
// single precision of STL files) are 1 um closer than the spheres' radius:
// every sphere touches the floor and both walls, three
// mesh contacts, one more than the per-particle slots hold, so the third
// contact's history lives in the wall fix's table of extra slots. Gravity
// tilted along x keeps the spheres sliding through the x slabs of the ranks
// (the table's records travel with them); the same scene with three primitive
// planes is the reference.
std::string channel_file() {
  static const std::string name = [] {
    std::vector<mesh_files::Triangle> t;
    const double w = 0.0009765625, l = 0.04, h = 0.004;
    mesh_files::add_rectangle(t, Vec3(0, -w, 0), Vec3(l, 0, 0), Vec3(0, 2 * w, 0), 8, 1);
    mesh_files::add_rectangle(t, Vec3(0, -w, 0), Vec3(l, 0, 0), Vec3(0, 0, h), 8, 1);
    mesh_files::add_rectangle(t, Vec3(0, w, 0), Vec3(l, 0, 0), Vec3(0, 0, h), 8, 1);
    return shared_mesh_file("channel.stl", t);
  }();
  return name;
}

struct Channel {
  std::map<long long, Vec3> x, v;
  int min_contacts = 1000, max_contacts = 0;  // mesh contacts per particle at the end
};

Channel run_channel(MPI_Comm comm, bool mesh) {
  granary::Engine e(comm);
  e.logger->set_screen(false);
  const std::string model = "wall/gran model hertz tangential history rolling_friction cdt ";
  std::vector<std::string> script =
      scene("* 1 1", "-0.001 0.041 -0.002 0.002 -0.001 0.004", "0.1", "0.0", "1e-5");
  for (int k = 0; k < 6; ++k)
    script.push_back("create_atoms 1 single " + std::to_string(0.002 + 0.0035 * k) +
                     " 0.0 0.0009774625 units box");
  for (const auto& l : std::vector<std::string>{
           "set type 1 diameter 0.001955125 density 2500",
           "velocity all set 0.4 0.0 0.0 units box",
           "fix gravi all gravity 9.81 vector 1.0 0.0 -1.0",
       })
    script.push_back(l);
  if (mesh) {
    script.push_back("fix cad all mesh/surface file " + channel_file() + " type 2");
    script.push_back("fix walls all " + model + "mesh n_meshes 1 meshes cad");
  } else {
    script.push_back("fix floor all " + model + "primitive type 2 zplane 0.0");
    script.push_back("fix side1 all " + model + "primitive type 2 yplane -0.0009765625");
    script.push_back("fix side2 all " + model + "primitive type 2 yplane 0.0009765625");
  }
  script.push_back("fix integr all nve/sphere");
  script.push_back("run 2500");
  granary::test::run(e, script);
  Channel c;
  const auto& p = *e.particles;
  std::vector<double> mine;
  const int count = mesh ? p.find_field("mesh_wall_contacts/walls") : -1;
  for (int i = 0; i < p.nlocal; ++i) {
    mine.push_back(static_cast<double>(p.id[i]));
    for (int d = 0; d < 3; ++d)
      mine.push_back(p.x[i][d]);
    for (int d = 0; d < 3; ++d)
      mine.push_back(p.v[i][d]);
    mine.push_back(count >= 0 ? p.extras[count].data[i] : 3.0);
  }
  const std::vector<double> all = granary::allgather(comm, mine);
  for (std::size_t k = 0; k + 7 < all.size(); k += 8) {
    c.x[static_cast<long long>(all[k])] = Vec3(all[k + 1], all[k + 2], all[k + 3]);
    c.v[static_cast<long long>(all[k])] = Vec3(all[k + 4], all[k + 5], all[k + 6]);
    c.min_contacts = std::min(c.min_contacts, static_cast<int>(all[k + 7]));
    c.max_contacts = std::max(c.max_contacts, static_cast<int>(all[k + 7]));
  }
  return c;
}

}  // namespace

TEST_CASE("spheres sliding in a narrow mesh channel keep three contacts with history on every rank count",
          "[mesh]") {
  const Channel planes = run_channel(MPI_COMM_SELF, false);
  const Channel one = run_channel(MPI_COMM_SELF, true);
  const Channel all = run_channel(MPI_COMM_WORLD, true);
  REQUIRE(planes.x.size() == 6);
  REQUIRE(one.x.size() == 6);
  REQUIRE(all.x.size() == 6);
  CHECK(one.min_contacts == 3);
  CHECK(one.max_contacts == 3);
  CHECK(all.min_contacts == 3);
  double travelled = 1e30, dplanes = 0.0, dranks = 0.0;
  for (const auto& [id, x] : planes.x) {
    travelled = std::min(travelled, x[0] - (0.002 + 0.0035 * (id - 1)));
    dplanes = std::max({dplanes, (one.x.at(id) - x).norm() / 0.01, (one.v.at(id) - planes.v.at(id)).norm()});
    dranks = std::max(dranks, (all.x.at(id) - one.x.at(id)).norm());
  }
  INFO("shortest distance slid " << travelled << " m; mesh vs planes " << dplanes << ", ranks " << dranks
                                 << " m");
  CHECK(travelled > 0.01);  // every sphere crossed at least one 1 cm slab of 4 ranks
  CHECK(dplanes < 1e-12);   // three face contacts with their history = three planes
  CHECK(dranks < 1e-12);
}
