// compute wall/gran/local (and dump local/gran/vtk of it) on 1, 2 and 4
// ranks (run by ctest at each count): spheres resting on a mesh floor and on
// a primitive floor report their weight as the normal force, the Hertz
// overlap of that weight, and the contact point and area of the geometry;
// the values LIGGGHTS 3.8 gives for the same script
// (unittest/scripts/wall_gran_local, reference
// unittest/reference/wall_gran_local.liggghts.dump); every wall contact of a
// settled bed once, whatever the decomposition, with the mesh and wall ids
// and groups; and the errors.
#include <mpi.h>

#include <vtkCellData.h>
#include <vtkCell.h>
#include <vtkDataArray.h>
#include <vtkDataSet.h>
#include <vtkIdList.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkXMLPolyDataReader.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "compute/compute.h"
#include "core/engine.h"
#include "core/modify.h"
#include "mesh_files.h"
#include "particles/particles.h"
#include "script_engine.h"

using Catch::Matchers::Contains;
using granary::Vec3;

namespace {

namespace fs = std::filesystem;
constexpr double kPi = 3.14159265358979323846;
constexpr double kG = 9.81;

using granary::test::world_rank;
using granary::test::world_size;

// A fresh output directory per test and rank count (ctest may run counts at
// once), with a floor mesh: the square -20..20 mm in x and y at z = 0, 4 x 4
// cells of two triangles (normal +z).
std::string fresh_dir(const std::string& name) {
  const std::string dir = "wall_gran_local_np" + std::to_string(world_size()) + "/" + name;
  if (world_rank() == 0) {
    fs::remove_all(dir);
    fs::create_directories(dir);
    std::vector<mesh_files::Triangle> floor;
    mesh_files::add_rectangle(floor, Vec3(-0.02, -0.02, 0), Vec3(0.04, 0, 0), Vec3(0, 0.04, 0), 4, 4);
    mesh_files::write_ascii(dir + "/floor.stl", floor);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  return dir;
}

using Row = std::vector<double>;

// The local rows of compute `id` of every rank, on every rank (collective).
std::vector<Row> all_rows(granary::Engine& e, const std::string& id) {
  granary::Compute* c = e.modify->find_compute(id);
  REQUIRE(c);
  c->compute_local();
  const int ncols = c->size_local_cols;
  const std::vector<double>& mine = c->array_local;
  int n = static_cast<int>(mine.size());
  std::vector<int> counts(world_size()), displs(world_size(), 0);
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, MPI_COMM_WORLD);
  for (int r = 1; r < world_size(); ++r)
    displs[r] = displs[r - 1] + counts[r - 1];
  std::vector<double> all(displs.back() + counts.back());
  MPI_Allgatherv(mine.data(), n, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE,
                 MPI_COMM_WORLD);
  std::vector<Row> rows;
  for (std::size_t k = 0; k + ncols <= all.size(); k += ncols)
    rows.emplace_back(all.begin() + k, all.begin() + k + ncols);
  return rows;
}

Vec3 v3(const Row& r, int at) {
  return Vec3(r[at], r[at + 1], r[at + 2]);
}

// Every particle: id -> (x, radius, mass, type), on every rank.
struct Sphere {
  Vec3 x;
  double r, m;
  int type;
};
std::map<long long, Sphere> spheres(granary::Engine& e) {
  const auto& p = *e.particles;
  std::vector<double> mine;
  for (int i = 0; i < p.nlocal; ++i)
    mine.insert(mine.end(), {static_cast<double>(p.id[i]), p.x[i][0], p.x[i][1], p.x[i][2], p.radius[i],
                             p.rmass[i], static_cast<double>(p.type[i])});
  int n = static_cast<int>(mine.size());
  std::vector<int> counts(world_size()), displs(world_size(), 0);
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, MPI_COMM_WORLD);
  for (int r = 1; r < world_size(); ++r)
    displs[r] = displs[r - 1] + counts[r - 1];
  std::vector<double> all(displs.back() + counts.back());
  MPI_Allgatherv(mine.data(), n, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE,
                 MPI_COMM_WORLD);
  std::map<long long, Sphere> out;
  for (std::size_t k = 0; k + 7 <= all.size(); k += 7)
    out[static_cast<long long>(all[k])] = {Vec3(all[k + 1], all[k + 2], all[k + 3]), all[k + 4], all[k + 5],
                                           static_cast<int>(all[k + 6])};
  return out;
}

