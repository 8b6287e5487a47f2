// Primitive walls visit only the particles near them: with the default
// neighbour settings (neigh_modify every 1 delay 0) fix wall/gran lists, at
// every neighbour-list build, the particles closer to the wall than radius +
// skin, and skips the others until the next build (no particle moves more than
// half the skin in between). These tests pour beads into a box of five walls,
// once with the near list and once with every particle visited at every step,
// and require identical trajectories and wall histories. Mesh walls do the
// same while their meshes stand still; a moving mesh makes them visit every
// particle.
#include <catch2/catch.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "mesh_files.h"
#include "neighbor/neighbor.h"
#include "script_engine.h"

namespace {

using granary::Vec3;

struct Pour {
  std::vector<Vec3> x, v, omega;  // by id (index 0 unused)
  long long builds = 0;
  int wall_contacts = 0;  // particles touching the floor at the end
};

// `delay` 0 uses the near lists; `delay 1` visits every particle and rebuilds
// at the same steps (decide() runs after the step counter since the last build
// was incremented, so it is never below 1).
// A box of five meshed walls (floor at z = 0 and four sides at +-6 mm, 0.5 mm
// triangles are finer than the beads, so contacts cross triangle edges).
std::string box_mesh(bool floor) {
  static const std::string dir = mesh_files::temp_dir();
  std::vector<mesh_files::Triangle> t;
  const double a = 0.006, h = 0.04;
  if (floor) {
    mesh_files::add_rectangle(t, Vec3(-a, -a, 0), Vec3(2 * a, 0, 0), Vec3(0, 2 * a, 0), 8, 8);
  } else {
    mesh_files::add_rectangle(t, Vec3(-a, -a, 0), Vec3(2 * a, 0, 0), Vec3(0, 0, h), 6, 10);
    mesh_files::add_rectangle(t, Vec3(-a, a, 0), Vec3(2 * a, 0, 0), Vec3(0, 0, h), 6, 10);
    mesh_files::add_rectangle(t, Vec3(-a, -a, 0), Vec3(0, 2 * a, 0), Vec3(0, 0, h), 6, 10);
    mesh_files::add_rectangle(t, Vec3(a, -a, 0), Vec3(0, 2 * a, 0), Vec3(0, 0, h), 6, 10);
  }
  const std::string file = dir + (floor ? "/floor.stl" : "/sides.stl");
  mesh_files::write_ascii(file, t);
  return file;
}

Pour pour(const std::string& neigh_modify, const std::string& side_walls) {
  granary::test::ScriptEngine s;
  const bool mesh = side_walls == "mesh" || side_walls == "moving mesh";
  std::vector<std::string> script = {
      "units si",
      "atom_style granular",
      "boundary m m m",
      "newton off",
      "region box block -0.008 0.008 -0.008 0.008 0.0 0.04 units box",
      "create_box 1 box",
      "neighbor 0.0005 bin",
      neigh_modify,
      granary::test::materials(1, 5.e6, 0.45, 0.7, 0.5),
      "fix m5 all property/global coefficientRollingFriction peratomtypepair 1 0.1",
      "pair_style gran model hertz tangential history rolling_friction cdt",
      "pair_coeff * *",
      "timestep 2e-5",
      "region fill block -0.0035 0.0035 -0.0035 0.0035 0.001 0.035 units box",
      "create_atoms 1 random 120 4711 fill overlap 0.0021 maxtry 200",
      "set type 1 diameter 0.002 density 2500",
      "velocity all set 0.3 -0.2 -0.5",
      "fix gravi all gravity 9.81 vector 0.0 0.0 -1.0",
  };
  const std::string model = "wall/gran model hertz tangential history rolling_friction cdt primitive type 1 ";
  if (!mesh) script.push_back("fix zwall all " + model + "zplane 0.0");
  if (mesh) {
    script.push_back("fix floor all mesh/surface file " + box_mesh(true) + " type 1");
    script.push_back("fix sides all mesh/surface file " + box_mesh(false) + " type 1");
    script.push_back(
        "fix walls all wall/gran model hertz tangential history rolling_friction cdt mesh n_meshes 2 meshes "
        "floor sides");
    // a floor creeping sideways by 0.1 um per step moves the mesh nodes every step
    if (side_walls == "moving mesh")
      script.push_back("fix creep all move/mesh mesh floor linear 0.005 0. 0.");
  } else if (side_walls == "planes") {
    script.push_back("fix xw1 all " + model + "xplane -0.006");
    script.push_back("fix xw2 all " + model + "xplane 0.006");
    script.push_back("fix yw1 all " + model + "yplane -0.006");
    script.push_back("fix yw2 all " + model + "yplane 0.006");
  } else {
    script.push_back("fix cyl all " + model + "zcylinder 0.0065 0.0 0.0");
  }
  script.push_back("fix integr all nve/sphere");
  script.push_back("run 6000");
  s.cmds(script);
  const auto& p = s.p();
  REQUIRE(p.nlocal == 120);
  Pour out;
  out.x.assign(p.nlocal + 1, Vec3::Zero());
  out.v = out.x;
  out.omega = out.x;
  for (int i = 0; i < p.nlocal; ++i) {
    out.x[p.id[i]] = p.x[i];
    out.v[p.id[i]] = p.v[i];
    out.omega[p.id[i]] = p.omega[i];
    if (p.x[i][2] < p.radius[i]) ++out.wall_contacts;
  }
  out.builds = s.e.neighbor->nbuilds;
  return out;
}

void require_same(const Pour& a, const Pour& b) {
  CHECK(a.builds == b.builds);
  CHECK(a.wall_contacts == b.wall_contacts);
  double dx = 0, dv = 0, dw = 0;
  for (std::size_t k = 1; k < a.x.size(); ++k) {
    dx = std::max(dx, (a.x[k] - b.x[k]).norm());
    dv = std::max(dv, (a.v[k] - b.v[k]).norm());
    dw = std::max(dw, (a.omega[k] - b.omega[k]).norm());
  }
  INFO("largest differences: position " << dx << " m, velocity " << dv << " m/s, spin " << dw << " rad/s");
  // the same operations in the same order: identical to the last bit
  CHECK(dx == 0.0);
  CHECK(dv == 0.0);
  CHECK(dw == 0.0);
}

}  // namespace

