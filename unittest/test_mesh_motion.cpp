// Mesh walls with a velocity field: move/mesh rotate, mesh/surface surface_vel;
// mesh/surface/stress outputs; dump mesh/stl.
#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkXMLPolyDataReader.h>

#include <Eigen/Geometry>
#include <catch2/catch.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "core/engine.h"
#include "fix/fix_mesh_surface.h"
#include "core/modify.h"
#include "mesh_files.h"
#include "particles/particles.h"
#include "script_engine.h"

using Catch::Matchers::Contains;
using granary::Vec3;
using granary::test::ScriptEngine;
using mesh_files::Triangle;

namespace {

const std::string kDir = mesh_files::temp_dir();

// A 0.12 m square floor at z = 0 made of 6 x 6 cells (72 triangles).
std::string floor_file() {
  static const std::string f = [] {
    std::vector<Triangle> t;
    mesh_files::add_rectangle(t, Vec3(-0.06, -0.06, 0), Vec3(0.12, 0, 0), Vec3(0, 0.12, 0), 6, 6);
    mesh_files::write_ascii(kDir + "/floor.stl", t);
    return kDir + "/floor.stl";
  }();
  return f;
}

std::vector<std::string> scene() {
  return {
      "units si",
      "atom_style granular",
      "boundary f f f",
      "region box block -0.07 0.07 -0.07 0.07 -0.03 0.05 units box",
      "create_box 2 box",
      "neighbor 0.001 bin",
      "neigh_modify delay 0",
      granary::test::materials(2, 5.e6, 0.45, 0.5, 0.5),
      "pair_style gran model hertz tangential history",
      "pair_coeff * *",
      "timestep 1e-5",
  };
}

// One sphere (r = 5 mm) resting on the floor at (x, y), with gravity.
std::vector<std::string> sphere_on_floor(double x, double y) {
  return {"create_atoms 1 single " + std::to_string(x) + " " + std::to_string(y) + " 0.00499 units box",
          "set group all diameter 0.01 density 2500", "fix gravi all gravity 9.81 vector 0.0 0.0 -1.0"};
}

granary::TriMesh& mesh_of(ScriptEngine& s, const std::string& id) {
  return granary::FixMeshSurface::find(*s.e.modify, id, "test").mesh;
}

}  // namespace

TEST_CASE("move/mesh rotate turns the mesh by 2 pi t / T about the axis and drags a sphere", "[mesh]") {
  // A sphere resting on a disc that starts rotating at omega: at its place the
  // floor slides under it at u = omega x r; as on a belt it ends rolling at
  // 2/7 u (the sliding phase lasts 2 u / (7 mu g) = 4 ms, in which it moves
  // 0.3 mm, so u hardly changes; tolerance 2%).
  ScriptEngine s;
  s.cmds(scene());
  s.cmds(sphere_on_floor(0.03, 0.0));
  const double period = 1.0;
  s.cmds({"fix cad all mesh/surface file " + floor_file() + " type 2",
          "fix spin all move/mesh mesh cad rotate origin 0.0 0.0 0.0 axis 0 0 1 period 1.0",
          "fix floor all wall/gran model hertz tangential history mesh n_meshes 1 meshes cad",
          "fix integr all nve/sphere"});
  const auto& mesh = mesh_of(s, "cad");
  std::vector<Vec3> x0;
  for (int k = 0; k < mesh.nnodes(); ++k)
    x0.push_back(mesh.node(k));
  s.cmd("run 2000");
  const double omega = 2.0 * M_PI / period, t = 0.02;
  const Eigen::Matrix3d r = Eigen::AngleAxisd(omega * t, Vec3::UnitZ()).toRotationMatrix();
  double worst = 0;
  for (int k = 0; k < mesh.nnodes(); ++k)
    worst = std::max(worst, (mesh.node(k) - r * x0[k]).norm());
  CHECK(worst < 1e-15);
  // the wall velocity field: omega x (p - origin)
  CHECK((mesh.velocity_at(0, Vec3(0.03, 0.01, 0)) - Vec3(-omega * 0.01, omega * 0.03, 0)).norm() < 1e-15);
  const Vec3 v = s.p().v[0];
  CHECK(v[1] == Approx(2.0 / 7.0 * omega * 0.03).epsilon(0.02));
  CHECK(std::fabs(v[0]) < 0.05 * v[1]);
  // rotation about an off-centre, tilted axis
  s.cmds(
      {"unfix spin", "fix spin2 all move/mesh mesh cad rotate origin 0.01 0.02 0.0 axis 1 1 0 period -0.5"});
  std::vector<Vec3> x1;
  for (int k = 0; k < mesh.nnodes(); ++k)
    x1.push_back(mesh.node(k));
  s.cmd("unfix floor");
  s.cmd("run 100");
  const Vec3 p(0.01, 0.02, 0.0);
  const Eigen::Matrix3d r2 =
      Eigen::AngleAxisd(-2.0 * M_PI * 100 * 1e-5 / 0.5, Vec3(1, 1, 0).normalized()).toRotationMatrix();
  worst = 0;
  for (int k = 0; k < mesh.nnodes(); ++k)
    worst = std::max(worst, (mesh.node(k) - (p + r2 * (x1[k] - p))).norm());
  CHECK(worst < 1e-15);
  REQUIRE_THROWS_WITH(s.cmd("fix bad all move/mesh mesh cad rotate origin 0 0 0 axis 0 0 0 period 1"),
                      Contains("axis"));
}

