// Mesh walls: fix mesh/surface, fix wall/gran mesh, fix move/mesh, dump mesh/vtk.
#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataReader.h>
#include <vtkSmartPointer.h>
#include <vtkXMLPolyDataReader.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "core/error.h"
#include "fix/fix_mesh_surface.h"
#include "fix/fix_wall_gran.h"
#include "core/modify.h"
#include "mesh_files.h"
#include "script_engine.h"

using granary::Vec3;
using granary::test::ScriptEngine;
using mesh_files::Triangle;

namespace {

const std::string kDir = mesh_files::temp_dir();

std::string path(const std::string& name) {
  return kDir + "/" + name;
}

// A 0.12 m square floor at z = 0 made of 6 x 6 cells (72 triangles).
std::string floor_file() {
  static const std::string f = [] {
    std::vector<Triangle> t;
    mesh_files::add_rectangle(t, Vec3(-0.06, -0.06, 0), Vec3(0.12, 0, 0), Vec3(0, 0.12, 0), 6, 6);
    mesh_files::write_ascii(path("floor.stl"), t);
    return path("floor.stl");
  }();
  return f;
}

std::vector<std::string> scene(double mu_r = 0.1, const std::string& rolling = "rolling_friction cdt") {
  return {
      "units si",
      "atom_style granular",
      "boundary f f f",
      "region box block -0.07 0.07 -0.07 0.07 -0.03 0.05 units box",
      "create_box 2 box",
      "neighbor 0.001 bin",
      "neigh_modify delay 0",
      granary::test::materials(2, 5.e6, 0.45, 0.5, 0.5),
      "fix m5 all property/global coefficientRollingFriction peratomtypepair 2 " + std::to_string(mu_r) +
          " " + std::to_string(mu_r) + " " + std::to_string(mu_r) + " " + std::to_string(mu_r),
      "pair_style gran model hertz tangential history " + rolling,
      "pair_coeff * *",
      "timestep 1e-5",
  };
}

struct Body {
  Vec3 x, v, w;
};
Body body(const ScriptEngine& s, int i = 0) {
  return {s.p().x[i], s.p().v[i], s.p().omega[i]};
}

double rel(const Vec3& a, const Vec3& b) {
  return (a - b).norm() / std::max(1e-30, b.norm());
}

granary::FixMeshSurface& mesh_fix(ScriptEngine& s, const std::string& id) {
  return granary::FixMeshSurface::find(*s.e.modify, id, "test");
}

const std::string kWallModel = "wall/gran model hertz tangential history rolling_friction cdt ";

/// The message of the InputError a script line raises, or "no error".
std::string error_of(ScriptEngine& s, const std::string& line) {
  try {
    s.cmd(line);
  } catch (const granary::InputError& e) {
    return std::string(e.what());
  }
  return std::string("no error");
}

}  // namespace

TEST_CASE("a sphere sliding and rolling over a floor of 72 triangles moves as on a zplane wall", "[mesh]") {
  // One sphere starts on the floor with a tangential velocity and a spin; it
  // slides, spins up and rolls across several triangle edges (cells are 2 cm,
  // it travels more than 4 cm). Only a plane-like contact, with its tangential
  // history carried from triangle to triangle, gives the primitive wall's
  // trajectory; the tolerance 1e-12 allows round-off only.
  std::vector<Body> ref, mesh;
  for (int variant = 0; variant < 2; ++variant) {
    ScriptEngine s;
    s.cmds(scene());
    s.cmds({"create_atoms 1 single 0.003 -0.002 0.00499 units box",
            "set group all diameter 0.01 density 2500", "velocity all set 0.9 0.35 0.0 units box",
            "set group all omega 10 -30 5", "fix gravi all gravity 9.81 vector 0.0 0.0 -1.0"});
    if (variant == 0) {
      s.cmd("fix floor all " + kWallModel + "primitive type 2 zplane 0.0");
    } else {
      s.cmd("fix cad all mesh/surface file " + floor_file() + " type 2");
      s.cmd("fix floor all " + kWallModel + "mesh n_meshes 1 meshes cad");
    }
    s.cmd("fix integr all nve/sphere");
    auto& out = variant == 0 ? ref : mesh;
    for (int k = 0; k < 12; ++k) {
      s.cmd("run 500");
      out.push_back(body(s));
    }
  }
  REQUIRE(ref.back().x[0] - 0.003 > 0.045);            // crossed at least two rows of cells
  REQUIRE(std::fabs(ref.back().x[2] - 0.005) < 1e-4);  // in contact all along
  double worst = 0;
  for (std::size_t k = 0; k < ref.size(); ++k) {
    worst = std::max({worst, rel(mesh[k].x, ref[k].x), rel(mesh[k].v, ref[k].v), rel(mesh[k].w, ref[k].w)});
  }
  INFO("largest relative difference " << worst);
  CHECK(worst < 1e-12);
}