// The frames of a LAMMPS `dump local` file: step -> rows.
std::map<long long, std::vector<Row>> read_dump_local(const std::string& file) {
  std::ifstream in(file);
  std::map<long long, std::vector<Row>> frames;
  std::string line;
  long long step = -1;
  while (std::getline(in, line)) {
    if (line.rfind("ITEM: TIMESTEP", 0) == 0) {
      std::getline(in, line);
      step = std::stoll(line);
      frames[step];
    } else if (line.rfind("ITEM: ", 0) == 0) {
      if (line.rfind("ITEM: NUMBER", 0) == 0) std::getline(in, line);
      if (line.rfind("ITEM: BOX", 0) == 0)
        for (int d = 0; d < 3; ++d)
          std::getline(in, line);
    } else if (step >= 0 && !line.empty()) {
      std::istringstream ss(line);
      Row r;
      double v;
      while (ss >> v)
        r.push_back(v);
      frames[step].push_back(r);
    }
  }
  return frames;
}

// The contact lines of a VTK frame of wall contacts as rows in LIGGGHTS'
// column order of `compute wall/gran/local pos vel id force force_normal
// force_tangential torque history contactArea delta contactPoint` (35
// columns with 3 history values).
std::vector<Row> frame_rows(vtkDataSet* ds) {
  std::vector<Row> rows;
  vtkCellData* cd = ds->GetCellData();
  const char* names[] = {"wall_vel",     "vel",          "mesh_id",          "triangle_id", "id",
                         "force",        "force_normal", "force_tangential", "torque",      "history",
                         "contact_area", "delta",        "contact_point"};
  for (const char* n : names) {
    INFO("cell array " << n);
    REQUIRE(cd->GetArray(n) != nullptr);
  }
  for (vtkIdType k = 0; k < ds->GetNumberOfCells(); ++k) {
    Row r;
    vtkIdList* ids = ds->GetCell(k)->GetPointIds();
    REQUIRE(ids->GetNumberOfIds() == 2);
    for (int e = 0; e < 2; ++e) {
      double x[3];
      ds->GetPoint(ids->GetId(e), x);
      r.insert(r.end(), x, x + 3);
    }
    for (const char* n : names) {
      vtkDataArray* a = cd->GetArray(n);
      for (int q = 0; q < a->GetNumberOfComponents(); ++q)
        r.push_back(a->GetComponent(k, q));
    }
    rows.push_back(r);
  }
  return rows;
}

vtkSmartPointer<vtkDataSet> read_vtp(const std::string& file) {
  auto reader = vtkSmartPointer<vtkXMLPolyDataReader>::New();
  reader->SetFileName(file.c_str());
  reader->Update();
  return vtkDataSet::SafeDownCast(reader->GetOutputDataObject(0));
}

std::vector<std::string> script_lines(const std::string& file) {
  std::ifstream in(file);
  std::vector<std::string> out;
  std::string line;
  while (std::getline(in, line))
    out.push_back(line);
  return out;
}

