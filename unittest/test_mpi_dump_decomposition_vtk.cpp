// dump decomposition/vtk: the processor grid as a VTK rectilinear grid, read
// back with VTK's readers on 1, 2 and 4 ranks (processors * 1 1 along x):
// the coordinates are the cut planes (uniform, then moved by `balance x` to
// given fractions), the cells carry the owning rank and its particle count
// (summing to all particles), time and step are in the field data; legacy
// .vtk (ASCII and binary) and XML .vtr with a .pvd. LIGGGHTS 3.8 writes the
// same coordinates (legacy ASCII, 6 decimals) for a 2 x 1 x 2 grid. With
// the rcb boxes of comm_style tiled: one voxel per rank in a legacy
// unstructured grid, the voxels filling the box.
#include <mpi.h>
#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkFieldData.h>
#include <vtkRectilinearGrid.h>
#include <vtkRectilinearGridReader.h>
#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>
#include <vtkUnstructuredGridReader.h>
#include <vtkXMLRectilinearGridReader.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <string>

#include "core/engine.h"
#include "core/input.h"
#include "particles/particles.h"
#include "script_engine.h"

namespace {

namespace fs = std::filesystem;
using Catch::Matchers::Contains;

vtkSmartPointer<vtkRectilinearGrid> read(const std::string& file) {
  if (fs::path(file).extension() == ".vtr") {
    auto r = vtkSmartPointer<vtkXMLRectilinearGridReader>::New();
    r->SetFileName(file.c_str());
    r->Update();
    return r->GetOutput();
  }
  auto r = vtkSmartPointer<vtkRectilinearGridReader>::New();
  r->SetFileName(file.c_str());
  r->Update();
  return r->GetOutput();
}

}  // namespace

TEST_CASE("dump decomposition/vtk writes the cut planes, ranks and particle counts", "[dump][mpi][vtk]") {
  int n = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &n);
  const std::string dir = "decomp_np" + std::to_string(n);
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  if (granary::test::world_rank() == 0) {
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  s.cmds({"atom_style granular",
          "atom_modify map array",
          "boundary p f f",
          "newton off",
          "communicate single vel yes",
          "units si",
          "processors * 1 1",
          "region b block 0 0.04 0 0.01 0 0.02 units box",
          "create_box 1 b",
          "neighbor 0.001 bin",
          "neigh_modify delay 0",
          granary::test::materials(1, 5e6, 0.45, 0.5, 0.5),
          "pair_style gran model hertz tangential history",
          "pair_coeff * *",
          "lattice sc 0.004",
          "create_atoms 1 box",
          "set group all diameter 0.002 density 2500",
          "timestep 1e-5",
          "fix integr all nve/sphere",
          "dump a all decomposition/vtk 10 " + dir + "/ascii*.vtk",
          "dump_modify a binary no",
          "dump b all decomposition/vtk 10 " + dir + "/bin*.vtk",
          "dump c all decomposition/vtk 10 " + dir + "/xml*.vtr",
          "run 10"});
  std::string cuts = "";
  if (n == 2) cuts = "balance 0.9 x 0.3";
  if (n == 4) cuts = "balance 0.9 x 0.1 0.35 0.6";
  if (!cuts.empty()) s.cmds({cuts, "run 10"});
  MPI_Barrier(MPI_COMM_WORLD);
  if (granary::test::world_rank() != 0) return;
  const double natoms = static_cast<double>(s.p().natoms);
  for (const std::string step : {"0", "10", "20"}) {
    if (step == "20" && cuts.empty()) continue;
    const bool balanced = step == "20";
    for (const std::string file : {"ascii" + step + ".vtk", "bin" + step + ".vtk", "xml" + step + ".vtr"}) {
      INFO(dir << "/" << file);
      auto g = read(dir + "/" + file);
      REQUIRE(g != nullptr);
      int dims[3];
      g->GetDimensions(dims);
      CHECK(dims[0] == n + 1);
      CHECK(dims[1] == 2);
      CHECK(dims[2] == 2);
      vtkDataArray* x = g->GetXCoordinates();
      REQUIRE(x->GetNumberOfTuples() == n + 1);
      for (int k = 0; k <= n; ++k) {
        double want = 0.04 * k / n;
        if (balanced && n == 2 && k == 1) want = 0.04 * 0.3;
        if (balanced && n == 4 && k > 0 && k < 4) want = 0.04 * (k == 1 ? 0.1 : k == 2 ? 0.35 : 0.6);
        CHECK(x->GetComponent(k, 0) == Approx(want).margin(1e-15));
      }
      CHECK(g->GetYCoordinates()->GetComponent(1, 0) == Approx(0.01));
      CHECK(g->GetZCoordinates()->GetComponent(1, 0) == Approx(0.02));
      vtkDataArray* rank = g->GetCellData()->GetArray("rank");
      vtkDataArray* parts = g->GetCellData()->GetArray("particles");
      REQUIRE(rank != nullptr);
      REQUIRE(parts != nullptr);
      double total = 0.0;
      for (int c = 0; c < n; ++c) {
        CHECK(rank->GetComponent(c, 0) == c);
        total += parts->GetComponent(c, 0);
      }
      CHECK(total == natoms);
      if (balanced && n == 4) CHECK(parts->GetComponent(0, 0) < parts->GetComponent(3, 0));  // a narrow slab
      vtkDataArray* st = g->GetFieldData()->GetArray("Step");
      REQUIRE(st != nullptr);
      CHECK(st->GetComponent(0, 0) == std::stod(step));
    }
  }
  CHECK(fs::exists(dir + "/xml.pvd"));
}