// unfix frees a mesh wall's per-particle contact slots (shutters are opened by
// replacing the wall fix, so each replacement would otherwise keep its slots);
// a wall defined again with the same ID starts with fresh, empty history.
TEST_CASE("unfix of a mesh wall frees its per-particle contact history", "[mesh]") {
  ScriptEngine s;
  s.cmds(scene());
  s.cmds({"create_atoms 1 single 0.003 -0.002 0.00499 units box", "set group all diameter 0.01 density 2500",
          "velocity all set 0.9 0.35 0.0 units box", "fix gravi all gravity 9.81 vector 0.0 0.0 -1.0",
          "fix cad all mesh/surface file " + floor_file() + " type 2",
          "fix floor all " + kWallModel + "mesh n_meshes 1 meshes cad", "fix integr all nve/sphere",
          "run 200"});
  const auto& p = s.p();
  const std::string slots =
      "mesh_wall_history/floor/" + std::to_string(granary::FixWallGran::kInlineSlots) + "/3";
  REQUIRE(p.find_field(slots) >= 0);
  CHECK(p.extras[p.find_field(slots)].data[4] != 0.0);  // a sliding contact holds shear history
  const std::size_t nfields = p.extras.size();
  s.cmd("unfix floor");
  CHECK(p.find_field(slots) < 0);
  CHECK(p.find_field("mesh_wall_contacts/floor") < 0);
  std::size_t held = 0;
  for (const auto& f : p.extras)
    held += f.data.capacity();
  s.cmd("fix floor all " + kWallModel + "mesh n_meshes 1 meshes cad");
  REQUIRE(p.find_field(slots) >= 0);
  CHECK(p.extras.size() == nfields + 2);
  CHECK(p.extras[p.find_field(slots)].data[4] == 0.0);  // fresh history
  s.cmd("run 200");
  CHECK(std::fabs(p.x[0][2] - 0.005) < 1e-4);  // still resting on the floor
  INFO("doubles held by extra fields after unfix: " << held);
  CHECK(held < 20);
}

TEST_CASE("a sphere on a convex edge is pushed away from the closest point", "[mesh]") {
  // Top plate z = 0 for x < 0, and a vertical face x = 0 below it: the edge is
  // the y axis. The sphere centre (3, 0, 2) mm, radius 5 mm, sees only the edge:
  // one Hertz contact along (3, 0, 2)/|.|, overlap r - |(3, 0, 2)| mm.
  std::vector<Triangle> t;
  mesh_files::add_rectangle(t, Vec3(-0.04, -0.04, 0), Vec3(0.04, 0, 0), Vec3(0, 0.08, 0), 2, 3);
  mesh_files::add_rectangle(t, Vec3(0, -0.04, 0), Vec3(0, 0, -0.02), Vec3(0, 0.08, 0), 2, 3);
  mesh_files::write_ascii(path("step.stl"), t);
  ScriptEngine s;
  s.cmds(scene());
  s.cmds({"create_atoms 1 single 0.003 0.001 0.002 units box", "set group all diameter 0.01 density 2500",
          "fix cad all mesh/surface file " + path("step.stl") + " type 2",
          "fix wall all " + kWallModel + "mesh n_meshes 1 meshes cad", "fix integr all nve/sphere", "run 0"});
  const Vec3 d(0.003, 0.0, 0.002);
  const double delta = 0.005 - d.norm();
  const double Y = 1.0 / (2.0 * (1.0 - 0.45 * 0.45) / 5e6);
  const double fn = 4.0 / 3.0 * Y * std::sqrt(0.005 * delta) * delta;
  const Vec3 f = s.p().f[0];
  CHECK(rel(f, fn * d.normalized()) < 1e-12);
  CHECK(s.e.fix_value("wall", 3) == Approx(-f[2]).epsilon(1e-14));  // f_wall[3]: force on the mesh
}

TEST_CASE("a sphere in a concave corner feels two plane contacts", "[mesh]") {
  std::vector<Triangle> t;
  mesh_files::add_rectangle(t, Vec3(0, -0.04, 0), Vec3(0.04, 0, 0), Vec3(0, 0.08, 0), 3, 2);
  mesh_files::add_rectangle(t, Vec3(0, -0.04, 0), Vec3(0, 0, 0.04), Vec3(0, 0.08, 0), 3, 2);
  mesh_files::write_ascii(path("corner.stl"), t);
  Vec3 force[2], torque[2];
  for (int variant = 0; variant < 2; ++variant) {
    ScriptEngine s;
    s.cmds(scene());
    s.cmds({"create_atoms 1 single 0.0041 0.001 0.0043 units box", "set group all diameter 0.01 density 2500",
            "velocity all set 0.1 0.2 -0.1 units box", "set group all omega 3 1 -2"});
    if (variant == 0) {
      s.cmd("fix w1 all " + kWallModel + "primitive type 2 xplane 0.0");
      s.cmd("fix w2 all " + kWallModel + "primitive type 2 zplane 0.0");
    } else {
      s.cmd("fix cad all mesh/surface file " + path("corner.stl") + " type 2");
      s.cmd("fix w1 all " + kWallModel + "mesh n_meshes 1 meshes cad");
    }
    s.cmds({"fix integr all nve/sphere", "run 20"});
    force[variant] = s.p().f[0];
    torque[variant] = s.p().torque[0];
  }
  CHECK(force[0].norm() > 1.0);
  CHECK(rel(force[1], force[0]) < 1e-12);
  CHECK(rel(torque[1], torque[0]) < 1e-12);
}

