// fix ave/euler and dump euler/vtk on 1, 2 and 4 ranks (run by ctest at each
// count): LIGGGHTS 3.8's cells of spheres of two sizes pressed together on a
// lattice and moving with velocity ramps (unittest/scripts/ave_euler,
// reference unittest/reference/ave_euler.liggghts.vtk); the particle volume
// and momentum the cells hold; parallel yes; the dump read back with VTK; the
// errors.
#include <mpi.h>
#include <vtkDataArray.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkPolyDataReader.h>
#include <vtkSmartPointer.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/modify.h"
#include "domain/domain.h"
#include "fix/fix_ave_euler.h"
#include "particles/particles.h"
#include "script_engine.h"

using Catch::Matchers::Contains;

namespace {

namespace fs = std::filesystem;
const fs::path kRoot(GRANARY_SOURCE_DIR);

// The arrays of a legacy ASCII VTK PolyData file as LIGGGHTS writes it:
// "POINTS", "v_avg" (3 per point), then the scalars by name.
std::map<std::string, std::vector<double>> read_liggghts_vtk(const fs::path& path) {
  std::ifstream in(path);
  std::map<std::string, std::vector<double>> out;
  std::string word, name;
  long n = 0;
  auto numbers = [&](const std::string& key, long count) {
    std::vector<double>& v = out[key];
    double x;
    while (static_cast<long>(v.size()) < count && in >> x)
      v.push_back(x);
  };
  while (in >> word) {
    if (word == "POINTS") {
      in >> n >> word;
      numbers("points", 3 * n);
    } else if (word == "VECTORS") {
      in >> name >> word;
      numbers(name, 3 * n);
    } else if (word == "SCALARS") {
      in >> name >> word >> word >> word >> word;  // float 1 LOOKUP_TABLE default
      numbers(name, n);
    }
  }
  return out;
}

granary::FixAveEuler& euler(granary::Engine& e, const std::string& id) {
  auto* f = dynamic_cast<granary::FixAveEuler*>(e.modify->find_fix(id));
  REQUIRE(f != nullptr);
  return *f;
}

}  // namespace

TEST_CASE("fix ave/euler: LIGGGHTS 3.8's cells of a pressed, moving lattice of two sphere sizes",
          "[ave_euler][mpi][liggghts]") {
  const auto ref = read_liggghts_vtk(kRoot / "unittest/reference/ave_euler.liggghts.vtk");
  REQUIRE(ref.at("points").size() == 3 * 54);
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  const std::string dir = granary::test::rank_count_dir("ave_euler");
  s.cmd("variable out index " + dir);
  s.cmd("include " + (kRoot / "unittest/scripts/ave_euler/in.ave_euler").string());
  const granary::FixAveEuler& f = euler(s.e, "e");
  REQUIRE(f.computed_step() == 10);
  // cells of 3 * 2 * rmax = 6 mm: floor(20 / 6) = 3 along x and y, floor(40 / 6) = 6 along z
  REQUIRE(f.grid().n == std::array<int, 3>{3, 3, 6});
  double pmax = 0.0;
  for (double p : ref.at("pressure"))
    pmax = std::max(pmax, std::abs(p));
  REQUIRE(pmax > 1e4);  // the pressed lattice: tens of kPa
  for (int c = 0; c < 54; ++c) {
    INFO("cell " << c);
    const granary::Vec3 x = f.grid().centre(c);
    for (int a = 0; a < 3; ++a) {
      // LIGGGHTS prints 6 decimals (%f) in single precision
      CHECK(x[a] == Approx(ref.at("points")[3 * c + a]).margin(1e-6));
      CHECK(f.v_avg[3 * c + a] == Approx(ref.at("v_avg")[3 * c + a]).margin(1e-6));
    }
    CHECK(f.volumefraction[c] == Approx(ref.at("volumefraction")[c]).margin(1e-6));
    CHECK(f.radius[c] == Approx(ref.at("radius")[c]).margin(1e-9));
    CHECK(f.pressure[c] == Approx(ref.at("pressure")[c]).epsilon(1e-6).margin(1e-6 * pmax));
  }
  // the frame Granary wrote at step 10, read back with VTK (binary legacy)
  if (granary::test::world_rank() == 0) {
    auto r = vtkSmartPointer<vtkPolyDataReader>::New();
    r->SetFileName((dir + "/euler_10.vtk").c_str());
    r->Update();
    vtkPolyData* d = r->GetOutput();
    REQUIRE(d->GetNumberOfPoints() == 54);
    REQUIRE(d->GetNumberOfVerts() == 54);
    vtkDataArray* p = d->GetPointData()->GetArray("pressure");
    vtkDataArray* v = d->GetPointData()->GetArray("v_avg");
    REQUIRE(p != nullptr);
    REQUIRE(v != nullptr);
    REQUIRE(v->GetNumberOfComponents() == 3);
    REQUIRE(d->GetPointData()->GetArray("volumefraction") != nullptr);
    REQUIRE(d->GetPointData()->GetArray("radius") != nullptr);
    for (int c = 0; c < 54; ++c) {
      CHECK(p->GetTuple1(c) == f.pressure[c]);
      CHECK(v->GetComponent(c, 2) == f.v_avg[3 * c + 2]);
    }
  }
}