// Box, two materials, Hertz with tangential history, gravity.
std::vector<std::string> box(const std::string& boundary = "f f f") {
  return {"units si",
          "atom_style granular",
          "atom_modify map array",
          "boundary " + boundary,
          "newton off",
          "communicate single vel yes",
          "region domain block -0.02 0.02 -0.02 0.02 -0.01 0.03 units box",
          "create_box 2 domain",
          "neighbor 0.0005 bin",
          "fix m1 all property/global youngsModulus peratomtype 5.e6 1.e7",
          "fix m2 all property/global poissonsRatio peratomtype 0.45 0.3",
          "fix m3 all property/global coefficientRestitution peratomtypepair 2 0.3 0.3 0.3 0.3",
          "fix m4 all property/global coefficientFriction peratomtypepair 2 0.5 0.4 0.4 0.3",
          "pair_style gran model hertz tangential history",
          "pair_coeff * *",
          "timestep 0.00001",
          "fix gravi all gravity 9.81 vector 0.0 0.0 -1.0"};
}

}  // namespace

// Spheres of two sizes and materials settle on a floor of material 1 (a
// mesh, or the primitive zplane 0): each reports the weight m g as its
// normal force, the overlap of Hertz' law for that force, 4/3 Y* sqrt(r
// delta) delta = m g, the contact point below its centre on the floor, and
// the area of the circle where the floor's plane cuts it.
TEST_CASE("compute wall/gran/local: spheres resting on a floor report their weight",
          "[wall_gran_local][mpi]") {
  const std::string dir = fresh_dir("resting");
  for (const bool mesh : {true, false}) {
    INFO((mesh ? "mesh floor" : "primitive floor"));
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    s.cmds(box());
    if (mesh)
      s.cmds({"fix floor all mesh/surface file " + dir + "/floor.stl type 1",
              "fix walls all wall/gran model hertz tangential history mesh n_meshes 1 meshes floor"});
    else
      s.cmd("fix walls all wall/gran model hertz tangential history primitive type 1 zplane 0.0");
    // just touching: they settle without bouncing off
    s.cmds({"create_atoms 1 single -0.013 -0.012 0.001 units box",
            "create_atoms 2 single 0.004 0.0055 0.0008 units box",
            "create_atoms 1 single 0.011 -0.003 0.0015 units box", "set atom 1 diameter 0.002 density 2500",
            "set atom 2 diameter 0.0016 density 3000", "set atom 3 diameter 0.003 density 2000",
            "fix integr all nve/sphere",
            "compute cw all wall/gran/local pos vel id force force_normal force_tangential torque history "
            "contactArea delta contactPoint",
            "run 3000"});
    const std::vector<Row> rows = all_rows(s.e, "cw");
    REQUIRE(rows.size() == 3);
    const auto all = spheres(s.e);
    for (const Row& r : rows) {
      REQUIRE(r.size() == 35);
      const long long id = static_cast<long long>(r[14]);
      INFO("sphere " << id);
      REQUIRE(all.count(id));
      const Sphere& sp = all.at(id);
      // positions: the contact point on the floor below the centre
      CHECK(v3(r, 3) == sp.x);
      CHECK(v3(r, 0) == Vec3(sp.x[0], sp.x[1], 0.0));
      CHECK(v3(r, 32) == v3(r, 0));
      CHECK(v3(r, 6).norm() == 0.0);  // the floor does not move
      CHECK(v3(r, 9).norm() < 1e-6);  // at rest
      // mesh id, triangle (the one under the centre), particle id
      if (mesh) {
        CHECK(r[12] == 0.0);
        // cells of 10 mm from -20 mm; cell (i, j) has triangles 2 (4 i + j) and
        // 2 (4 i + j) + 1, split along the diagonal from (0, 0) to (1, 1) of the
        // cell when i + j is even, else from (1, 0) to (0, 1)
        const int ci = static_cast<int>(std::floor((sp.x[0] + 0.02) / 0.01));
        const int cj = static_cast<int>(std::floor((sp.x[1] + 0.02) / 0.01));
        const double u = (sp.x[0] + 0.02) / 0.01 - ci, v = (sp.x[1] + 0.02) / 0.01 - cj;
        const bool second = (ci + cj) % 2 == 0 ? v > u : u + v > 1;
        CHECK(r[13] == 2 * (4 * ci + cj) + (second ? 1 : 0));
      } else {
        CHECK(r[12] == -1.0);
        CHECK(r[13] == -1.0);
      }
      // the weight, along the normal
      const double weight = sp.m * kG;
      CHECK(v3(r, 15)[2] == Approx(weight).epsilon(1e-6));
      CHECK((v3(r, 18) - Vec3(0, 0, weight)).norm() < 1e-6 * weight);
      CHECK(v3(r, 21).norm() < 1e-6 * weight);
      CHECK(v3(r, 24).norm() < 1e-6 * weight * sp.r);
      // Hertz: the overlap that carries the weight; Y* of the sphere's material with the floor's
      const double y[2] = {5e6, 1e7}, nu[2] = {0.45, 0.3};
      const double ystar =
          1.0 / ((1 - nu[0] * nu[0]) / y[0] + (1 - nu[sp.type - 1] * nu[sp.type - 1]) / y[sp.type - 1]);
      const double delta = std::pow(3 * weight / (4 * ystar * std::sqrt(sp.r)), 2.0 / 3.0);
      CHECK(r[31] == Approx(delta).epsilon(1e-6));
      CHECK(r[31] == Approx(sp.r - sp.x[2]).epsilon(1e-12));
      CHECK(r[30] == Approx(kPi * (2 * sp.r * r[31] - r[31] * r[31])).epsilon(1e-12));
    }
  }
}