TEST_CASE("mesh/surface reads ASCII and binary STL and applies scale, move, rotate in order", "[mesh]") {
  const std::vector<Triangle> one = {{Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 0)},
                                     {Vec3(1, 0, 0), Vec3(1, 1, 0.5), Vec3(0, 1, 0)}};
  mesh_files::write_ascii(path("t.stl"), one);
  mesh_files::write_binary(path("tb.stl"), one);
  ScriptEngine s;
  s.cmds(scene());
  s.cmd("fix a all mesh/surface file " + path("t.stl") + " type 1");
  s.cmd("fix b all mesh/surface file " + path("tb.stl") + " type 1 verbose no heal auto_remove_duplicates");
  const auto& ma = mesh_fix(s, "a").mesh;
  const auto& mb = mesh_fix(s, "b").mesh;
  REQUIRE(ma.ntri() == 2);
  REQUIRE(ma.nnodes() == 4);  // shared corners merged
  REQUIRE(mb.ntri() == 2);
  for (int t = 0; t < 2; ++t)
    for (int c = 0; c < 3; ++c) {
      CHECK(ma.corner(t, c) == one[t][c]);
      CHECK(mb.corner(t, c) == one[t][c]);
    }
  // scale 2 -> move (1, 0, 0) -> rotate 90 degrees about z: (x, y) -> (-y, x)
  s.cmd("fix c all mesh/surface file " + path("t.stl") +
        " type 1 scale 2 move 1 0 0 rotate axis 0 0 1 angle 90 curvature_tolerant yes");
  const auto& mc = mesh_fix(s, "c").mesh;
  const Vec3 expect[3] = {Vec3(0, 3, 0), Vec3(-2, 1, 0), Vec3(0, 1, 0)};
  for (int c = 0; c < 3; ++c)
    CHECK((mc.corner(0, c) - expect[c]).norm() < 1e-15);
  CHECK((mc.normal(0) - Vec3(0, 0, 1)).norm() < 1e-15);
}

TEST_CASE("mesh/surface refuses a binary STL cut inside a triangle or with bytes after its triangles",
          "[mesh]") {
  const std::vector<Triangle> two = {{Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 0)},
                                     {Vec3(1, 0, 0), Vec3(1, 1, 0.5), Vec3(0, 1, 0)}};
  const std::string whole = path("whole.stl"), cut = path("cut.stl"), longer = path("long.stl");
  mesh_files::write_binary(whole, two);
  REQUIRE(std::filesystem::file_size(whole) == 84 + 2 * 50);
  mesh_files::write_binary(cut, two);
  std::filesystem::resize_file(cut, 84 + 50 + 30);  // inside the second triangle
  mesh_files::write_binary(longer, two);
  {
    std::ofstream out(longer, std::ios::binary | std::ios::app);
    out << "extra";
  }
  ScriptEngine s;
  s.cmds(scene());
  s.cmd("fix ok all mesh/surface file " + whole + " type 1");
  CHECK(mesh_fix(s, "ok").mesh.ntri() == 2);
  const std::string e1 = error_of(s, "fix a all mesh/surface file " + cut + " type 1");
  CHECK_THAT(e1, Catch::Contains(cut) && Catch::Contains("is cut") && Catch::Contains("2 triangles") &&
                     Catch::Contains("triangle 2 ends at byte 164 instead of 184"));
  const std::string e2 = error_of(s, "fix b all mesh/surface file " + longer + " type 1");
  CHECK_THAT(e2, Catch::Contains(longer) && Catch::Contains("5 bytes after the 2 triangles"));
}

TEST_CASE("mesh/surface checks every file the reader takes for binary, also one that starts like ASCII",
          "[mesh]") {
  // an ASCII STL with binary bytes in its first 256: the reader takes it for a
  // binary STL and its bytes 80-83 for the triangle count (here 2^32 - 1),
  // which it would allocate for; it is refused before the reader runs
  std::string text =
      "solid x\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n"
      "   vertex 0 1 0\n  endloop\n endfacet\nendsolid x\n";
  text.resize(300, ' ');
  for (int k = 0; k < 4; ++k)
    text[80 + k] = static_cast<char>(0xff);
  for (int k = 100; k < 120; ++k)
    text[k] = static_cast<char>(0x01);
  const std::string file = path("mixed.stl");
  {
    std::ofstream out(file, std::ios::binary);
    out << text;
  }
  ScriptEngine s;
  s.cmds(scene());
  const std::string e = error_of(s, "fix m all mesh/surface file " + file + " type 1");
  CHECK_THAT(e, Catch::Contains(file) && Catch::Contains("starts like an ASCII STL") &&
                    Catch::Contains("announces 4294967295 triangles"));
}

