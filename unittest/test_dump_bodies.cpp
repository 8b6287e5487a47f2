// dump bodies/vtk: one point per clump with the body state as point data, read
// back with VTK's reader and compared with the bodies of fix multisphere; the
// .pvd collection; group selection and errors.
#include <mpi.h>
#include <vtkDataArray.h>
#include <vtkFieldData.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkType.h>
#include <vtkXMLDataElement.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLUtilities.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "core/engine.h"
#include "core/error.h"
#include "core/input.h"
#include "core/logger.h"
#include "core/update.h"
#include "fix/fix_multisphere.h"
#include "core/modify.h"
#include "script_engine.h"

namespace {

namespace fs = std::filesystem;
using granary::Bodies;
using granary::Engine;
using granary::FixMultisphere;
using granary::Vec3;

std::string fresh_dir(const std::string& name) {
  const std::string dir = "dump_bodies/" + name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void setup(Engine& e) {
  e.logger->set_screen(false);
  const std::vector<std::string> lines = {
      "units si",
      "atom_style granular",
      "boundary f f f",
      "region box block -0.05 0.05 -0.05 0.05 -0.05 0.05",
      "create_box 2 box",
      "neighbor 0.001 bin",
      "neigh_modify delay 0",
      granary::test::materials(2, 5.e6, 0.45, 0.5, 0.5),
      "pair_style gran model hertz tangential history",
      "pair_coeff * *",
      "timestep 1e-5",
      // three spheres of different sizes (three distinct moments), type 1
      "fix tri all particletemplate/multisphere 15485863 atom_type 1 density constant 2500 nspheres 3 "
      "ntry 1000000 spheres 0 0 0 0.002 0.003 0 0 0.0015 0 0.0025 0 0.001 type 1",
      // a dumbbell along body x, type 2
      "fix dumb all particletemplate/multisphere 15485867 atom_type 2 density constant 2500 nspheres 2 "
      "ntry 1000000 spheres -0.001 0 0 0.001 0.001 0 0 0.001 type 2",
  };
  granary::test::run(e, lines);
}

vtkSmartPointer<vtkPolyData> read_vtp(const std::string& file) {
  auto reader = vtkSmartPointer<vtkXMLPolyDataReader>::New();
  reader->SetFileName(file.c_str());
  reader->Update();
  return reader->GetOutput();
}

std::vector<std::pair<double, std::string>> pvd_entries(const std::string& file) {
  std::vector<std::pair<double, std::string>> out;
  vtkSmartPointer<vtkXMLDataElement> root;
  root.TakeReference(vtkXMLUtilities::ReadElementFromFile(file.c_str()));
  if (!root) return out;
  vtkXMLDataElement* coll = root->FindNestedElementWithName("Collection");
  if (!coll) return out;
  for (int k = 0; k < coll->GetNumberOfNestedElements(); ++k) {
    vtkXMLDataElement* ds = coll->GetNestedElement(k);
    out.emplace_back(std::stod(ds->GetAttribute("timestep")), ds->GetAttribute("file"));
  }
  return out;
}

vtkDataArray* array(vtkPolyData* pd, const char* name, int ncomp) {
  vtkDataArray* a = pd->GetPointData()->GetArray(name);
  INFO("array " << name);
  REQUIRE(a != nullptr);
  REQUIRE(a->GetNumberOfComponents() == ncomp);
  REQUIRE(a->GetNumberOfTuples() == pd->GetNumberOfPoints());
  return a;
}

}  // namespace

TEST_CASE("dump bodies/vtk: every array reads back as the body state", "[dump][vtk][multisphere]") {
  const std::string dir = fresh_dir("state");
  Engine e(MPI_COMM_WORLD);
  setup(e);
  e.input->one("fix ms all multisphere");
  e.input->one("create_clump tri -0.01 0.002 0.0 quat 0.9238795 0 0 0.3826834 vel 0.3 0 0 omega 0 0 10");
  e.input->one(
      "create_clump dumb 0.01 -0.002 0.001 quat 0.9659258 0 0.2588190 0 vel -0.2 0.1 0 omega 5 -3 2");
  e.input->one("create_clump tri 0.0 0.02 -0.01 quat 0.5 0.5 0.5 0.5 omega 20 0 0");
  e.input->one("fix g all gravity 9.81 vector 0 0 -1");
  e.input->one("dump b all bodies/vtk 25 " + dir + "/bodies_*.vtp");
  e.input->one("run 100");

  const Bodies& B = dynamic_cast<FixMultisphere*>(e.clumps)->bodies();
  REQUIRE(B.size() == 3);
  auto pd = read_vtp(dir + "/bodies_100.vtp");
  REQUIRE(pd->GetNumberOfPoints() == 3);
  vtkDataArray* id = array(pd, "id", 1);
  vtkDataArray* type = array(pd, "type", 1);
  vtkDataArray* mass = array(pd, "mass", 1);
  vtkDataArray* quat = array(pd, "quaternion", 4);
  vtkDataArray* axis = array(pd, "long_axis", 3);
  vtkDataArray* vel = array(pd, "velocity", 3);
  vtkDataArray* omega = array(pd, "angular_velocity", 3);
  vtkDataArray* nsph = array(pd, "nspheres", 1);
  // 64-bit integer ids, 32-bit integer type and count, doubles for the rest
  CHECK(id->GetDataType() != VTK_DOUBLE);
  CHECK(id->GetDataTypeSize() == 8);
  CHECK(type->GetDataType() == VTK_INT);
  CHECK(nsph->GetDataType() == VTK_INT);
  for (vtkDataArray* a : {mass, quat, axis, vel, omega})
    CHECK(a->GetDataType() == VTK_DOUBLE);

  for (int b = 0; b < 3; ++b) {
    INFO("body " << b);
    double x[3];
    pd->GetPoint(b, x);
    for (int d = 0; d < 3; ++d)
      CHECK(x[d] == B.xcm[b][d]);  // no periodic boundary: wrapped = unwrapped
    CHECK(id->GetComponent(b, 0) == static_cast<double>(B.tag[b]));
    CHECK(type->GetComponent(b, 0) == B.type[b]);
    CHECK(mass->GetComponent(b, 0) == B.mass[b]);
    CHECK(nsph->GetComponent(b, 0) == B.nspheres[b]);
    const double q[4] = {B.quat[b].w(), B.quat[b].x(), B.quat[b].y(), B.quat[b].z()};
    for (int c = 0; c < 4; ++c)
      CHECK(quat->GetComponent(b, c) == q[c]);
    for (int d = 0; d < 3; ++d) {
      CHECK(vel->GetComponent(b, d) == B.vcm[b][d]);
      CHECK(omega->GetComponent(b, d) == B.omega[b][d]);
    }
    // long_axis = the body x axis rotated by the written quaternion
    const Eigen::Quaterniond qr(quat->GetComponent(b, 0), quat->GetComponent(b, 1), quat->GetComponent(b, 2),
                                quat->GetComponent(b, 3));
    const Vec3 ex = qr.toRotationMatrix().col(0);
    const Vec3 a(axis->GetComponent(b, 0), axis->GetComponent(b, 1), axis->GetComponent(b, 2));
    CHECK((a - ex).norm() < 1e-14);
    CHECK(a.norm() == Approx(1.0).epsilon(1e-14));
  }
  // types and sizes of the clumps as created (bodies sorted by id)
  CHECK(type->GetComponent(0, 0) == 1);
  CHECK(type->GetComponent(1, 0) == 2);
  CHECK(nsph->GetComponent(0, 0) == 3);
  CHECK(nsph->GetComponent(1, 0) == 2);
  // the dumbbell's long axis: body x tilted by 30 degrees about y, the spin moved it a little
  // (its first frame shows the created orientation exactly)
  auto first = read_vtp(dir + "/bodies_0.vtp");
  vtkDataArray* a0 = array(first, "long_axis", 3);
  CHECK(a0->GetComponent(1, 0) == Approx(std::cos(M_PI / 6)).margin(1e-6));
  CHECK(a0->GetComponent(1, 1) == Approx(0.0).margin(1e-6));
  CHECK(a0->GetComponent(1, 2) == Approx(-std::sin(M_PI / 6)).margin(1e-6));

  // time and step as field data
  vtkDataArray* tv = pd->GetFieldData()->GetArray("TimeValue");
  vtkDataArray* step = pd->GetFieldData()->GetArray("Step");
  REQUIRE(tv);
  REQUIRE(step);
  CHECK(tv->GetComponent(0, 0) == e.update->time());
  CHECK(step->GetComponent(0, 0) == 100);

  // the collection lists every frame with its simulated time
  const auto entries = pvd_entries(dir + "/bodies_.pvd");
  REQUIRE(entries.size() == 5);
  for (int k = 0; k < 5; ++k) {
    CHECK(entries[k].second == "bodies_" + std::to_string(25 * k) + ".vtp");
    CHECK(entries[k].first == Approx(25 * k * 1e-5).epsilon(1e-12));
    CHECK(fs::exists(dir + "/" + entries[k].second));
  }
  for (const auto& f : fs::directory_iterator(dir))  // no temporary file of a write is left
    CHECK(f.path().filename().string().find(".tmp") == std::string::npos);

  // a second run continues the collection with the later times
  e.input->one("run 50");
  const auto more = pvd_entries(dir + "/bodies_.pvd");
  REQUIRE(more.size() == 7);
  CHECK(more.back().second == "bodies_150.vtp");
  CHECK(more.back().first == Approx(150e-5).epsilon(1e-12));
}

TEST_CASE("dump bodies/vtk: group selection, ASCII files, pvd name", "[dump][vtk][multisphere]") {
  const std::string dir = fresh_dir("group");
  Engine e(MPI_COMM_WORLD);
  setup(e);
  e.input->one("fix ms all multisphere");
  e.input->one("create_clump tri -0.01 0 0");
  e.input->one("create_clump dumb 0.01 0 0");
  e.input->one("group dumbs type 2");
  e.input->one("dump b dumbs bodies/vtk 10 " + dir + "/d_*.vtp");
  e.input->one("dump_modify b binary no pad 4 pvd " + dir + "/clumps.pvd");
  e.input->one("run 10");
  auto pd = read_vtp(dir + "/d_0010.vtp");
  REQUIRE(pd->GetNumberOfPoints() == 1);
  CHECK(pd->GetPointData()->GetArray("type")->GetComponent(0, 0) == 2);
  CHECK(pd->GetPointData()->GetArray("nspheres")->GetComponent(0, 0) == 2);
  const auto entries = pvd_entries(dir + "/clumps.pvd");
  REQUIRE(entries.size() == 2);
  CHECK(entries[0].second == "d_0000.vtp");
  CHECK(entries[1].second == "d_0010.vtp");
}

TEST_CASE("write_dump bodies/vtk: one file of the current state, no collection", "[dump][vtk][multisphere]") {
  const std::string dir = fresh_dir("write_dump");
  Engine e(MPI_COMM_WORLD);
  setup(e);
  e.input->one("fix ms all multisphere");
  e.input->one("create_clump tri -0.01 0 0 vel 0.1 0 0");
  e.input->one("create_clump dumb 0.01 0 0");
  e.input->one("dump b all bodies/vtk 10 " + dir + "/bodies_*.vtp");
  e.input->one("run 15");
  const auto before = pvd_entries(dir + "/bodies_.pvd");
  REQUIRE(before.size() == 2);
  e.input->one("write_dump all bodies/vtk " + dir + "/now.vtp");
  auto pd = read_vtp(dir + "/now.vtp");
  REQUIRE(pd->GetNumberOfPoints() == 2);
  const Bodies& B = dynamic_cast<FixMultisphere*>(e.clumps)->bodies();
  double x[3];
  pd->GetPoint(0, x);
  CHECK(x[0] == B.xcm[0][0]);  // the state at step 15
  CHECK(pd->GetFieldData()->GetArray("Step")->GetComponent(0, 0) == 15);
  CHECK_FALSE(fs::exists(dir + "/now.pvd"));
  CHECK(pvd_entries(dir + "/bodies_.pvd") == before);
  // a collection only when asked for
  e.input->one("write_dump all bodies/vtk " + dir + "/asked.vtp modify pvd " + dir + "/asked.pvd");
  REQUIRE(pvd_entries(dir + "/asked.pvd").size() == 1);
}

TEST_CASE("dump bodies/vtk: errors", "[dump][vtk][multisphere]") {
  using Catch::Matchers::Contains;
  const std::string dir = fresh_dir("errors");
  Engine e(MPI_COMM_WORLD);
  setup(e);
  CHECK_THROWS_WITH(e.input->one("dump b all bodies/vtk 10 " + dir + "/b_*.vtu"), Contains(".vtp"));
  CHECK_THROWS_WITH(e.input->one("dump b all bodies/vtk 10 " + dir + "/b_*.vtp id"), Contains("no fields"));
  CHECK_THROWS_WITH(e.input->one("dump b all bodies/vtk 10 " + dir + "/nodir/b_*.vtp"), Contains("nodir"));
  // without fix multisphere the first run stops with a clear message
  e.input->one("dump b all bodies/vtk 10 " + dir + "/b_*.vtp");
  CHECK_THROWS_WITH(e.input->one("run 10"), Contains("no fix multisphere"));
}

TEST_CASE("Engine::clumps is the fix multisphere while it exists, through redefinition and unfix",
          "[multisphere]") {
  Engine e(MPI_COMM_WORLD);
  setup(e);
  CHECK(e.clumps == nullptr);
  CHECK_THROWS_WITH(e.input->one("create_clump tri 0 0 0"), Catch::Contains("needs fix multisphere"));
  e.input->one("fix ms all multisphere");
  auto* first = dynamic_cast<FixMultisphere*>(e.modify->find_fix("ms"));
  REQUIRE(first != nullptr);
  CHECK(e.clumps == first);
  e.input->one("create_clump tri -0.01 0.002 0.0");
  e.input->one("create_clump dumb 0.01 -0.002 0.001");
  // redefined with the same id: the new fix keeps the clumps and is the handle
  e.input->one("fix ms all multisphere");
  auto* second = dynamic_cast<FixMultisphere*>(e.modify->find_fix("ms"));
  REQUIRE(second != nullptr);
  CHECK(e.clumps == second);
  CHECK(e.clumps->bodies().size() == 2);
  e.input->one("run 10");
  e.input->one("unfix ms");
  CHECK(e.clumps == nullptr);
  e.input->one("compute o all orientation axis 1 0 0");
  CHECK_THROWS_WITH(e.input->one("run 1"), Catch::Contains("needs fix multisphere"));
}