// LIGGGHTS 3.8 (dump local of every column, %.17g) for the same script, run
// unchanged by Granary (its dump local, and dump local/gran/vtk besides).
TEST_CASE(
    "compute wall/gran/local, dump local and dump local/gran/vtk: LIGGGHTS 3.8's values for four spheres on "
    "two meshes",
    "[wall_gran_local][mpi][liggghts]") {
  const fs::path src(GRANARY_SOURCE_DIR);
  const fs::path scripts = src / "unittest/scripts/wall_gran_local";
  const auto reference = read_dump_local((src / "unittest/reference/wall_gran_local.liggghts.dump").string());
  REQUIRE(reference.size() == 4);
  const std::string dir = fresh_dir("liggghts");
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  for (std::string line : script_lines((scripts / "in.wall_gran_local").string())) {
    // the script's files, in the test's directory
    for (const char* file : {"floor.stl", "side.stl", "wall_gran_local.dump", "wallcontacts*.vtp"}) {
      const std::string name(file);
      const auto at = line.find(" " + name);
      if (at == std::string::npos) continue;
      const bool input = name.find(".stl") != std::string::npos;
      line.replace(at + 1, name.size(), input ? (scripts / name).string() : dir + "/" + name);
    }
    s.cmd(line);
  }
  const auto written = read_dump_local(dir + "/wall_gran_local.dump");
  CHECK(written.size() == reference.size());
  for (const auto& [step, expect] : reference) {
    for (const char* source : {"dump local", "dump local/gran/vtk"}) {
      INFO("step " << step << ", " << source);
      std::vector<Row> got;
      if (source == std::string("dump local")) {
        REQUIRE(written.count(step));
        got = written.at(step);
      } else {
        const auto ds = read_vtp(dir + "/wallcontacts" + std::to_string(step) + ".vtp");
        REQUIRE(ds);
        got = frame_rows(ds);
      }
      REQUIRE(got.size() == expect.size());
      REQUIRE(expect.size() == 4);
      for (const Row& want : expect) {
        REQUIRE(want.size() == 35);
        // the same contact: mesh, triangle, particle
        const Row* match = nullptr;
        for (const Row& g : got)
          if (g[12] == want[12] && g[13] == want[13] && g[14] == want[14]) match = &g;
        INFO("contact of particle " << want[14] << " with triangle " << want[13] << " of mesh " << want[12]);
        REQUIRE(match);
        const Row& g = *match;
        REQUIRE(g.size() == 35);
        // positions and velocities: the same to round-off
        for (int c = 0; c < 12; ++c)
          CHECK(g[c] == Approx(want[c]).epsilon(1e-12).margin(1e-15));
        // forces, torques, history (to 1e-10 of the largest component of
        // each vector; the parts of the force to 1e-10 of the force: LIGGGHTS'
        // split leaves round-off of 1e-17 N in a zero tangential part)
        const double force = v3(want, 15).norm();
        for (int at : {15, 18, 21, 24, 27}) {
          double scale = std::max({std::abs(want[at]), std::abs(want[at + 1]), std::abs(want[at + 2])});
          if (at <= 21) scale = std::max(scale, force);
          INFO("columns " << at + 1 << "-" << at + 3);
          CHECK((v3(g, at) - v3(want, at)).norm() <= 1e-10 * scale + 1e-30);
        }
        CHECK(g[30] == Approx(want[30]).epsilon(1e-10));  // contact area
        CHECK(g[31] == Approx(want[31]).epsilon(1e-10));  // overlap
        // LIGGGHTS writes zeros as the contact point of wall contacts; Granary
        // the contact point on the wall (the first position)
        CHECK(v3(want, 32).norm() == 0.0);
        CHECK(v3(g, 32) == v3(g, 0));
      }
    }
  }
}