TEST_CASE("mesh/surface refuses missing, malformed, empty and degenerate files with the file name",
          "[mesh]") {
  ScriptEngine s;
  s.cmds(scene());
  const std::string missing = path("nothere.stl");
  CHECK_THAT(error_of(s, "fix a all mesh/surface file " + missing + " type 1"), Catch::Contains(missing));
  { std::ofstream(path("bad.stl")) << "solid x\n facet normal 0 0 1\n outer loop\n vertex 0 0 zero\n"; }
  CHECK_THAT(error_of(s, "fix a all mesh/surface file " + path("bad.stl") + " type 1"),
             Catch::Contains(path("bad.stl")));
  { std::ofstream(path("empty.stl")) << "solid x\nendsolid x\n"; }
  CHECK_THAT(error_of(s, "fix a all mesh/surface file " + path("empty.stl") + " type 1"),
             Catch::Contains(path("empty.stl")));
  mesh_files::write_ascii(path("degenerate.stl"), {{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0)}});
  const std::string deg = error_of(s, "fix a all mesh/surface file " + path("degenerate.stl") + " type 1");
  CHECK_THAT(deg, Catch::Contains(path("degenerate.stl")) && Catch::Contains("degenerate"));
  CHECK_THAT(error_of(s, "fix a all mesh/surface file " + floor_file() + " type 1 wiggle 3"),
             Catch::Contains("unknown keyword 'wiggle'"));
  CHECK_THAT(error_of(s, "fix a all mesh/surface file " + floor_file()), Catch::Contains("type"));
  CHECK(s.e.modify->find_fix("a") == nullptr);
}

TEST_CASE("mesh/surface reads ASCII STL in any case and several solids, and names the line of a mistake",
          "[mesh]") {
  ScriptEngine s;
  s.cmds(scene());
  const std::string facet =
      " FACET NORMAL 0 0 1\n  OUTER LOOP\n   VERTEX 0 0 0\n   VERTEX 1 0 0\n   VERTEX 0 1 0\n  ENDLOOP\n"
      " ENDFACET\n";
  const std::string two = path("two_solids.stl");
  std::ofstream(two)
      << "SOLID a b c\n" + facet + "ENDSOLID a\nsolid\n" +
             " facet normal 0 0 1\n outer loop\n vertex 1 0 0\n vertex 1 1 0.5\n vertex 0 1 0\n"
             " endloop\n endfacet\nendsolid\n";
  s.cmd("fix two all mesh/surface file " + two + " type 1");
  const auto& mesh = mesh_fix(s, "two").mesh;
  REQUIRE(mesh.ntri() == 2);
  CHECK(mesh.corner(1, 1) == Vec3(1, 1, 0.5));
  // single precision, as a binary STL holds the coordinates
  std::ofstream(path("tenth.stl")) << "solid t\n facet normal 0 0 1\n outer loop\n vertex 0.1 0 0\n"
                                      " vertex 1 0 0\n vertex 0 1 0\n endloop\n endfacet\nendsolid t\n";
  s.cmd("fix tenth all mesh/surface file " + path("tenth.stl") + " type 1");
  CHECK(mesh_fix(s, "tenth").mesh.corner(0, 0)[0] == static_cast<double>(0.1f));

  auto refused = [&](const std::string& name, const std::string& text) {
    std::ofstream(path(name)) << text;
    return error_of(s, "fix bad all mesh/surface file " + path(name) + " type 1");
  };
  CHECK_THAT(refused("word.stl", "solid x\n facet normal 0 0 1\n outer loop\n vertex 0 0 zero\n"),
             Catch::Contains("line 4") && Catch::Contains("'zero' is not a finite number"));
  CHECK_THAT(refused("quad.stl",
                     "solid q\n facet normal 0 0 1\n outer loop\n vertex 0 0 0\n vertex 1 0 0\n"
                     " vertex 1 1 0\n vertex 0 1 0\n endloop\n endfacet\nendsolid q\n"),
             Catch::Contains("line 7") && Catch::Contains("more than three vertices"));
  CHECK_THAT(refused("noloop.stl", "solid n\n facet normal 0 0 1\n vertex 0 0 0\n"),
             Catch::Contains("line 3") && Catch::Contains("expected 'outer', found 'vertex'"));
  CHECK_THAT(refused("open.stl", "solid o\n" + facet), Catch::Contains("expected 'endsolid', found the end"));
  CHECK_THAT(refused("blank.stl", "\n\n"), Catch::Contains("is empty"));
  CHECK_THAT(refused("inf.stl", "solid i\n facet normal 0 0 1\n outer loop\n vertex 0 0 1e60\n"),
             Catch::Contains("line 4") && Catch::Contains("'1e60' is not a finite number"));
  CHECK(s.e.modify->find_fix("bad") == nullptr);
}