TEST_CASE("plane walls with near lists give the trajectories of a full scan", "[wall][physics]") {
  const Pour near = pour("neigh_modify delay 0", "planes");
  const Pour full = pour("neigh_modify delay 1", "planes");
  // the beads have landed and lean on the floor (and the side walls)
  CHECK(near.wall_contacts > 20);
  CHECK(near.builds > 10);
  require_same(near, full);
  // the side walls contain the beads
  for (std::size_t k = 1; k < near.x.size(); ++k) {
    CHECK(std::fabs(near.x[k][0]) < 0.006);
    CHECK(std::fabs(near.x[k][1]) < 0.006);
  }
}

TEST_CASE("a cylinder wall with near lists gives the trajectories of a full scan", "[wall][physics]") {
  const Pour near = pour("neigh_modify delay 0", "cylinder");
  const Pour full = pour("neigh_modify delay 1", "cylinder");
  CHECK(near.wall_contacts > 20);
  require_same(near, full);
  for (std::size_t k = 1; k < near.x.size(); ++k)
    CHECK(std::hypot(near.x[k][0], near.x[k][1]) < 0.0065);
}

TEST_CASE("mesh walls with near lists give the trajectories of a full scan", "[wall][mesh][physics]") {
  const Pour near = pour("neigh_modify delay 0", "mesh");
  const Pour full = pour("neigh_modify delay 1", "mesh");
  CHECK(near.wall_contacts > 20);
  CHECK(near.builds > 10);
  require_same(near, full);
  for (std::size_t k = 1; k < near.x.size(); ++k) {
    CHECK(std::fabs(near.x[k][0]) < 0.006);
    CHECK(std::fabs(near.x[k][1]) < 0.006);
  }
}

TEST_CASE("a moving mesh wall is scanned in full and matches the trajectories of delay 1",
          "[wall][mesh][physics]") {
  const Pour near = pour("neigh_modify delay 0", "moving mesh");
  const Pour full = pour("neigh_modify delay 1", "moving mesh");
  CHECK(near.wall_contacts > 20);
  require_same(near, full);
}
