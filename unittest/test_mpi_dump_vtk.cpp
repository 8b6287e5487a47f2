// dump custom/vtk on 1, 2 and 4 ranks (run by ctest at each count).
//
// A small bed is run with a VTK dump every few steps; the files are read back
// with VTK's own readers and every field of the last frame is compared with the
// particle state gathered from all ranks. On several ranks the .pvtp index must
// name one piece per rank and the pieces together must hold every particle
// exactly once. The .pvd collection must list every frame with its time. The
// gathered formats (legacy .vtk, text dump custom sorted by id) are checked too.
#include <mpi.h>

#include <vtkDataArray.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkPolyDataReader.h>
#include <vtkSmartPointer.h>
#include <vtkXMLDataElement.h>
#include <vtkXMLPPolyDataReader.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLUtilities.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/input.h"
#include "core/logger.h"
#include "particles/particles.h"
#include "script_engine.h"

namespace {

namespace fs = std::filesystem;

using granary::test::world_rank;
using granary::test::world_size;

// A fresh output directory per test and rank count (ctest may run counts at once).
std::string fresh_dir(const std::string& name) {
  const std::string dir = "dump_vtk_np" + std::to_string(world_size()) + "/" + name;
  if (world_rank() == 0) {
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  return dir;
}

const double kDt = 1e-5;

// spread: split the box across x and y so that every rank owns particles;
// otherwise the default split along z leaves the upper ranks empty.
void setup_bed(granary::Engine& e, bool spread = true) {
  if (spread) e.input->one("processors * * 1");
  const std::vector<std::string> lines = {
      "units si",
      "atom_style granular",
      "boundary f f f",
      "newton off",
      "region box block 0 0.02 0 0.02 0 0.03 units box",
      "create_box 2 box",
      "neighbor 0.0005 bin",
      "neigh_modify delay 0",
      granary::test::materials(2, 5.e6, 0.45, 0.7, 0.5),
      "pair_style gran model hertz tangential history",
      "pair_coeff * *",
      "timestep 1e-5",
      "region fill block 0.001 0.019 0.001 0.019 0.001 0.012 units box",
      "create_atoms 1 random 150 4711 fill overlap 0.0021 maxtry 200",
      "create_atoms 2 random 60 815 fill overlap 0.0021 maxtry 200",
      "set type 1 diameter 0.002 density 2500",
      "set type 2 diameter 0.0015 density 2000",
      "velocity all set 0.05 -0.1 -0.5",
      "fix gravi all gravity 9.81 vector 0.0 0.0 -1.0",
      "fix zwall all wall/gran model hertz tangential history primitive type 1 zplane 0.0",
      "fix integr all nve/sphere",
      "compute pa all property/atom vx radius",
      "variable vz2 atom vz*2",
  };
  granary::test::run(e, lines);
}

// Particle state gathered on every rank: id -> values.
enum Col { kType, kX, kY, kZ, kVx, kVy, kVz, kFx, kFy, kFz, kWx, kWy, kWz, kR, kM, kRho, kNumCols };
using State = std::map<long long, std::vector<double>>;

State gather_state(granary::Engine& e) {
  const granary::Particles& p = *e.particles;
  std::vector<double> mine;
  for (int i = 0; i < p.nlocal; ++i) {
    mine.push_back(static_cast<double>(p.id[i]));
    mine.push_back(p.type[i]);
    for (const auto* a : {&p.x, &p.v, &p.f, &p.omega})
      for (int d = 0; d < 3; ++d)
        mine.push_back((*a)[i][d]);
    mine.push_back(p.radius[i]);
    mine.push_back(p.rmass[i]);
    mine.push_back(p.density[i]);
  }
  int n = static_cast<int>(mine.size());
  std::vector<int> counts(world_size()), displs(world_size(), 0);
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, MPI_COMM_WORLD);
  for (int r = 1; r < world_size(); ++r)
    displs[r] = displs[r - 1] + counts[r - 1];
  std::vector<double> all(displs.back() + counts.back());
  MPI_Allgatherv(mine.data(), n, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE,
                 MPI_COMM_WORLD);
  State s;
  for (std::size_t k = 0; k < all.size(); k += kNumCols + 1) {
    s[static_cast<long long>(all[k])] =
        std::vector<double>(all.begin() + k + 1, all.begin() + k + 1 + kNumCols);
  }
  return s;
}

std::string read_text(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Root element of an XML file (owned by the smart pointer); null if it does not parse.
vtkSmartPointer<vtkXMLDataElement> read_xml(const std::string& file) {
  vtkSmartPointer<vtkXMLDataElement> root;
  root.TakeReference(vtkXMLUtilities::ReadElementFromFile(file.c_str()));
  return root;
}

// Check every point of `pd` against the state (bit for bit when `exact`).
void check_points(vtkPolyData* pd, const State& s, bool exact, std::set<long long>* seen = nullptr) {
  vtkDataArray* ids = pd->GetPointData()->GetArray("id");
  vtkDataArray* type = pd->GetPointData()->GetArray("type");
  vtkDataArray* v = pd->GetPointData()->GetArray("v");
  vtkDataArray* f = pd->GetPointData()->GetArray("f");
  vtkDataArray* w = pd->GetPointData()->GetArray("omega");
  vtkDataArray* r = pd->GetPointData()->GetArray("radius");
  vtkDataArray* m = pd->GetPointData()->GetArray("mass");
  vtkDataArray* rho = pd->GetPointData()->GetArray("density");
  vtkDataArray* dia = pd->GetPointData()->GetArray("diameter");
  vtkDataArray* cpa = pd->GetPointData()->GetArray("c_pa[1]");
  vtkDataArray* vz2 = pd->GetPointData()->GetArray("v_vz2");
  REQUIRE(ids);
  REQUIRE(type);
  REQUIRE(v);
  REQUIRE(f);
  REQUIRE(w);
  REQUIRE(r);
  REQUIRE(m);
  REQUIRE(rho);
  REQUIRE(dia);
  REQUIRE(cpa);
  REQUIRE(vz2);
  CHECK(v->GetNumberOfComponents() == 3);
  CHECK(pd->GetPointData()->GetArray("vx") == nullptr);  // grouped into "v"
  CHECK(pd->GetNumberOfVerts() == pd->GetNumberOfPoints());
  auto same = [exact](double a, double b) {
    return exact ? a == b : std::fabs(a - b) <= 1e-12 * std::max(1.0, std::fabs(b));
  };
  long long bad = 0, missing = 0;
  for (vtkIdType k = 0; k < pd->GetNumberOfPoints(); ++k) {
    const long long id = static_cast<long long>(ids->GetTuple1(k));
    if (seen) seen->insert(id);
    auto it = s.find(id);
    if (it == s.end()) {
      ++missing;
      continue;
    }
    const std::vector<double>& q = it->second;
    double x[3];
    pd->GetPoint(k, x);
    bool ok = type->GetTuple1(k) == q[kType];
    for (int d = 0; d < 3; ++d) {
      ok = ok && same(x[d], q[kX + d]) && same(v->GetComponent(k, d), q[kVx + d]) &&
           same(f->GetComponent(k, d), q[kFx + d]) && same(w->GetComponent(k, d), q[kWx + d]);
    }
    ok = ok && same(r->GetTuple1(k), q[kR]) && same(m->GetTuple1(k), q[kM]) &&
         same(rho->GetTuple1(k), q[kRho]) && same(dia->GetTuple1(k), 2.0 * q[kR]) &&
         same(cpa->GetTuple1(k), q[kVx]) && same(vz2->GetTuple1(k), 2.0 * q[kVz]);
    if (!ok) ++bad;
  }
  CHECK(missing == 0);
  CHECK(bad == 0);
}

const char* kFields =
    "id type x y z vx vy vz fx fy fz omegax omegay omegaz tqx tqy tqz radius diameter mass density c_pa[1] "
    "v_vz2";

// Run the bed with a dump every 20 steps to step 60 and check the files.
void run_and_check(const std::string& dir, const std::vector<std::string>& modify, bool exact,
                   const std::string& header_must, const std::string& header_must_not, bool spread = true) {
  granary::Engine e(MPI_COMM_WORLD);
  e.logger->set_screen(false);
  setup_bed(e, spread);
  e.input->one("dump d all custom/vtk 20 " + dir + "/particles_*.vtp " + kFields);
  for (const auto& m : modify)
    e.input->one("dump_modify d " + m);
  e.input->one("run 60");
  const State s = gather_state(e);
  REQUIRE(s.size() == 210);
  const int np = world_size();
  if (world_rank() != 0) return;

  // the last frame against the state
  std::set<long long> seen;
  if (np == 1) {
    const std::string file = dir + "/particles_60.vtp";
    REQUIRE(fs::exists(file));
    const std::string text = read_text(file);
    CHECK(text.find(header_must) != std::string::npos);
    if (!header_must_not.empty()) CHECK(text.find(header_must_not) == std::string::npos);
    auto reader = vtkSmartPointer<vtkXMLPolyDataReader>::New();
    reader->SetFileName(file.c_str());
    reader->Update();
    vtkPolyData* pd = reader->GetOutput();
    CHECK(pd->GetNumberOfPoints() == 210);
    check_points(pd, s, exact, &seen);
  } else {
    const std::string index = dir + "/particles_60.pvtp";
    REQUIRE(fs::exists(index));
    auto root = read_xml(index);
    REQUIRE(root);
    CHECK(std::string(root->GetAttribute("type")) == "PPolyData");
    vtkXMLDataElement* ppd = root->FindNestedElementWithName("PPolyData");
    REQUIRE(ppd);
    std::vector<std::string> pieces;
    for (int k = 0; k < ppd->GetNumberOfNestedElements(); ++k) {
      vtkXMLDataElement* el = ppd->GetNestedElement(k);
      if (std::string(el->GetName()) == "Piece") pieces.push_back(el->GetAttribute("Source"));
    }
    REQUIRE(static_cast<int>(pieces.size()) == np);
    long long total = 0;
    int nonempty = 0;
    for (const auto& piece : pieces) {
      const std::string file = dir + "/" + piece;
      REQUIRE(fs::exists(file));
      const std::string text = read_text(file);
      CHECK(text.find(header_must) != std::string::npos);
      if (!header_must_not.empty()) CHECK(text.find(header_must_not) == std::string::npos);
      auto reader = vtkSmartPointer<vtkXMLPolyDataReader>::New();
      reader->SetFileName(file.c_str());
      reader->Update();
      total += reader->GetOutput()->GetNumberOfPoints();
      nonempty += reader->GetOutput()->GetNumberOfPoints() > 0;
      check_points(reader->GetOutput(), s, exact, &seen);
    }
    CHECK(total == 210);  // with `seen` covering all ids: every particle exactly once
    if (spread) CHECK(nonempty == np);
    // the parallel reader joins the pieces
    auto preader = vtkSmartPointer<vtkXMLPPolyDataReader>::New();
    preader->SetFileName(index.c_str());
    preader->Update();
    CHECK(preader->GetOutput()->GetNumberOfPoints() == 210);
  }
  CHECK(seen.size() == 210);

  // the collection lists every frame with its simulated time
  const std::string pvd = dir + "/particles_.pvd";
  REQUIRE(fs::exists(pvd));
  CHECK_FALSE(fs::exists(pvd + ".tmp"));
  auto root = read_xml(pvd);
  REQUIRE(root);
  CHECK(std::string(root->GetName()) == "VTKFile");
  CHECK(std::string(root->GetAttribute("type")) == "Collection");
  vtkXMLDataElement* coll = root->FindNestedElementWithName("Collection");
  REQUIRE(coll);
  REQUIRE(coll->GetNumberOfNestedElements() == 4);
  for (int k = 0; k < 4; ++k) {
    vtkXMLDataElement* ds = coll->GetNestedElement(k);
    CHECK(std::string(ds->GetName()) == "DataSet");
    const std::string file = ds->GetAttribute("file");
    const std::string expect = "particles_" + std::to_string(20 * k) + (np == 1 ? ".vtp" : ".pvtp");
    CHECK(file == expect);
    CHECK(fs::exists(dir + "/" + file));
    CHECK(std::stod(ds->GetAttribute("timestep")) == Approx(20 * k * kDt).epsilon(1e-14).margin(1e-300));
  }
}

}  // namespace

TEST_CASE("dump custom/vtk: binary, zlib-compressed round trip", "[dump][vtk][mpi]") {
  const std::string dir = fresh_dir("binary");
  run_and_check(dir, {}, true, "compressor=\"vtkZLibDataCompressor\"", "format=\"ascii\"");
}

TEST_CASE("dump custom/vtk: binary without compression", "[dump][vtk][mpi]") {
  const std::string dir = fresh_dir("uncompressed");
  run_and_check(dir, {"compression none"}, true, "format=\"binary\"", "compressor=", false);  // empty pieces
}

TEST_CASE("dump custom/vtk: ascii round trip", "[dump][vtk][mpi]") {
  const std::string dir = fresh_dir("ascii");
  run_and_check(dir, {"binary no"}, true, "format=\"ascii\"",
                "format=\"binary\"");  // VTK writes round-trip digits
}

TEST_CASE("dump custom/vtk: legacy .vtk is gathered into one file", "[dump][vtk][mpi]") {
  const std::string dir = fresh_dir("legacy");
  granary::Engine e(MPI_COMM_WORLD);
  e.logger->set_screen(false);
  setup_bed(e);
  e.input->one("dump d all custom/vtk 25 " + dir + "/legacy_*.vtk " + kFields);
  e.input->one("run 50");
  const State s = gather_state(e);
  if (world_rank() == 0) {
    for (int step : {0, 25, 50})
      CHECK(fs::exists(dir + "/legacy_" + std::to_string(step) + ".vtk"));
    CHECK(std::count_if(fs::directory_iterator(dir), fs::directory_iterator(),
                        [](const fs::directory_entry&) { return true; }) == 3);
    auto reader = vtkSmartPointer<vtkPolyDataReader>::New();
    reader->SetFileName((dir + "/legacy_50.vtk").c_str());
    reader->Update();
    vtkPolyData* pd = reader->GetOutput();
    CHECK(pd->GetNumberOfPoints() == 210);
    std::set<long long> seen;
    check_points(pd, s, true, &seen);
    CHECK(seen.size() == 210);
  }
}

TEST_CASE("dump custom: frames gathered from every rank, sorted by id", "[dump][custom][mpi]") {
  const std::string dir = fresh_dir("text");
  granary::Engine e(MPI_COMM_WORLD);
  e.logger->set_screen(false);
  setup_bed(e);
  e.input->one("dump d all custom 30 " + dir + "/all.txt id type x y z vx vy vz");
  e.input->one("dump_modify d sort id precision 17");
  e.input->one("run 30");
  const State s = gather_state(e);
  if (world_rank() != 0) return;
  std::ifstream in(dir + "/all.txt");
  std::string line;
  int frames = 0;
  std::vector<std::vector<double>> last;
  while (std::getline(in, line)) {
    if (line != "ITEM: TIMESTEP") continue;
    ++frames;
    std::getline(in, line);
    std::getline(in, line);  // ITEM: NUMBER OF ATOMS
    std::getline(in, line);
    const int n = std::stoi(line);
    for (int k = 0; k < 4; ++k)
      std::getline(in, line);  // BOX BOUNDS + 3 lines
    std::getline(in, line);
    CHECK(line == "ITEM: ATOMS id type x y z vx vy vz");
    last.assign(n, std::vector<double>(8));
    for (int i = 0; i < n; ++i)
      for (int c = 0; c < 8; ++c)
        in >> last[i][c];
    std::getline(in, line);
  }
  CHECK(frames == 2);
  REQUIRE(last.size() == 210);
  long long bad = 0;
  for (std::size_t i = 0; i < last.size(); ++i) {
    const long long id = static_cast<long long>(last[i][0]);
    if (i > 0 && !(last[i][0] > last[i - 1][0])) ++bad;  // strictly ascending ids
    const auto& q = s.at(id);
    for (int d = 0; d < 3; ++d)
      if (last[i][2 + d] != q[kX + d] || last[i][5 + d] != q[kVx + d]) ++bad;
  }
  CHECK(bad == 0);
}