TEST_CASE("move/mesh linear moves the mesh by V t and a belt drags a sphere to 2/7 of its speed", "[mesh]") {
  // In the belt's frame the sphere slides backwards at V and ends rolling at
  // 5/7 of that (angular momentum about the contact point is conserved), so in
  // the lab it ends at V - 5/7 V = 2/7 V. The lever arm r - delta/2 makes this
  // exact only to O(delta/r) ~ 1e-3; tolerance 1%.
  ScriptEngine s;
  s.cmds(scene(0.0, ""));
  s.cmds({"create_atoms 1 single 0.0 0.0 0.00499 units box", "set group all diameter 0.01 density 2500",
          "fix gravi all gravity 9.81 vector 0.0 0.0 -1.0",
          "fix cad all mesh/surface file " + floor_file() + " type 2",
          "fix belt all move/mesh mesh cad linear 0.1 0.0 0.0",
          "fix floor all wall/gran model hertz tangential history mesh n_meshes 1 meshes cad",
          "fix integr all nve/sphere"});
  const auto& mesh = mesh_fix(s, "cad").mesh;
  std::vector<Vec3> x0;
  for (int k = 0; k < mesh.nnodes(); ++k)
    x0.push_back(mesh.node(k));
  s.cmd("run 3000");
  double worst = 0;
  for (int k = 0; k < mesh.nnodes(); ++k)
    worst = std::max(worst, (mesh.node(k) - (x0[k] + Vec3(0.1 * 0.03, 0, 0))).norm());
  CHECK(worst < 1e-16);
  CHECK(s.p().v[0][0] == Approx(2.0 / 7.0 * 0.1).epsilon(0.01));
  CHECK(std::fabs(s.p().v[0][1]) < 1e-12);
  // rolling on the belt: contact point moves with the belt
  CHECK(s.p().v[0][0] - 0.005 * s.p().omega[0][1] == Approx(0.1).epsilon(0.01));
  // after unfix the mesh stands still
  s.cmd("unfix belt");
  const Vec3 n0 = mesh.node(0);
  s.cmd("run 100");
  CHECK(mesh.node(0) == n0);
  CHECK(mesh.velocity.norm() == 0.0);
}

TEST_CASE("dump mesh/vtk writes the triangles, normals and velocity as VTK PolyData", "[mesh]") {
  ScriptEngine s;
  s.cmds(scene());
  s.cmds({"fix cad all mesh/surface file " + floor_file() + " type 2 rotate axis 1 0 0 angle 30",
          "fix belt all move/mesh mesh cad linear 0.0 0.1 0.2",
          "dump d all mesh/vtk 10 " + path("mesh_*.vtp") + " cad", "run 10"});
  const auto& mesh = mesh_fix(s, "cad").mesh;
  auto reader = vtkSmartPointer<vtkXMLPolyDataReader>::New();
  reader->SetFileName(path("mesh_10.vtp").c_str());
  reader->Update();
  vtkPolyData* pd = reader->GetOutput();
  REQUIRE(pd->GetNumberOfPolys() == mesh.ntri());
  REQUIRE(pd->GetNumberOfPoints() == mesh.nnodes());
  double worst = 0;
  for (int k = 0; k < mesh.nnodes(); ++k) {
    double p[3];
    pd->GetPoint(k, p);
    worst = std::max(worst, (Vec3(p[0], p[1], p[2]) - mesh.node(k)).norm());
  }
  CHECK(worst == 0.0);
  vtkDataArray* n = pd->GetCellData()->GetArray("normal");
  vtkDataArray* v = pd->GetCellData()->GetArray("velocity");
  REQUIRE(n);
  REQUIRE(v);
  for (int t = 0; t < mesh.ntri(); ++t) {
    const double* nn = n->GetTuple3(t);
    CHECK(Vec3(nn[0], nn[1], nn[2]) == mesh.normal(t));
    const double* vv = v->GetTuple3(t);
    CHECK(Vec3(vv[0], vv[1], vv[2]) == Vec3(0.0, 0.1, 0.2));
  }
  CHECK(std::filesystem::exists(path("mesh_.pvd")));

  // write_dump: the current state once, one file, no collection; the dump's collection is untouched
  const auto pvd_time = std::filesystem::last_write_time(path("mesh_.pvd"));
  const auto pvd_size = std::filesystem::file_size(path("mesh_.pvd"));
  s.cmds({"write_dump all mesh/vtk " + path("mesh_now.vtp") + " cad"});
  auto now = vtkSmartPointer<vtkXMLPolyDataReader>::New();
  now->SetFileName(path("mesh_now.vtp").c_str());
  now->Update();
  CHECK(now->GetOutput()->GetNumberOfPolys() == mesh.ntri());
  CHECK_FALSE(std::filesystem::exists(path("mesh_now.pvd")));
  CHECK(std::filesystem::last_write_time(path("mesh_.pvd")) == pvd_time);
  CHECK(std::filesystem::file_size(path("mesh_.pvd")) == pvd_size);
}

