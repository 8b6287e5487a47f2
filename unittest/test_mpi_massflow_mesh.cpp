// fix massflow/mesh on 1, 2 and 4 ranks (run by ctest at each count): the
// mass and number of spheres falling through a planar mesh (the known mass
// of the spheres above it, at the steps free fall predicts, as LIGGGHTS 3.8
// counts them), counting across a periodic boundary (multiple, once),
// deleting what passed, the sides of point_at_outlet on a cylinder, the
// per-atom marker, the file, restart files and the errors.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/modify.h"
#include "core/update.h"
#include "fix/fix.h"
#include "mesh_files.h"
#include "particles/particles.h"
#include "script_engine.h"

using Catch::Matchers::Contains;
using granary::Vec3;

namespace {

namespace fs = std::filesystem;
constexpr double kPi = 3.14159265358979323846;

using granary::test::world_rank;
using granary::test::world_size;

// A fresh output directory per test and rank count (ctest may run counts at
// once), with the meshes: the square -10..10 mm in x and y at z = 0 (two
// triangles, normal +z), a bent sheet (not planar), and a cylinder of radius
// 5 mm around the z axis from z = -5 to 5 mm (24 facets).
std::string fresh_dir(const std::string& name) {
  const std::string dir = "massflow_np" + std::to_string(world_size()) + "/" + name;
  if (world_rank() == 0) {
    fs::remove_all(dir);
    fs::create_directories(dir);
    std::vector<mesh_files::Triangle> plane, bent, cyl;
    mesh_files::add_rectangle(plane, Vec3(-0.01, -0.01, 0), Vec3(0.02, 0, 0), Vec3(0, 0.02, 0), 1, 1);
    mesh_files::write_ascii(dir + "/plane.stl", plane);
    mesh_files::add_rectangle(bent, Vec3(-0.01, -0.01, 0), Vec3(0.01, 0, 0), Vec3(0, 0.02, 0), 1, 1);
    mesh_files::add_rectangle(bent, Vec3(0, -0.01, 0), Vec3(0.01, 0, 0.002), Vec3(0, 0.02, 0), 1, 1);
    mesh_files::write_ascii(dir + "/bent.stl", bent);
    const int n = 24;
    const double r = 0.005;
    for (int k = 0; k < n; ++k) {
      const double a0 = 2 * kPi * k / n, a1 = 2 * kPi * (k + 1) / n;
      mesh_files::add_rectangle(cyl, Vec3(r * std::cos(a0), r * std::sin(a0), -0.005),
                                Vec3(r * (std::cos(a1) - std::cos(a0)), r * (std::sin(a1) - std::sin(a0)), 0),
                                Vec3(0, 0, 0.01), 1, 1);
    }
    mesh_files::write_ascii(dir + "/cyl.stl", cyl);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  return dir;
}

// The box, materials and pair style of LIGGGHTS' test script, the square
// mesh `plane`, and 98 spheres (d = 2 mm) on a simple cubic lattice of 4 mm:
// 7 x 7 columns at z = 4 and 8 mm; the 5 x 5 columns inside |x|, |y| < 10 mm
// fall through the square.
std::vector<std::string> falling(const std::string& dir, const std::string& boundary) {
  return {"units si",
          "atom_style granular",
          "atom_modify map array",
          "boundary " + boundary,
          "newton off",
          "communicate single vel yes",
          "region domain block -0.02 0.02 -0.02 0.02 -0.03 0.03 units box",
          "create_box 1 domain",
          "neighbor 0.0005 bin",
          "neigh_modify delay 0",
          granary::test::materials(1, 5.e6, 0.45, 0.9, 0.5),
          "pair_style gran model hertz tangential history",
          "pair_coeff * *",
          "timestep 0.00001",
          "fix gravi all gravity 9.81 vector 0.0 0.0 -1.0",
          "fix plane all mesh/surface file " + dir + "/plane.stl type 1",
          "lattice sc 0.004",
          "region fill block -0.012 0.012 -0.012 0.012 0.002 0.01 units box",
          "create_atoms 1 region fill",
          "set group all diameter 0.002 density 2500",
          "fix integr all nve/sphere"};
}

double fval(granary::Engine& e, const std::string& id, int k) {
  return e.modify->find_fix(id)->compute_vector(k - 1);
}

std::vector<std::vector<double>> read_rows(const std::string& file, std::string& header) {
  std::ifstream in(file);
  std::vector<std::vector<double>> rows;
  std::string line;
  std::getline(in, header);
  while (std::getline(in, line)) {
    std::istringstream ss(line);
    std::vector<double> r;
    double v;
    while (ss >> v)
      r.push_back(v);
    rows.push_back(r);
  }
  return rows;
}

const double kMass = 2500 * 4.0 / 3.0 * kPi * 1e-9;  // one sphere of d = 2 mm

}  // namespace

// LIGGGHTS 3.8 with the same script (thermo every 1000 steps of f_mass[1..6])
// gives 25 spheres, 0.0002617993878 kg, at step 3000 and 50 spheres,
// 0.0005235987756 kg, at 5000, with the rates 0.02617993878 kg/s and
// 2500 /s over the last 1000 steps at both; its file (writeTime) has the 25
// spheres of the lower layer at t = 0.02856 s, crossing at z = -8.79e-07 m
// with vz = -0.2801 m/s, and the upper layer at 0.04039 s.
TEST_CASE("fix massflow/mesh: the mass through a plane is the mass of the spheres that fell through it",
          "[massflow][mpi][liggghts]") {
  const std::string dir = fresh_dir("plane");
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds(falling(dir, "f f f"));
  s.cmds({"fix mass all massflow/mesh mesh plane vec_side 0 0 -1 file " + dir + "/mf.txt writeTime",
          "thermo_style custom step atoms f_mass[1] f_mass[2] f_mass[3] f_mass[4] f_mass[5] f_mass[6]",
          "thermo 1000"});
  CHECK(s.e.particles->natoms == 98);
  s.cmd("run 2000");
  CHECK(fval(s.e, "mass", 2) == 0.0);
  s.cmd("run 1000");
  CHECK(fval(s.e, "mass", 1) == Approx(25 * kMass).epsilon(1e-12));
  CHECK(fval(s.e, "mass", 2) == 25.0);
  CHECK(fval(s.e, "mass", 3) == Approx(0.02617993878).epsilon(1e-9));
  CHECK(fval(s.e, "mass", 4) == Approx(2500).epsilon(1e-12));
  s.cmd("run 2000");
  CHECK(fval(s.e, "mass", 1) == Approx(50 * kMass).epsilon(1e-12));
  CHECK(fval(s.e, "mass", 2) == 50.0);
  // over the 1000 steps since the last read (thermo at step 4000)
  CHECK(fval(s.e, "mass", 3) == Approx(0.02617993878).epsilon(1e-9));
  CHECK(fval(s.e, "mass", 4) == Approx(2500).epsilon(1e-12));
  CHECK(fval(s.e, "mass", 5) == 0.0);
  CHECK(fval(s.e, "mass", 6) == 0.0);
  s.cmd("run 3000");
  CHECK(fval(s.e, "mass", 2) == 50.0);
  CHECK(fval(s.e, "mass", 3) == 0.0);
  // the per-atom marker, also under LIGGGHTS' name: 1 counted, 0 came within
  // reach of the mesh, -1 never did (the columns beyond its edges)
  std::vector<double> marker, alias;
  s.e.fix_peratom("mass", 0, marker);
  s.e.fix_peratom("massflow_mass", 0, alias);
  CHECK(marker == alias);
  double counts[3] = {0, 0, 0}, all[3];
  for (double m : marker)
    counts[static_cast<int>(m) + 1] += 1;
  MPI_Allreduce(counts, all, 3, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  CHECK(all[2] == 50);
  CHECK(all[1] == 0);
  CHECK(all[0] == 48);  // 2 mm beyond the edges: farther than radius and skin
  // the file: every sphere once, at the first step free fall takes its
  // centre below the plane: z0 - g (n dt)^2 / 2 < 0
  if (world_rank() == 0) {
    std::string header;
    const auto rows = read_rows(dir + "/mf.txt", header);
    CHECK(header == "# ID time  diameter x y z u v w  (ex ey ez, color)");
    REQUIRE(rows.size() == 50);
    std::map<long long, int> seen;
    for (const auto& r : rows) {
      REQUIRE(r.size() == 9);
      ++seen[static_cast<long long>(r[0])];
      CHECK(r[2] == 0.002);
      CHECK(std::abs(r[3]) < 0.01);
      CHECK(std::abs(r[4]) < 0.01);
      const double z0 = r[5] + 0.5 * 9.81 * r[1] * r[1];  // where it started
      const bool lower = std::abs(z0 - 0.004) < 1e-9;
      CHECK((lower || std::abs(z0 - 0.008) < 1e-9));
      const long long step = std::llround(r[1] / 1e-5);
      CHECK(step == (lower ? 2856 : 4039));
      CHECK(r[5] < 0.0);
      CHECK(r[5] + 0.5 * 9.81 * r[1] * r[1] - 0.5 * 9.81 * std::pow((step - 1) * 1e-5, 2) >
            0.0);                                                    // above at n-1
      CHECK(r[8] == Approx(-9.81 * (r[1] - 0.5e-5)).epsilon(1e-9));  // the velocity of the step's middle
      if (lower) {
        CHECK(r[5] == Approx(-8.79e-07).epsilon(1e-3));  // LIGGGHTS' %.4g
        CHECK(r[8] == Approx(-0.2801).margin(5e-5));
      }
    }
    CHECK(seen.size() == 50);
  }
}

// LIGGGHTS 3.8, boundary f f p: with count multiple the spheres fall through
// the plane again after crossing the periodic boundary (200 at step 20000);
// with count once they are counted once (50).
TEST_CASE("fix massflow/mesh: count multiple and once across a periodic boundary",
          "[massflow][mpi][liggghts]") {
  const std::string dir = fresh_dir("periodic");
  for (const char* count : {"multiple", "once"}) {
    INFO("count " << count);
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    s.cmds(falling(dir, "f f p"));
    s.cmds(
        {std::string("fix mass all massflow/mesh mesh plane vec_side 0 0 -1 count ") + count, "run 11000"});
    CHECK(fval(s.e, "mass", 2) == 50.0);
    s.cmd("run 1000");
    const bool multiple = count == std::string("multiple");
    CHECK(fval(s.e, "mass", 2) == (multiple ? 100.0 : 50.0));
    s.cmd("run 8000");
    CHECK(fval(s.e, "mass", 2) == (multiple ? 200.0 : 50.0));
    CHECK(fval(s.e, "mass", 1) == Approx((multiple ? 200 : 50) * kMass).epsilon(1e-12));
  }
}

// LIGGGHTS 3.8: 50 spheres deleted, 48 left; f_mass[5] and [6] the mass and
// number deleted.
TEST_CASE("fix massflow/mesh: delete_atoms removes what passed", "[massflow][mpi][liggghts]") {
  const std::string dir = fresh_dir("delete");
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds(falling(dir, "f f f"));
  s.cmds({"fix mass all massflow/mesh mesh plane vec_side 0 0 -1 count once delete_atoms yes", "run 8000"});
  CHECK(s.e.particles->natoms == 48);
  CHECK(fval(s.e, "mass", 2) == 50.0);
  CHECK(fval(s.e, "mass", 5) == Approx(50 * kMass).epsilon(1e-12));
  CHECK(fval(s.e, "mass", 6) == 50.0);
  // the state goes to restart files
  s.cmd("write_restart " + dir + "/mf.restart");
  granary::test::ScriptEngine r(MPI_COMM_WORLD);
  r.cmds({"read_restart " + dir + "/mf.restart",
          "fix plane all mesh/surface file " + dir + "/plane.stl type 1",
          "fix mass all massflow/mesh mesh plane vec_side 0 0 -1 count once delete_atoms yes"});
  CHECK(fval(r.e, "mass", 1) == Approx(50 * kMass).epsilon(1e-12));
  CHECK(fval(r.e, "mass", 2) == 50.0);
  CHECK(fval(r.e, "mass", 6) == 50.0);
}

// LIGGGHTS 3.8 (a 24-facet cylinder, point_at_outlet on its axis): a sphere
// moving towards the axis through a facet is counted, one moving away is
// not; with inside_out the other way round.
TEST_CASE("fix massflow/mesh: point_at_outlet counts towards the point, inside_out away from it",
          "[massflow][mpi][liggghts]") {
  const std::string dir = fresh_dir("cylinder");
  for (const char* flip : {"", " inside_out"}) {
    INFO("keywords '" << flip << "'");
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    const double a = 7.5 * kPi / 180, b = 97.5 * kPi / 180;
    char in_line[200], out_line[200], vin[200], vout[200];
    std::snprintf(in_line, sizeof in_line, "create_atoms 1 single %.9f %.9f 0 units box", 0.008 * std::cos(a),
                  0.008 * std::sin(a));
    std::snprintf(out_line, sizeof out_line, "create_atoms 1 single %.9f %.9f 0.001 units box",
                  0.002 * std::cos(b), 0.002 * std::sin(b));
    std::snprintf(vin, sizeof vin, "set atom 1 vx %.9f vy %.9f", -std::cos(a), -std::sin(a));
    std::snprintf(vout, sizeof vout, "set atom 2 vx %.9f vy %.9f", std::cos(b), std::sin(b));
    s.cmds({"units si", "atom_style granular", "boundary f f f",
            "region domain block -0.02 0.02 -0.02 0.02 -0.03 0.03", "create_box 1 domain",
            "neighbor 0.0005 bin", granary::test::materials(1, 5.e6, 0.45, 0.9, 0.5),
            "pair_style gran model hertz tangential history", "pair_coeff * *", "timestep 0.00001",
            "fix cyl all mesh/surface file " + dir + "/cyl.stl type 1", in_line, out_line,
            "set group all diameter 0.001 density 2500", vin, vout, "fix integr all nve/sphere",
            std::string("fix mass all massflow/mesh mesh cyl count once point_at_outlet 0 0 0") + flip +
                " file " + dir + "/cyl.txt",
            "run 600"});
    CHECK(fval(s.e, "mass", 2) == 1.0);
    CHECK(fval(s.e, "mass", 1) == Approx(2500 * 4.0 / 3.0 * kPi * 0.0005 * 0.0005 * 0.0005).epsilon(1e-12));
    if (world_rank() == 0) {
      std::string header;
      const auto rows = read_rows(dir + "/cyl.txt", header);
      CHECK(header == "# ID diameter x y z u v w  (ex ey ez, color)");
      REQUIRE(rows.size() == 1);
      CHECK(rows[0][0] == (*flip ? 2.0 : 1.0));
      // LIGGGHTS: sphere 1 at r = 4.95 mm (step 305), sphere 2 at r = 4.96 mm (step 296),
      // just past the facet at r = 5 cos(7.5 deg) = 4.957 mm
      const double r = std::hypot(rows[0][2], rows[0][3]);
      const double facet = 0.005 * std::cos(7.5 * kPi / 180);
      if (*flip)
        CHECK((r > facet && r < facet + 1e-5));
      else
        CHECK((r < facet && r > facet - 1e-5));
    }
  }
}

TEST_CASE("fix massflow/mesh: errors say what to change", "[massflow][mpi][errors]") {
  const std::string dir = fresh_dir("errors");
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds(falling(dir, "f f f"));
  s.cmds({"fix bent all mesh/surface file " + dir + "/bent.stl type 1"});
  const std::string f = "fix mass all massflow/mesh ";
  CHECK_THROWS_WITH(s.cmd(f + "vec_side 0 0 -1"), Contains("mesh MESH-ID"));
  CHECK_THROWS_WITH(s.cmd(f + "mesh nowhere vec_side 0 0 -1"), Contains("nowhere"));
  CHECK_THROWS_WITH(s.cmd(f + "mesh gravi vec_side 0 0 -1"), Contains("not a mesh/surface fix"));
  CHECK_THROWS_WITH(s.cmd(f + "mesh plane"), Contains("vec_side") && Contains("point_at_outlet"));
  CHECK_THROWS_WITH(s.cmd(f + "mesh plane vec_side 1 0 0"), Contains("lies in the plane"));
  CHECK_THROWS_WITH(s.cmd(f + "mesh plane vec_side 0 0"), Contains("three numbers"));
  CHECK_THROWS_WITH(s.cmd(f + "mesh bent vec_side 0 0 -1"),
                    Contains("planar") && Contains("point_at_outlet"));
  CHECK_THROWS_WITH(s.cmd(f + "mesh plane vec_side 0 0 -1 inside_out"), Contains("inside_out"));
  CHECK_THROWS_WITH(s.cmd(f + "mesh plane point_at_outlet 0 0 -1"), Contains("count once"));
  CHECK_THROWS_WITH(s.cmd(f + "mesh plane vec_side 0 0 -1 delete_atoms yes"), Contains("count once"));
  CHECK_THROWS_WITH(s.cmd(f + "mesh plane vec_side 0 0 -1 count twice"), Contains("once or multiple"));
  CHECK_THROWS_WITH(s.cmd(f + "mesh plane vec_side 0 0 -1 sieveSize 0.002"), Contains("unknown keyword"));
  CHECK_THROWS_WITH(s.cmd(f + "mesh plane vec_side 0 0 -1 file " + dir + "/nodir/a.txt"),
                    Contains("cannot open"));
  // a bent mesh is fine with point_at_outlet
  s.cmd(f + "mesh bent count once point_at_outlet 0 0 -1");
  s.cmd("unfix mass");
  CHECK(s.e.modify->find_fix("mass") == nullptr);
}