TEST_CASE("mesh/surface/planar: the same wall as mesh/surface for a planar mesh, an error for another",
          "[mesh]") {
  // a sphere dropped at a slant on the floor: the same trajectory bit for bit
  Vec3 x[2];
  const char* styles[2] = {"mesh/surface", "mesh/surface/planar"};
  for (int k = 0; k < 2; ++k) {
    ScriptEngine s;
    s.cmds(scene());
    s.cmds({"create_atoms 1 single 0.01 0.0 0.02 units box",
            "set group all diameter 0.01 density 2500 vx 0.2",
            "fix gravi all gravity 9.81 vector 0.0 0.0 -1.0",
            "fix cad all " + std::string(styles[k]) + " file " + floor_file() + " type 2",
            "fix floor all wall/gran model hertz tangential history mesh n_meshes 1 meshes cad",
            "fix integr all nve/sphere", "run 8000"});
    x[k] = s.p().x[0];
  }
  CHECK(x[0] == x[1]);
  CHECK(x[0].z() > 0.004);  // the floor stopped it (free fall would be at -0.011 m)
  // a floor with a raised cell, and a floor with a triangle facing down (parallel: planar)
  std::vector<Triangle> bent, flipped;
  mesh_files::add_rectangle(bent, Vec3(-0.06, -0.06, 0), Vec3(0.12, 0, 0), Vec3(0, 0.12, 0), 2, 2);
  flipped = bent;
  bent.back()[2] += Vec3(0, 0, 1e-3);
  std::swap(flipped.back()[1], flipped.back()[2]);
  mesh_files::write_ascii(kDir + "/bent.stl", bent);
  mesh_files::write_ascii(kDir + "/flipped.stl", flipped);
  ScriptEngine s;
  s.cmds(scene());
  CHECK_THROWS_WITH(s.cmd("fix bent all mesh/surface/planar file " + kDir + "/bent.stl type 2"),
                    Contains("is not planar: node") && Contains("use fix mesh/surface for this mesh"));
  s.cmd("fix flat all mesh/surface/planar file " + kDir + "/flipped.stl type 2");
}

TEST_CASE("mesh/surface surface_vel: a conveyor belt drags a sphere to 2/7 of its speed", "[mesh]") {
  ScriptEngine s;
  s.cmds(scene());
  s.cmds(sphere_on_floor(0.0, 0.0));
  // the belt velocity has a normal part, which is dropped (speed kept: 0.1 m/s along x)
  s.cmds({"fix cad all mesh/surface file " + floor_file() + " type 2 surface_vel 0.08 0.0 0.06",
          "fix floor all wall/gran model hertz tangential history mesh n_meshes 1 meshes cad",
          "fix integr all nve/sphere"});
  const auto& mesh = mesh_of(s, "cad");
  const Vec3 n0 = mesh.node(0);
  s.cmd("run 3000");
  CHECK(mesh.node(0) == n0);  // the nodes stay
  CHECK(s.p().v[0][0] == Approx(2.0 / 7.0 * 0.1).epsilon(0.01));
  CHECK(std::fabs(s.p().v[0][1]) < 1e-12);
  CHECK(s.p().v[0][0] - 0.005 * s.p().omega[0][1] == Approx(0.1).epsilon(0.01));
}