TEST_CASE("dump decomposition/vtk input errors", "[dump][mpi][vtk]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds({"atom_style granular", "boundary f f f", "units si", "region b block 0 1 0 1 0 1 units box",
          "create_box 1 b"});
  CHECK_THROWS_WITH(s.cmd("dump d all decomposition/vtk 10 grid.txt"), Contains("ending in .vtk"));
  CHECK_THROWS_WITH(s.cmd("dump d all decomposition/vtk 10 grid.vtk extra"),
                    Contains("no further arguments"));
  CHECK_THROWS_WITH(s.cmd("dump d all decomposition/vtk 10 grid%.vtk"), Contains("'%' is not allowed"));
}

TEST_CASE("dump decomposition/vtk writes the rcb boxes of comm_style tiled as voxels", "[dump][mpi][vtk]") {
  int n = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &n);
  const std::string dir = "decomp_rcb_np" + std::to_string(n);
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  if (granary::test::world_rank() == 0) {
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  s.cmds({"atom_style granular", "boundary f f f", "units si", "comm_style tiled",
          "region b block 0 0.04 0 0.01 0 0.02 units box", "create_box 1 b",
          "region corner block 0 0.015 0 0.01 0 0.008 units box", "create_atoms 1 random 400 4711 corner",
          "set group all diameter 0.002 density 2500", "balance 1.0 rcb",
          "dump a all decomposition/vtk 10 " + dir + "/boxes*.vtk", "dump_modify a binary no",
          "dump c all decomposition/vtk 10 " + dir + "/xml*.vtr"});
  if (n > 1) {
    CHECK_THROWS_WITH(s.cmd("run 0"), Contains("give the dump a .vtk file name"));
  }
  s.cmds({"undump c", "run 0"});
  MPI_Barrier(MPI_COMM_WORLD);
  if (granary::test::world_rank() != 0) return;
  if (n == 1) return;  // one rank: no rcb boxes (balance leaves a single rank's box alone)
  auto r = vtkSmartPointer<vtkUnstructuredGridReader>::New();
  r->SetFileName((dir + "/boxes0.vtk").c_str());
  r->Update();
  vtkUnstructuredGrid* g = r->GetOutput();
  REQUIRE(g->GetNumberOfCells() == n);
  double volume = 0.0, total = 0.0;
  vtkDataArray* rank = g->GetCellData()->GetArray("rank");
  vtkDataArray* parts = g->GetCellData()->GetArray("particles");
  REQUIRE(rank != nullptr);
  REQUIRE(parts != nullptr);
  for (vtkIdType c = 0; c < n; ++c) {
    CHECK(g->GetCellType(c) == VTK_VOXEL);
    double b[6];
    g->GetCell(c)->GetBounds(b);
    volume += (b[1] - b[0]) * (b[3] - b[2]) * (b[5] - b[4]);
    CHECK(rank->GetComponent(c, 0) == c);
    total += parts->GetComponent(c, 0);
    // every box holds an even share of the corner's particles (the cuts fall between two of them)
    CHECK(std::abs(parts->GetComponent(c, 0) - 400.0 / n) <= 1.0);
  }
  CHECK(volume == Approx(0.04 * 0.01 * 0.02).epsilon(1e-12));
  CHECK(total == static_cast<double>(s.p().natoms));
}