// A 1 cm sphere resting on the floor (gravity, 2000 steps of 10 us): the
// legacy .vtk frame (LIGGGHTS' file name) holds the same triangles; on every
// triangle stress_components x area = force and pressure = -stress . normal;
// the summed force carries the sphere's weight. A .pvd list is refused for
// legacy frames.
TEST_CASE("dump mesh/vtk with a .vtk name writes legacy VTK with the stress components", "[mesh]") {
  ScriptEngine s;
  s.cmds(scene());
  s.cmds({"fix cad all mesh/surface file " + floor_file() + " type 2",
          "fix floor all " + kWallModel + "mesh n_meshes 1 meshes cad",
          "fix gravi all gravity 9.81 vector 0 0 -1", "create_atoms 1 single 0.001 0.002 0.00499 units box",
          "set group all diameter 0.01 density 2500", "fix integr all nve/sphere",
          "dump d all mesh/vtk 2000 " + path("legacy_*.vtk") + " id stress stresscomponents cad",
          "run 2000"});
  const auto& mesh = mesh_fix(s, "cad").mesh;
  REQUIRE(std::filesystem::exists(path("legacy_2000.vtk")));
  CHECK_FALSE(std::filesystem::exists(path("legacy_.pvd")));
  auto reader = vtkSmartPointer<vtkPolyDataReader>::New();
  reader->SetFileName(path("legacy_2000.vtk").c_str());
  reader->Update();
  vtkPolyData* pd = reader->GetOutput();
  REQUIRE(pd->GetNumberOfPolys() == mesh.ntri());
  vtkDataArray* force = pd->GetCellData()->GetArray("force");
  vtkDataArray* stress = pd->GetCellData()->GetArray("stress_components");
  vtkDataArray* area = pd->GetCellData()->GetArray("area");
  vtkDataArray* pressure = pd->GetCellData()->GetArray("pressure");
  REQUIRE(force);
  REQUIRE(stress);
  REQUIRE(area);
  REQUIRE(pressure);
  Vec3 total(0, 0, 0);
  for (int t = 0; t < mesh.ntri(); ++t) {
    const double* f = force->GetTuple3(t);
    const Vec3 fv(f[0], f[1], f[2]);
    const double* sc = stress->GetTuple3(t);
    const Vec3 sv(sc[0], sc[1], sc[2]);
    const double a = area->GetTuple1(t);
    CHECK((sv * a - fv).norm() <= 1e-12 * std::max(1.0, fv.norm()));
    CHECK(pressure->GetTuple1(t) == Approx(-sv.dot(mesh.normal(t))).margin(1e-9));
    total += fv;
  }
  const double weight = 2500 * 4.0 / 3.0 * 3.14159265358979323846 * 0.005 * 0.005 * 0.005 * 9.81;
  CHECK(total.z() == Approx(-weight).epsilon(0.05));  // at rest after the first bounces (restitution 0.5)
  CHECK_THROWS_WITH(s.cmd("dump_modify d pvd " + path("legacy.pvd")),
                    Catch::Contains("legacy .vtk files cannot be listed in a .pvd"));
}

