// dump custom/vtk on one rank: the other formats (.vtu, explicit .pvtp), the
// .pvd collection (names, relative paths, several runs), array naming, errors.
// The round trip of every field on 1, 2 and 4 ranks is in test_mpi_dump_vtk.cpp;
// ParaView reading the .pvd and rendering the dumps is in python/test_render.py.
#include <vtkCellType.h>
#include <vtkDataArray.h>
#include <vtkFieldData.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLDataElement.h>
#include <vtkXMLPPolyDataReader.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLUnstructuredGridReader.h>
#include <vtkXMLUtilities.h>

#include <catch2/catch.hpp>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/error.h"
#include "core/input.h"
#include "core/logger.h"
#include "particles/particles.h"
#include "script_engine.h"

namespace {

namespace fs = std::filesystem;
using Catch::Matchers::Contains;

std::string fresh_dir(const std::string& name) {
  const std::string dir = "dump_vtk_serial/" + name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void setup_bed(granary::Engine& e) {
  e.logger->set_screen(false);
  const std::vector<std::string> lines = {
      "units si",
      "atom_style granular",
      "boundary f f f",
      "region box block 0 0.02 0 0.02 0 0.03 units box",
      "create_box 1 box",
      "neighbor 0.0005 bin",
      granary::test::materials(1, 5.e6, 0.45, 0.7, 0.5),
      "pair_style gran model hertz tangential history",
      "pair_coeff * *",
      "timestep 1e-5",
      "region fill block 0.001 0.019 0.001 0.019 0.001 0.012 units box",
      "create_atoms 1 random 100 4711 fill overlap 0.0021 maxtry 200",
      "set type 1 diameter 0.002 density 2500",
      "velocity all set 0.05 -0.1 -0.5",
      "fix gravi all gravity 9.81 vector 0.0 0.0 -1.0",
      "fix zwall all wall/gran model hertz tangential history primitive type 1 zplane 0.0",
      "fix integr all nve/sphere",
  };
  granary::test::run(e, lines);
}

vtkSmartPointer<vtkXMLDataElement> read_xml(const std::string& file) {
  vtkSmartPointer<vtkXMLDataElement> root;
  root.TakeReference(vtkXMLUtilities::ReadElementFromFile(file.c_str()));
  return root;
}

// (timestep, file) of every DataSet in a .pvd
std::vector<std::pair<double, std::string>> pvd_entries(const std::string& file) {
  std::vector<std::pair<double, std::string>> out;
  auto root = read_xml(file);
  if (!root) return out;
  vtkXMLDataElement* coll = root->FindNestedElementWithName("Collection");
  if (!coll) return out;
  for (int k = 0; k < coll->GetNumberOfNestedElements(); ++k) {
    vtkXMLDataElement* ds = coll->GetNestedElement(k);
    out.emplace_back(std::stod(ds->GetAttribute("timestep")), ds->GetAttribute("file"));
  }
  return out;
}

vtkSmartPointer<vtkPolyData> read_vtp(const std::string& file) {
  auto reader = vtkSmartPointer<vtkXMLPolyDataReader>::New();
  reader->SetFileName(file.c_str());
  reader->Update();
  return reader->GetOutput();
}

}  // namespace

TEST_CASE("dump custom/vtk: .vtu files read back as vertex cells", "[dump][vtk]") {
  const std::string dir = fresh_dir("vtu");
  granary::Engine e(MPI_COMM_WORLD);
  setup_bed(e);
  e.input->one("dump d all custom/vtk 10 " + dir + "/grid_*.vtu id vx vy vz radius");
  e.input->one("run 10");
  auto reader = vtkSmartPointer<vtkXMLUnstructuredGridReader>::New();
  reader->SetFileName((dir + "/grid_10.vtu").c_str());
  reader->Update();
  vtkUnstructuredGrid* ug = reader->GetOutput();
  REQUIRE(ug->GetNumberOfPoints() == 100);
  REQUIRE(ug->GetNumberOfCells() == 100);
  CHECK(ug->GetCellType(0) == VTK_VERTEX);
  std::map<long long, int> idx;
  for (int i = 0; i < e.particles->nlocal; ++i)
    idx[e.particles->id[i]] = i;
  vtkDataArray* ids = ug->GetPointData()->GetArray("id");
  vtkDataArray* v = ug->GetPointData()->GetArray("v");
  REQUIRE(ids);
  REQUIRE(v);
  int bad = 0;
  for (vtkIdType k = 0; k < ug->GetNumberOfPoints(); ++k) {
    const int i = idx.at(static_cast<long long>(ids->GetTuple1(k)));
    double x[3];
    ug->GetPoint(k, x);
    for (int d = 0; d < 3; ++d)
      if (x[d] != e.particles->x[i][d] || v->GetComponent(k, d) != e.particles->v[i][d]) ++bad;
  }
  CHECK(bad == 0);
  CHECK(pvd_entries(dir + "/grid_.pvd").size() == 2);
}

TEST_CASE("dump atom/vtk: LIGGGHTS' arrays, read back", "[dump][vtk]") {
  // LIGGGHTS 3.8 writes these point arrays (an UnstructuredGrid of vertex
  // cells): radii, id, type, proc, mass, velocity_lin, velocity_ang, force
  const std::string dir = fresh_dir("atom_vtk");
  granary::Engine e(MPI_COMM_WORLD);
  setup_bed(e);
  e.input->one("dump d all atom/vtk 10 " + dir + "/atoms_*.vtu");
  e.input->one("run 10");
  auto reader = vtkSmartPointer<vtkXMLUnstructuredGridReader>::New();
  reader->SetFileName((dir + "/atoms_10.vtu").c_str());
  reader->Update();
  vtkUnstructuredGrid* ug = reader->GetOutput();
  REQUIRE(ug->GetNumberOfPoints() == 100);
  CHECK(ug->GetCellType(0) == VTK_VERTEX);
  vtkPointData* pd = ug->GetPointData();
  CHECK(pd->GetNumberOfArrays() == 8);
  for (const char* name : {"radii", "id", "type", "proc", "mass", "velocity_lin", "velocity_ang", "force"}) {
    INFO(name);
    CHECK(pd->GetArray(name) != nullptr);
  }
  REQUIRE(pd->GetArray("velocity_lin"));
  CHECK(pd->GetArray("velocity_lin")->GetNumberOfComponents() == 3);
  std::map<long long, int> idx;
  for (int i = 0; i < e.particles->nlocal; ++i)
    idx[e.particles->id[i]] = i;
  int bad = 0;
  for (vtkIdType k = 0; k < ug->GetNumberOfPoints(); ++k) {
    const int i = idx.at(static_cast<long long>(pd->GetArray("id")->GetTuple1(k)));
    if (pd->GetArray("radii")->GetTuple1(k) != e.particles->radius[i]) ++bad;
    if (pd->GetArray("mass")->GetTuple1(k) != e.particles->rmass[i]) ++bad;
    if (pd->GetArray("proc")->GetTuple1(k) != 0) ++bad;
    for (int d = 0; d < 3; ++d) {
      if (pd->GetArray("velocity_lin")->GetComponent(k, d) != e.particles->v[i][d]) ++bad;
      if (pd->GetArray("velocity_ang")->GetComponent(k, d) != e.particles->omega[i][d]) ++bad;
      if (pd->GetArray("force")->GetComponent(k, d) != e.particles->f[i][d]) ++bad;
    }
  }
  CHECK(bad == 0);
  CHECK_THROWS_WITH(e.input->one("dump d2 all atom/vtk 10 " + dir + "/a_*.vtu id"),
                    Contains("atom/vtk takes no fields"));
  CHECK_THROWS_WITH(e.input->one("dump d3 all atom/vtk 10 " + dir + "/a_*.txt"),
                    Contains("atom/vtk needs a file name ending in .vtp"));
}

TEST_CASE("dump custom/vtk: a .pvtp name gives the parallel format on one rank", "[dump][vtk]") {
  const std::string dir = fresh_dir("pvtp");
  granary::Engine e(MPI_COMM_WORLD);
  setup_bed(e);
  e.input->one("dump d all custom/vtk 5 " + dir + "/p*.pvtp id");
  e.input->one("run 5");
  CHECK(fs::exists(dir + "/p5.pvtp"));
  CHECK(fs::exists(dir + "/p5_0.vtp"));
  auto reader = vtkSmartPointer<vtkXMLPPolyDataReader>::New();
  reader->SetFileName((dir + "/p5.pvtp").c_str());
  reader->Update();
  CHECK(reader->GetOutput()->GetNumberOfPoints() == 100);
  const auto entries = pvd_entries(dir + "/p.pvd");
  REQUIRE(entries.size() == 2);
  CHECK(entries[1].second == "p5.pvtp");
}

TEST_CASE("dump custom/vtk: array names, time field data and partial vectors", "[dump][vtk]") {
  const std::string dir = fresh_dir("arrays");
  granary::Engine e(MPI_COMM_WORLD);
  setup_bed(e);
  e.input->one("dump d all custom/vtk 7 " + dir + "/a_*.vtp id type type vx vz fx fy fz ix iy iz");
  e.input->one("run 7");
  auto pd = read_vtp(dir + "/a_7.vtp");
  vtkPointData* pdata = pd->GetPointData();
  CHECK(pdata->GetNumberOfArrays() == 6);  // id type vx vz f image
  CHECK(pdata->GetArray("vx"));
  CHECK(pdata->GetArray("vz"));
  CHECK(pdata->GetArray("v") == nullptr);
  REQUIRE(pdata->GetArray("f"));
  CHECK(pdata->GetArray("f")->GetNumberOfComponents() == 3);
  REQUIRE(pdata->GetArray("image"));
  CHECK(pdata->GetArray("image")->GetNumberOfComponents() == 3);
  CHECK(pdata->GetArray("id")->GetDataType() == VTK_TYPE_INT64);
  CHECK(pdata->GetArray("type")->GetDataType() == VTK_INT);
  vtkDataArray* tv = pd->GetFieldData()->GetArray("TimeValue");
  REQUIRE(tv);
  CHECK(tv->GetTuple1(0) == Approx(7e-5).epsilon(1e-14));
}

TEST_CASE("dump custom/vtk: the .pvd collection across runs, names and paths", "[dump][vtk][pvd]") {
  const std::string dir = fresh_dir("pvd");
  fs::create_directories(dir + "/frames");
  granary::Engine e(MPI_COMM_WORLD);
  setup_bed(e);
  e.input->one("dump a all custom/vtk 5 " + dir + "/frames/f_*.vtp id");
  e.input->one("dump_modify a pvd " + dir + "/movie.pvd pad 3");
  e.input->one("dump b all custom/vtk 5 " + dir + "/last.vtp id");
  e.input->one("dump c all custom/vtk 5 " + dir + "/none_*.vtp id");
  e.input->one("dump_modify c pvd no");
  e.input->one("run 10");
  e.input->one("timestep 2e-5");
  e.input->one("run 5");  // step 10 is not written twice

  const auto a = pvd_entries(dir + "/movie.pvd");
  REQUIRE(a.size() == 4);
  CHECK(a[0].second == "frames/f_000.vtp");
  CHECK(a[3].second == "frames/f_015.vtp");
  CHECK(a[2].first == Approx(10e-5).epsilon(1e-14));
  CHECK(a[3].first == Approx(10e-5 + 5 * 2e-5).epsilon(1e-14));
  for (const auto& entry : a)
    CHECK(fs::exists(dir + "/" + entry.second));
  CHECK_FALSE(fs::exists(dir + "/frames/f_.pvd"));

  const auto b = pvd_entries(dir + "/last.pvd");  // no '*': the file holds the latest frame
  REQUIRE(b.size() == 1);
  CHECK(b[0].second == "last.vtp");
  CHECK(b[0].first == Approx(a[3].first).epsilon(1e-14));
  CHECK_FALSE(fs::exists(dir + "/none_.pvd"));
  CHECK(fs::exists(dir + "/none_15.vtp"));
  for (const auto& f : fs::recursive_directory_iterator(dir))  // no temporary file of a write is left
    CHECK(f.path().filename().string().find(".tmp") == std::string::npos);
}

TEST_CASE("dump custom/vtk: errors name the file", "[dump][vtk][errors]") {
  const std::string dir = fresh_dir("errors");
  granary::Engine e(MPI_COMM_WORLD);
  setup_bed(e);
  const std::string missing = dir + "/missing/p_*.vtp";
  CHECK_THROWS_AS(e.input->one("dump d all custom/vtk 1 " + missing + " id"), granary::InputError);
  CHECK_THROWS_WITH(e.input->one("dump d all custom/vtk 1 " + missing + " id"), Contains(missing));
  CHECK_THROWS_WITH(e.input->one("dump d all custom/vtk 1 " + dir + "/p_*.csv id"), Contains(".vtp"));
  CHECK_THROWS_WITH(e.input->one("dump d all custom/vtk 1 " + dir + "/p_*.vtp id nosuch"),
                    Contains("nosuch"));
  e.input->one("dump d all custom/vtk 1 " + dir + "/p_*.vtp id");
  CHECK_THROWS_WITH(e.input->one("dump_modify d compression gzip"), Contains("zlib"));
  CHECK_THROWS_WITH(e.input->one("dump_modify d pvd " + dir + "/x.txt"), Contains(".pvd"));
  CHECK_THROWS_WITH(e.input->one("dump_modify d format line %d"), Contains("format"));
  e.input->one("undump d");
  fs::create_directories(dir + "/taken_5.vtp");
  e.input->one("dump d all custom/vtk 5 " + dir + "/taken_*.vtp id");
  e.input->one("run 4");
  CHECK_THROWS_WITH(e.input->one("run 1"), Contains(dir + "/taken_5.vtp"));
}
