// fix mesh/surface/stress ... wear finnie and the "wear" array of dump
// mesh/vtk (mesh/gran/VTK) on 1, 2 and 4 ranks (run by ctest at each count):
// LIGGGHTS 3.8's wear for three impacts (unittest/scripts/wear_finnie,
// reference unittest/reference/wear_finnie.liggghts.vtk); without friction the
// analytic wear of an impact, whatever the force law; linear in k_finnie; a
// head-on impact wears nothing; the wear goes on across a restart file; the
// errors.
#include <mpi.h>

#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkPolyData.h>
#include <vtkPolyDataReader.h>
#include <vtkSmartPointer.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/modify.h"
#include "fix/fix_mesh_surface.h"
#include "script_engine.h"

using Catch::Matchers::Contains;

namespace {

namespace fs = std::filesystem;
using granary::test::world_rank;
using granary::test::world_size;

const fs::path kScripts = fs::path(GRANARY_SOURCE_DIR) / "unittest/scripts/wear_finnie";

std::string fresh_dir(const std::string& name) {
  const std::string dir = "wear_finnie_np" + std::to_string(world_size()) + "/" + name;
  if (world_rank() == 0) {
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  return dir;
}

// Runs unittest/scripts/wear_finnie/in.wear_finnie with these variables
// (index variables defined first win over the script's defaults).
void run_script(granary::test::ScriptEngine& s, const std::string& dir, const std::string& extra = "") {
  s.cmd("variable meshfile index " + (kScripts / "plate.stl").string());
  s.cmd("variable out index " + dir);
  if (!extra.empty()) s.cmd(extra);
  s.cmd("include " + (kScripts / "in.wear_finnie").string());
}

// The wear of every triangle of mesh `id`, summed over the ranks (collective).
std::vector<double> wear_of(granary::test::ScriptEngine& s, const std::string& id) {
  auto& m = granary::FixMeshSurface::find(*s.e.modify, id, "test");
  std::vector<double> local = m.mesh.tri_wear, all(local.size());
  MPI_Allreduce(local.data(), all.data(), static_cast<int>(local.size()), MPI_DOUBLE, MPI_SUM,
                MPI_COMM_WORLD);
  return all;
}

// The "wear" cell array of a legacy VTK file written by dump mesh/gran/VTK.
std::vector<double> wear_in_file(const std::string& file) {
  auto reader = vtkSmartPointer<vtkPolyDataReader>::New();
  reader->SetFileName(file.c_str());
  reader->ReadAllFieldsOn();
  reader->Update();
  vtkPolyData* pd = reader->GetOutput();
  std::vector<double> out;
  vtkDataArray* a = pd ? pd->GetCellData()->GetArray("wear") : nullptr;
  if (!a) return out;
  for (vtkIdType c = 0; c < a->GetNumberOfTuples(); ++c)
    out.push_back(a->GetTuple1(c));
  return out;
}

// LIGGGHTS' values: the numbers after the line "wear 1 N double" of its
// ASCII legacy VTK file.
std::vector<double> liggghts_wear(const std::string& file) {
  std::ifstream in(file);
  std::string line;
  std::vector<double> out;
  while (std::getline(in, line)) {
    if (line.rfind("wear 1 ", 0) != 0) continue;
    std::istringstream head(line);
    std::string name, type;
    int ncomp = 0, n = 0;
    head >> name >> ncomp >> n >> type;
    for (int k = 0; k < n; ++k) {
      double v;
      in >> v;
      out.push_back(v);
    }
  }
  return out;
}

// Finnie's f(gamma) with tan(gamma) = vn / vt
double finnie_f(double vn, double vt) {
  const double v = std::hypot(vn, vt);
  const double s = vn / v, c = vt / v;
  return 3.0 * vn > vt ? c * c / 3.0 : 2.0 * s * c - 3.0 * s * s;
}

}  // namespace

TEST_CASE("wear finnie: LIGGGHTS 3.8's wear of three impacts at three angles", "[wear][mpi][liggghts]") {
  const auto reference =
      liggghts_wear((fs::path(GRANARY_SOURCE_DIR) / "unittest/reference/wear_finnie.liggghts.vtk").string());
  REQUIRE(reference.size() == 6);
  const std::string dir = fresh_dir("liggghts");
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  run_script(s, dir);
  const auto mine = wear_of(s, "cad");
  const auto written = wear_in_file(dir + "/mesh_1500.vtk");
  REQUIRE(mine.size() == 6);
  REQUIRE(written.size() == 6);
  for (int t = 0; t < 6; ++t) {
    INFO("triangle " << t);
    // each sphere hits the first triangle of its square: the other stays unworn
    if (reference[t] == 0.0) {
      CHECK(mine[t] == 0.0);
    } else {
      // the two programs integrate the same contacts with round-off
      // differences: 1e-4 relative (observed 1e-5 at most)
      CHECK(mine[t] == Approx(reference[t]).epsilon(1e-4));
    }
    CHECK(written[t] == Approx(mine[t]).epsilon(1e-15));
  }
}

TEST_CASE("wear finnie: without friction the wear of an impact is the analytic integral over the approach",
          "[wear][mpi]") {
  // Frictionless, the tangential velocity vt stays constant and the normal
  // force is m dvn/dt whatever the force law (Hertz, damping), so one impact
  // wears its triangle by
  //   (2 k m / A) * integral from 0 to vn0 of sqrt(vt^2 + vn^2) f(gamma(vn)) dvn
  // (the approach: vn from vn0 to 0; nothing while the sphere leaves).
  const std::string dir = fresh_dir("analytic");
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  run_script(s, dir, "variable mu index 0.0\nvariable dt index 2e-7\nvariable nrun index 15000");
  const auto wear = wear_of(s, "cad");
  REQUIRE(wear.size() == 6);
  const double k = 2.0, m = 2500.0 * 4.0 / 3.0 * M_PI * 1e-9, area = 0.5 * 0.02 * 0.02;
  const double vt[3] = {1.0, 1.0, 0.3}, vn0[3] = {0.1, 0.5, 1.0};
  for (int b = 0; b < 3; ++b) {
    // Simpson's rule, 20000 intervals (f has a kink at tan(gamma) = 1/3: its
    // error there is far below the tolerance)
    const int n = 20000;
    const double h = vn0[b] / n;
    double sum = 0.0;
    for (int j = 0; j <= n; ++j) {
      const double vn = j * h;
      const double w = (j == 0 || j == n) ? 1.0 : (j % 2 ? 4.0 : 2.0);
      sum += w * std::hypot(vt[b], vn) * finnie_f(vn, vt[b]);
    }
    const double expect = 2.0 * k * m / area * sum * h / 3.0;
    INFO("sphere " << b + 1 << ": vt " << vt[b] << ", vn0 " << vn0[b]);
    // the contact is resolved in 500-1000 steps: the step's discretisation of
    // the integral (the force with the velocity of the same step) is within
    // 0.3 % (1 % at the steps of the LIGGGHTS comparison, 2e-6 s)
    CHECK(wear[2 * b] == Approx(expect).epsilon(0.003));
    CHECK(wear[2 * b + 1] == 0.0);
  }
}

TEST_CASE("wear finnie: linear in k_finnie, nothing for a head-on impact, and on across a restart file",
          "[wear][mpi]") {
  const std::string dir = fresh_dir("restart");
  std::vector<double> base;
  {
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    run_script(s, dir);
    base = wear_of(s, "cad");
  }
  {
    // the dynamics do not depend on k: the wear scales with it exactly
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    run_script(s, dir, "variable kf index 0.5");
    const auto quarter = wear_of(s, "cad");
    for (int t = 0; t < 6; ++t)
      CHECK(quarter[t] == Approx(0.25 * base[t]).epsilon(1e-12));
  }
  {
    // f(90 degrees) = 0: a particle that meets the wall head-on wears nothing
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    run_script(s, dir, "variable v1x index 0.0\nvariable v2x index 0.0\nvariable v3x index 0.0");
    for (double w : wear_of(s, "cad"))
      CHECK(w == 0.0);
  }
  // 700 steps, a restart file, then the other 800: the same wear as one run
  {
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    run_script(s, dir, "variable nrun index 700");
    s.cmd("write_restart " + dir + "/wear.restart");
  }
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds({"read_restart " + dir + "/wear.restart", "neighbor 0.0005 bin", "neigh_modify delay 0",
          "fix m1 all property/global youngsModulus peratomtype 5.e6",
          "fix m2 all property/global poissonsRatio peratomtype 0.45",
          "fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5",
          "fix m4 all property/global coefficientFriction peratomtypepair 1 0.3",
          "fix m5 all property/global k_finnie peratomtypepair 1 2.0",
          "pair_style gran model hertz tangential history", "pair_coeff * *", "timestep 0.000002",
          "fix cad all mesh/surface/stress file " + (kScripts / "plate.stl").string() + " type 1 wear finnie",
          "fix walls all wall/gran model hertz tangential history mesh n_meshes 1 meshes cad",
          "fix integr all nve/sphere", "run 800"});
  const auto resumed = wear_of(s, "cad");
  for (int t = 0; t < 6; ++t) {
    INFO("triangle " << t);
    CHECK(resumed[t] == Approx(base[t]).epsilon(1e-9));
  }
  CHECK(base[0] > 0.0);
}

TEST_CASE("wear finnie: errors", "[wear][mpi]") {
  const std::string dir = fresh_dir("errors");
  const std::string plate = (kScripts / "plate.stl").string();
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds(granary::test::liggghts_head("-0.04 0.04 -0.02 0.02 -0.01 0.02", 1));
  s.cmds({"fix m1 all property/global youngsModulus peratomtype 5.e6",
          "fix m2 all property/global poissonsRatio peratomtype 0.45",
          "fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5",
          "fix m4 all property/global coefficientFriction peratomtypepair 1 0.3",
          "pair_style gran model hertz tangential history", "pair_coeff * *",
          "create_atoms 1 single 0.005 -0.004 0.0012 units box", "fix integr all nve/sphere"});
  REQUIRE_THROWS_WITH(s.cmd("fix w all mesh/surface/stress file " + plate + " type 1 wear archard"),
                      Contains("'wear archard' is not a wear model") && Contains("wear finnie"));
  s.cmd("fix plain all mesh/surface/stress file " + plate + " type 1");
  REQUIRE_THROWS_WITH(s.cmd("dump d all mesh/gran/VTK 10 " + dir + "/m_*.vtk stress wear plain"),
                      Contains("'wear' needs a fix mesh/surface/stress with 'wear finnie'"));
  s.cmds({"unfix plain", "fix cad all mesh/surface/stress file " + plate + " type 1 wear finnie",
          "fix walls all wall/gran model hertz tangential history mesh n_meshes 1 meshes cad"});
  // without k_finnie the run stops before its first step, naming the property
  REQUIRE_THROWS_WITH(s.cmd("run 1"), Contains("k_finnie"));
}