TEST_CASE("mesh/surface/stress reports the force and torque of a resting sphere", "[mesh]") {
  ScriptEngine s;
  s.cmds(scene());
  // on the centroid of a triangle (cell x 0.02..0.04, y -0.02..0 cut along its
  // rising diagonal): the torque takes the force at the contact point, under the centre
  const double cx = 0.02 + 0.04 / 3.0, cy = -0.02 + 0.02 / 3.0;
  s.cmds(sphere_on_floor(cx, cy));
  s.cmds({"fix cad all mesh/surface/stress file " + floor_file() +
              " type 2 move 0 0 1 move 0 0 -1 reference_point 0.01 0.0 0.0",
          "fix floor all wall/gran model hertz tangential history mesh n_meshes 1 meshes cad",
          "fix integr all nve/sphere", "dump d all mesh/vtk 20000 " + kDir + "/stress_*.vtp cad",
          "run 20000"});
  const double mg = 2500 * 4.0 / 3.0 * M_PI * 1.25e-7 * 9.81;
  // at rest: the mesh carries the weight
  CHECK(s.e.fix_value("cad", 1) == Approx(0.0).margin(1e-6 * mg));
  CHECK(s.e.fix_value("cad", 3) == Approx(-mg).epsilon(1e-3));
  // torque about (0.01, 0, 0) of the weight at the centroid: (cx - 0.01, cy, 0) x (0, 0, -mg)
  CHECK(s.e.fix_value("cad", 4) == Approx(-cy * mg).epsilon(1e-3));
  CHECK(s.e.fix_value("cad", 5) == Approx((cx - 0.01) * mg).epsilon(1e-3));
  CHECK(s.e.fix_value("cad", 7) == Approx(0.01));  // the reference point moved with the mesh
  CHECK(s.e.fix_value("cad", 9) == Approx(0.0).margin(1e-15));
  // dump mesh/vtk: pressure times area sums to the weight
  auto reader = vtkSmartPointer<vtkXMLPolyDataReader>::New();
  reader->SetFileName((kDir + "/stress_20000.vtp").c_str());
  reader->Update();
  vtkPolyData* pd = reader->GetOutput();
  vtkDataArray* pr = pd->GetCellData()->GetArray("pressure");
  vtkDataArray* area = pd->GetCellData()->GetArray("area");
  vtkDataArray* shear = pd->GetCellData()->GetArray("shear_stress");
  REQUIRE(pr);
  REQUIRE(area);
  REQUIRE(shear);
  double load = 0, tangential = 0;
  for (vtkIdType c = 0; c < pd->GetNumberOfCells(); ++c) {
    load += pr->GetTuple1(c) * area->GetTuple1(c);
    tangential += shear->GetTuple1(c) * area->GetTuple1(c);
  }
  CHECK(load == Approx(mg).epsilon(1e-3));
  CHECK(tangential < 1e-3 * mg);
  REQUIRE_THROWS_WITH(s.cmd("fix w all mesh/surface/stress file " + floor_file() + " type 1 wear archard"),
                      Contains("not a wear model"));
  REQUIRE_THROWS_WITH(s.cmd("fix w all mesh/surface file " + floor_file() + " type 1 wear off"),
                      Contains("unknown keyword 'wear'"));
}

TEST_CASE("dump mesh/stl writes the current mesh as ASCII STL that reads back", "[mesh]") {
  ScriptEngine s;
  s.cmds(scene());
  s.cmds({"fix cad all mesh/surface file " + floor_file() + " type 2 rotate axis 1 0 0 angle 30",
          "fix spin all move/mesh mesh cad rotate origin 0.0 0.0 0.0 axis 0 1 0 period 0.3",
          "fix other all mesh/surface file " + floor_file() + " type 1 move 0 0 0.02",
          "dump d all mesh/stl 10 " + kDir + "/mesh*.stl cad",
          "dump d2 all mesh/stl 10 " + kDir + "/all*.stl", "run 10"});
  s.cmd("fix back all mesh/surface file " + kDir + "/mesh10.stl type 2");
  const auto& a = mesh_of(s, "cad");
  const auto& b = mesh_of(s, "back");
  REQUIRE(b.ntri() == a.ntri());
  REQUIRE(b.nnodes() == a.nnodes());
  double worst = 0;
  for (int t = 0; t < a.ntri(); ++t)
    for (int c = 0; c < 3; ++c)
      worst = std::max(worst, (a.corner(t, c) - b.corner(t, c)).norm());
  CHECK(worst < 1e-7);  // the STL reader keeps single precision
  // without mesh IDs: every mesh, one solid each
  s.cmd("fix back2 all mesh/surface file " + kDir + "/all10.stl type 2");
  CHECK(mesh_of(s, "back2").ntri() == a.ntri() + mesh_of(s, "other").ntri());
  REQUIRE_THROWS_WITH(s.cmd("dump e all mesh/stl 10 " + kDir + "/x*.stl nosuchmesh"), Contains("nosuchmesh"));
}