// A bed of spheres settled on a mesh floor between two primitive walls
// (x = -9.5 and 9.5 mm), periodic in y: every sphere within its radius of a
// wall is one row, listed once whatever the decomposition, with the wall's
// id (mesh 0; the primitive walls -1 and -2, in the order of their fixes);
// the group of the compute and of the dump select the spheres.
TEST_CASE("compute wall/gran/local: every wall contact once on any number of ranks, groups",
          "[wall_gran_local][mpi][vtk]") {
  const std::string dir = fresh_dir("bed");
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds(box("f p f"));
  s.cmds({"fix floor all mesh/surface file " + dir + "/floor.stl type 1",
          "fix walls all wall/gran model hertz tangential history mesh n_meshes 1 meshes floor",
          "fix xlo all wall/gran model hertz tangential history primitive type 2 xplane -0.0095",
          "fix xhi all wall/gran model hertz tangential history primitive type 2 xplane 0.0095",
          "region fill block -0.0085 0.0085 -0.019 0.019 0.001 0.02 units box",
          "create_atoms 1 random 300 4711 fill overlap 0.0021 maxtry 200",
          "create_atoms 2 random 100 815 fill overlap 0.0021 maxtry 200",
          "set type 1 diameter 0.002 density 2500", "set type 2 diameter 0.0015 density 2000",
          "fix integr all nve/sphere", "group small type 2", "run 6000",
          "compute all_c all wall/gran/local id delta", "compute small_c small wall/gran/local pos id",
          "compute pos_c all wall/gran/local pos id",
          "dump all_d all local/gran/vtk 100 " + dir + "/all*.vtp small_c",
          "dump small_d small local/gran/vtk 100 " + dir + "/small*.vtp pos_c", "run 0"});
  const auto all = spheres(s.e);
  REQUIRE(all.size() == 400);
  // the contacts the geometry gives: (wall id, particle) -> overlap
  std::map<std::pair<int, long long>, double> expect;
  for (const auto& [id, sp] : all) {
    if (sp.x[2] < sp.r) expect[{0, id}] = sp.r - sp.x[2];
    if (sp.x[0] + 0.0095 < sp.r) expect[{-1, id}] = sp.r - (sp.x[0] + 0.0095);
    if (0.0095 - sp.x[0] < sp.r) expect[{-2, id}] = sp.r - (0.0095 - sp.x[0]);
  }
  int floor = 0, side = 0;
  for (const auto& [key, d] : expect)
    (key.first == 0 ? floor : side) += 1;
  CHECK(floor > 50);
  CHECK(side > 5);
  const std::vector<Row> rows = all_rows(s.e, "all_c");
  CHECK(rows.size() == expect.size());
  std::map<std::pair<int, long long>, int> seen;
  for (const Row& r : rows) {
    REQUIRE(r.size() == 4);
    const std::pair<int, long long> key{static_cast<int>(r[0]), static_cast<long long>(r[2])};
    INFO("wall " << key.first << ", particle " << key.second);
    ++seen[key];
    REQUIRE(expect.count(key));
    CHECK(r[3] == Approx(expect[key]).epsilon(1e-9));
    if (key.first < 0) CHECK(r[1] == -1.0);
    if (key.first == 0) CHECK((r[1] >= 0 && r[1] < 32));
  }
  for (const auto& [key, n] : seen)
    CHECK(n == 1);
  // the group of the compute
  std::size_t nsmall = 0;
  for (const auto& [key, d] : expect)
    nsmall += all.at(key.second).type == 2;
  const std::vector<Row> small = all_rows(s.e, "small_c");
  CHECK(small.size() == nsmall);
  for (const Row& r : small)
    CHECK(all.at(static_cast<long long>(r[8])).type == 2);
  // the dump: lines from the contact point to the centre, in the groups of
  // the compute and of the dump
  if (world_rank() == 0) {
    const auto a = read_vtp(dir + "/all6000.vtp");
    REQUIRE(a);
    CHECK(static_cast<std::size_t>(a->GetNumberOfCells()) == nsmall);
    for (vtkIdType k = 0; k < a->GetNumberOfCells(); ++k) {
      vtkIdList* ids = a->GetCell(k)->GetPointIds();
      double p0[3], p1[3];
      a->GetPoint(ids->GetId(0), p0);
      a->GetPoint(ids->GetId(1), p1);
      const long long id = static_cast<long long>(a->GetCellData()->GetArray("id")->GetComponent(k, 0));
      CHECK(Vec3(p1[0], p1[1], p1[2]) == all.at(id).x);
      const Vec3 arm = Vec3(p1[0], p1[1], p1[2]) - Vec3(p0[0], p0[1], p0[2]);
      CHECK(arm.norm() < all.at(id).r);
    }
    const auto sm = read_vtp(dir + "/small6000.vtp");
    REQUIRE(sm);
    CHECK(static_cast<std::size_t>(sm->GetNumberOfCells()) == nsmall);
  }
}