// Two meshes, the floor with a 1 cm sphere resting on it and a lid above:
// dump mesh/vtm writes FRAME.vtm listing FRAME/FRAME_0.vtp and
// FRAME/FRAME_1.vtp (LIGGGHTS' layout), blocks named by the mesh IDs, each
// with its own triangles; the floor's forces carry the sphere's weight and
// equal those of dump mesh/vtk at the same step; the lid's are zero.
TEST_CASE("dump mesh/vtm writes one block per mesh, as LIGGGHTS lays it out", "[mesh]") {
  ScriptEngine s;
  s.cmds(scene());
  s.cmds({"fix cad all mesh/surface file " + floor_file() + " type 2",
          "fix lid all mesh/surface file " + floor_file() + " type 2 move 0 0 0.04",
          "fix floor all " + kWallModel + "mesh n_meshes 2 meshes cad lid",
          "fix gravi all gravity 9.81 vector 0 0 -1", "create_atoms 1 single 0.001 0.002 0.00499 units box",
          "set group all diameter 0.01 density 2500", "fix integr all nve/sphere",
          "dump d all mesh/vtm 2000 " + path("blocks*.vtm") + " meshes all mesh_properties id stress",
          "dump v all mesh/vtk 2000 " + path("flat_*.vtp") + " cad lid", "run 2000"});
  REQUIRE(std::filesystem::exists(path("blocks2000.vtm")));
  std::ifstream in(path("blocks2000.vtm"));
  const std::string xml((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CHECK_THAT(xml,
             Catch::Contains("<DataSet index=\"0\" name=\"cad\" file=\"blocks2000/blocks2000_0.vtp\"/>"));
  CHECK_THAT(xml,
             Catch::Contains("<DataSet index=\"1\" name=\"lid\" file=\"blocks2000/blocks2000_1.vtp\"/>"));
  CHECK(std::filesystem::exists(path("blocks.pvd")));
  auto flat = vtkSmartPointer<vtkXMLPolyDataReader>::New();
  flat->SetFileName(path("flat_2000.vtp").c_str());
  flat->Update();
  vtkDataArray* fall = flat->GetOutput()->GetCellData()->GetArray("force");
  REQUIRE(fall);
  const auto& mesh = mesh_fix(s, "cad").mesh;
  Vec3 total[2] = {Vec3(0, 0, 0), Vec3(0, 0, 0)};
  for (int b = 0; b < 2; ++b) {
    auto reader = vtkSmartPointer<vtkXMLPolyDataReader>::New();
    reader->SetFileName(path("blocks2000/blocks2000_" + std::to_string(b) + ".vtp").c_str());
    reader->Update();
    vtkPolyData* pd = reader->GetOutput();
    REQUIRE(pd->GetNumberOfPolys() == mesh.ntri());
    REQUIRE(pd->GetNumberOfPoints() == mesh.nnodes());
    vtkDataArray* force = pd->GetCellData()->GetArray("force");
    REQUIRE(force);
    for (int t = 0; t < mesh.ntri(); ++t) {
      const double* f = force->GetTuple3(t);
      total[b] += Vec3(f[0], f[1], f[2]);
      const double* g = fall->GetTuple3(b * mesh.ntri() + t);
      CHECK(Vec3(f[0], f[1], f[2]) == Vec3(g[0], g[1], g[2]));
    }
    double p[3];
    pd->GetPoint(0, p);
    CHECK(p[2] == Approx(b == 0 ? 0.0 : 0.04).margin(1e-15));
  }
  const double weight = 2500 * 4.0 / 3.0 * 3.14159265358979323846 * 0.005 * 0.005 * 0.005 * 9.81;
  CHECK(total[0].z() == Approx(-weight).epsilon(0.05));
  CHECK(total[1].norm() == 0.0);
  CHECK_THAT(error_of(s, "dump e all mesh/vtm 10 " + path("x*.vtk") + " meshes all"),
             Catch::Contains("must end in .vtm"));
  CHECK_THAT(error_of(s, "dump e all mesh/vtm 10 " + path("x*.vtm") + " cad"),
             Catch::Contains("expected 'meshes all' or 'meshes ID ...'"));
  CHECK_THAT(error_of(s, "dump e all mesh/vtm 10 " + path("x*.vtm") + " meshes nosuch"),
             Catch::Contains("'nosuch' is neither the ID of a fix mesh/surface after 'meshes'"));
}

TEST_CASE("mesh contact history and a moved mesh survive write_restart and read_restart", "[mesh][restart]") {
  // A sphere sliding on a moving belt of 72 triangles: the run split by a
  // restart file continues bit for bit (history slots and node positions).
  auto setup = [&](ScriptEngine& s) {
    s.cmds({"fix gravi all gravity 9.81 vector 0.0 0.0 -1.0",
            "fix cad all mesh/surface file " + floor_file() + " type 2",
            "fix belt all move/mesh mesh cad linear 0.3 -0.1 0.0",
            "fix floor all " + kWallModel + "mesh n_meshes 1 meshes cad", "fix integr all nve/sphere"});
  };
  auto fresh = [&](ScriptEngine& s) {
    s.cmds(scene());
    s.cmds({"create_atoms 1 single 0.001 0.002 0.00499 units box",
            "create_atoms 1 single 0.02 0.01 0.005 units box", "set group all diameter 0.01 density 2500",
            "velocity all set -0.4 0.2 0.0 units box"});
    setup(s);
  };
  Body straight[2], restarted[2];
  Vec3 node_straight, node_restarted;
  {
    ScriptEngine s;
    fresh(s);
    s.cmd("run 2000");
    for (int i = 0; i < 2; ++i)
      straight[s.p().id[i] - 1] = body(s, i);
    node_straight = mesh_fix(s, "cad").mesh.node(0);
  }
  const std::string file = path("mesh.restart");
  {
    ScriptEngine s;
    fresh(s);
    s.cmd("run 1000");
    s.cmd("write_restart " + file);
  }
  {
    ScriptEngine s;
    s.cmds({"atom_style granular", "read_restart " + file});
    for (const auto& l : scene())
      if (l.rfind("fix m", 0) == 0 || l.rfind("pair", 0) == 0 || l.rfind("timestep", 0) == 0 ||
          l.rfind("neigh", 0) == 0)
        s.cmd(l);
    setup(s);
    s.cmd("run 1000");
    for (int i = 0; i < 2; ++i)
      restarted[s.p().id[i] - 1] = body(s, i);
    node_restarted = mesh_fix(s, "cad").mesh.node(0);
  }
  CHECK(node_restarted == node_straight);
  for (int i = 0; i < 2; ++i) {
    CHECK(restarted[i].x == straight[i].x);
    CHECK(restarted[i].v == straight[i].v);
    CHECK(restarted[i].w == straight[i].w);
  }
}

// Spheres wedged in a channel narrower than they are (side walls at
// y = +-2^-10 m, 1 um inside the radius) touch the floor and both walls:
// three contacts, the ones beyond the inline slot kept in the wall fix's table
// of extra slots, which goes into the restart file.
std::string channel_file() {
  static const std::string f = [] {
    std::vector<Triangle> t;
    const double w = 0.0009765625, l = 0.04, h = 0.004;
    mesh_files::add_rectangle(t, Vec3(0, -w, 0), Vec3(l, 0, 0), Vec3(0, 2 * w, 0), 8, 1);
    mesh_files::add_rectangle(t, Vec3(0, -w, 0), Vec3(l, 0, 0), Vec3(0, 0, h), 8, 1);
    mesh_files::add_rectangle(t, Vec3(0, w, 0), Vec3(l, 0, 0), Vec3(0, 0, h), 8, 1);
    mesh_files::write_ascii(path("channel.stl"), t);
    return path("channel.stl");
  }();
  return f;
}
void channel_setup(ScriptEngine& s) {
  // friction 0.1: the wedged spheres keep sliding on all three faces
  s.cmds({"fix m4 all property/global coefficientFriction peratomtypepair 2 0.1 0.1 0.1 0.1",
          "fix gravi all gravity 9.81 vector 1.0 0.0 -1.0",
          "fix cad all mesh/surface file " + channel_file() + " type 2",
          "fix walls all " + kWallModel + "mesh n_meshes 1 meshes cad", "fix integr all nve/sphere"});
}
void channel_fresh(ScriptEngine& s) {
  s.cmds(scene(0.1));
  s.cmds({"create_atoms 1 single 0.002 0.0 0.0009774625 units box",
          "create_atoms 1 single 0.006 0.0 0.0009774625 units box",
          "set group all diameter 0.001955125 density 2500", "velocity all set 0.4 0.0 0.0 units box"});
  channel_setup(s);
}
// the fewest mesh contacts of a particle
int channel_contacts(const ScriptEngine& s) {
  const auto& p = s.p();
  const int f = p.find_field("mesh_wall_contacts/walls");
  REQUIRE(f >= 0);
  int least = 100;
  for (int i = 0; i < p.nlocal; ++i)
    least = std::min(least, static_cast<int>(p.extras[f].data[i]));
  return least;
}
// read_restart of `file` and the channel's settings
void channel_read(ScriptEngine& s, const std::string& file) {
  s.cmds({"atom_style granular", "read_restart " + file});
  for (const auto& l : scene(0.1))
    if (l.rfind("fix m", 0) == 0 || l.rfind("pair", 0) == 0 || l.rfind("timestep", 0) == 0 ||
        l.rfind("neigh", 0) == 0)
      s.cmd(l);
  channel_setup(s);
}

TEST_CASE("mesh contacts beyond the per-particle slots survive write_restart and read_restart",
          "[mesh][restart]") {
  // The run split by a restart continues bit for bit.
  Body straight[2], restarted[2];
  {
    ScriptEngine s;
    channel_fresh(s);
    s.cmd("run 1600");
    CHECK(channel_contacts(s) == 3);
    for (int i = 0; i < 2; ++i)
      straight[s.p().id[i] - 1] = body(s, i);
  }
  const std::string file = path("channel.restart");
  {
    ScriptEngine s;
    channel_fresh(s);
    s.cmd("run 800");
    CHECK(channel_contacts(s) == 3);
    s.cmd("write_restart " + file);
  }
  {
    ScriptEngine s;
    channel_read(s, file);
    s.cmd("run 800");
    CHECK(channel_contacts(s) == 3);
    for (int i = 0; i < 2; ++i)
      restarted[s.p().id[i] - 1] = body(s, i);
  }
  CHECK(straight[0].x[0] > 0.004);  // slid along the channel
  for (int i = 0; i < 2; ++i) {
    CHECK(restarted[i].x == straight[i].x);
    CHECK(restarted[i].v == straight[i].v);
    CHECK(restarted[i].w == straight[i].w);
  }
}

TEST_CASE("a restart file with two mesh contact slots per particle continues bit for bit",
          "[mesh][restart]") {
  // unittest/reference/restart/channel_2slots.restart was written after 800
  // steps of the channel scene by a build that kept two contact slots per
  // particle inline (one now): read_restart moves the second into the table
  // of extra slots, and the run continues as the uninterrupted one.
  Body straight[2], restarted[2];
  {
    ScriptEngine s;
    channel_fresh(s);
    s.cmd("run 1600");
    for (int i = 0; i < 2; ++i)
      straight[s.p().id[i] - 1] = body(s, i);
  }
  {
    ScriptEngine s;
    channel_read(s, std::string(GRANARY_SOURCE_DIR) + "/unittest/reference/restart/channel_2slots.restart");
    REQUIRE(s.p().find_field("mesh_wall_history/walls/2/3") >= 0);  // as read
    s.cmd("run 800");
    CHECK(s.p().find_field("mesh_wall_history/walls/2/3") < 0);  // converted
    CHECK(channel_contacts(s) == 3);
    for (int i = 0; i < 2; ++i)
      restarted[s.p().id[i] - 1] = body(s, i);
  }
  for (int i = 0; i < 2; ++i) {
    CHECK(restarted[i].x == straight[i].x);
    CHECK(restarted[i].v == straight[i].v);
    CHECK(restarted[i].w == straight[i].w);
  }
}