TEST_CASE("fix ave/euler: the cells hold the particles' volume and momentum; parallel yes",
          "[ave_euler][mpi]") {
  for (const std::string par : {"no", "yes"}) {
    INFO("parallel " << par);
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    const std::string dir = granary::test::rank_count_dir("ave_euler_sums_" + par);
    s.cmd("variable out index " + dir);
    s.cmd("variable par index " + par);
    s.cmd("variable e index 0.5");
    s.cmd("include " + (kRoot / "unittest/scripts/ave_euler/in.ave_euler").string());
    const granary::FixAveEuler& f = euler(s.e, "e");
    const auto& p = *s.e.particles;
    const auto& g = f.grid();
    const double vcell = g.dx[0] * g.dx[1] * g.dx[2];
    // sums over the cells (every rank's own cells with parallel yes)
    double cells[4] = {0, 0, 0, 0}, parts[4] = {0, 0, 0, 0};
    for (int c = 0; c < g.cells(); ++c) {
      const double vol = f.volumefraction[c] * vcell;
      const double r = f.radius[c];
      // mass of the cell from its particle volume (one density, 2500)
      cells[0] += vol;
      if (r > 0)
        for (int a = 0; a < 3; ++a)
          cells[1 + a] += 2500.0 * vol * f.v_avg[3 * c + a];
    }
    for (int i = 0; i < p.nlocal; ++i) {
      const double vol = 4.0 / 3.0 * M_PI * std::pow(p.radius[i], 3);
      parts[0] += vol;
      for (int a = 0; a < 3; ++a)
        parts[1 + a] += p.rmass[i] * p.v[i][a];
    }
    MPI_Allreduce(MPI_IN_PLACE, parts, 4, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
    if (par == "yes") MPI_Allreduce(MPI_IN_PLACE, cells, 4, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
    CHECK(cells[0] == Approx(parts[0]).epsilon(1e-12));
    for (int a = 1; a < 4; ++a)
      CHECK(cells[a] == Approx(parts[a]).epsilon(1e-9).margin(1e-15));
    if (par == "yes") {
      // each rank's grid covers its subdomain
      for (int a = 0; a < 3; ++a)
        CHECK(g.lo[a] + g.n[a] * g.dx[a] == Approx(s.e.domain->subhi[a]).epsilon(1e-12));
    }
    int nfiles = 0;
    if (granary::test::world_rank() == 0)
      for (const auto& entry : fs::directory_iterator(dir))
        nfiles += entry.path().extension() == ".vtk";
    if (granary::test::world_rank() == 0) CHECK(nfiles == 2);  // steps 0 and 10
  }
}

TEST_CASE("fix ave/euler and dump euler/vtk: errors", "[ave_euler][mpi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  const std::string dir = granary::test::rank_count_dir("ave_euler_err");
  s.cmds(granary::test::liggghts_head("0 0.02 0 0.02 0 0.04", 1));
  s.cmds({"fix m1 all property/global youngsModulus peratomtype 5e6",
          "fix m2 all property/global poissonsRatio peratomtype 0.3",
          "fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5",
          "fix m4 all property/global coefficientFriction peratomtypepair 1 0.5",
          "pair_style gran model hertz tangential history", "pair_coeff * *", "timestep 1e-5",
          "create_atoms 1 single 0.01 0.01 0.01 units box", "set group all diameter 0.002 density 2500",
          "fix integr all nve/sphere"});
  s.cmd("dump d1 all euler/vtk 5 " + dir + "/a_*.vtk");  // the fix is looked for when a run starts
  CHECK_THROWS_WITH(s.cmd("run 1"), Contains("no fix ave/euler is defined"));
  s.cmd("undump d1");
  CHECK_THROWS_WITH(s.cmd("fix e all ave/euler nevery 5 cell_size_relative 2 parallel no"),
                    Contains("at least 3"));
  CHECK_THROWS_WITH(s.cmd("fix e all ave/euler nevery 5 cell_size_relative 4"),
                    Contains("needs the keywords nevery, cell_size_relative and parallel"));
  CHECK_THROWS_WITH(
      s.cmd("fix e all ave/euler nevery 5 cell_size_relative 4 parallel no basevolume_region r"),
      Contains("basevolume_region is not supported"));
  CHECK_THROWS_WITH(s.cmd("fix e all ave/euler nevery 0 cell_size_relative 4 parallel no"),
                    Contains("nevery must be at least 1"));
  CHECK_THROWS_WITH(s.cmd("dump d2 all euler/vtk 5 " + dir + "/a_*.csv"), Contains("ending in .vtk"));
  s.cmd("fix e all ave/euler nevery 5 cell_size_relative 4 parallel no");
  s.cmd("dump d3 all euler/vtk 3 " + dir + "/b_*.vtk");
  CHECK_THROWS_WITH(s.cmd("run 3"), Contains("not at step 3") && Contains("multiple of 5"));
  s.cmd("undump d3");
  s.cmd("unfix e");
  CHECK(s.e.modify->find_compute("e_ave_euler_stress") == nullptr);
}