TEST_CASE("compute wall/gran/local: errors say what to change", "[wall_gran_local][mpi][errors]") {
  const std::string dir = fresh_dir("errors");
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds(box());
  CHECK_THROWS_WITH(s.cmd("compute c all wall/gran/local pos speed"),
                    Contains("unknown keyword 'speed'") && Contains("contactPoint"));
  CHECK_THROWS_WITH(s.cmd("compute c all wall/gran/local heatFlux"), Contains("heat/gran"));
  s.cmds({"compute c all wall/gran/local", "compute nopos all wall/gran/local force",
          "create_atoms 1 single 0 0 0.0009 units box", "set atom * diameter 0.002 density 2500",
          "fix integr all nve/sphere"});
  CHECK_THROWS_WITH(s.cmd("dump d all local/gran/vtk 10 " + dir + "/a*.vtp nopos"),
                    Contains("contact point and the particle centre") && Contains("add the keyword pos"));
  // a run needs a wall
  CHECK_THROWS_WITH(s.cmd("run 0"), Contains("there is none") && Contains("fix walls all wall/gran"));
  s.cmd("fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.0");
  // before the first run the wall has no materials
  CHECK_THROWS_WITH(all_rows(s.e, "c"), Contains("run 0"));
  s.cmd("run 0");
  const std::vector<Row> rows = all_rows(s.e, "c");
  REQUIRE(rows.size() == 1);
  CHECK(rows[0].size() == 25);  // pos vel id force torque history contactArea
  // local values are not per-atom values
  s.cmd("dump bad all custom 10 " + dir + "/a.txt id c_c[1]");
  CHECK_THROWS_WITH(s.cmd("run 0"), Contains("local values"));
}
