// compute pair/gran/local and dump local/gran/vtk on 1, 2 and 4 ranks (run by
// ctest at each count): the Hertz force of a resting overlap; the values
// LIGGGHTS 3.8 gives for the same script (unittest/scripts/pair_gran_local,
// reference unittest/reference/pair_gran_local.liggghts.dump); every contact
// of a periodic bed once, whatever the decomposition and newton; the dump's
// formats (lines, pieces, legacy file, .pvd) read back with VTK's readers; and
// the errors.
#include <mpi.h>

#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDataArray.h>
#include <vtkFieldData.h>
#include <vtkPolyData.h>
#include <vtkPolyDataReader.h>
#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLPPolyDataReader.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <array>
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
#include "core/update.h"
#include "particles/particles.h"
#include "script_engine.h"

using Catch::Matchers::Contains;
using granary::Vec3;

namespace {

namespace fs = std::filesystem;
constexpr double kPi = 3.14159265358979323846;

using granary::test::world_rank;
using granary::test::world_size;

// A fresh output directory per test and rank count (ctest may run counts at once).
std::string fresh_dir(const std::string& name) {
  const std::string dir = "pair_gran_local_np" + std::to_string(world_size()) + "/" + name;
  if (world_rank() == 0) {
    fs::remove_all(dir);
    fs::create_directories(dir);
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

// The contact lines of a VTK frame as rows in LIGGGHTS' column order of
// `compute pair/gran/local pos vel id force force_normal force_tangential
// torque history contactArea delta contactPoint` (35 columns with 3 history
// values; the periodic flag is the third id column).
std::vector<Row> frame_rows(vtkDataSet* ds) {
  std::vector<Row> rows;
  vtkCellData* cd = ds->GetCellData();
  const char* names[] = {"vel1",         "vel2",    "id1",          "id2",
                         "periodic",     "force",   "force_normal", "force_tangential",
                         "torque",       "history", "contact_area", "delta",
                         "contact_point"};
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

template <class Reader>
vtkSmartPointer<vtkDataSet> read_xml(const std::string& file) {
  auto reader = vtkSmartPointer<Reader>::New();
  reader->SetFileName(file.c_str());
  reader->Update();
  vtkSmartPointer<vtkDataSet> ds = vtkDataSet::SafeDownCast(reader->GetOutputDataObject(0));
  return ds;
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

std::vector<std::string> script_lines(const std::string& file) {
  std::ifstream in(file);
  std::vector<std::string> out;
  std::string line;
  while (std::getline(in, line))
    out.push_back(line);
  return out;
}

// Two resting spheres of different sizes and materials that overlap by delta.
void two_spheres(granary::test::ScriptEngine& s, double delta) {
  char line[200];
  std::snprintf(line, sizeof line, "create_atoms 2 single %.17g 0.0003 -0.0002", 0.0018 - delta);
  s.cmds({"units si", "atom_style granular", "boundary f f f",
          "region box block -0.01 0.01 -0.01 0.01 -0.01 0.01", "create_box 2 box", "neighbor 0.0005 bin",
          "fix m1 all property/global youngsModulus peratomtype 5.e6 1.e7",
          "fix m2 all property/global poissonsRatio peratomtype 0.45 0.3",
          "fix m3 all property/global coefficientRestitution peratomtypepair 2 0.9 0.8 0.8 0.7",
          "fix m4 all property/global coefficientFriction peratomtypepair 2 0.5 0.4 0.4 0.3",
          "pair_style gran model hertz tangential history", "pair_coeff * *", "timestep 1e-5",
          "create_atoms 1 single 0 0.0003 -0.0002", line, "set atom 1 diameter 0.002 density 2500",
          "set atom 2 diameter 0.0016 density 3000"});
}

// A row of the 35 columns above as seen from its other particle: positions,
// velocities and ids swap; the force, its parts and the history (the
// tangential displacement) change sign; contact area, overlap and contact
// point stay. The torque on the first particle is -(r1 - delta/2) n x Ft + Mr
// (n from the second centre to the first, Ft the tangential force, Mr the
// rolling torque); the other particle gets -(r2 - delta/2) n x Ft - Mr.
Row seen_from_other(const Row& r) {
  Row o = r;
  for (int c = 0; c < 3; ++c) {
    std::swap(o[c], o[c + 3]);
    std::swap(o[6 + c], o[9 + c]);
  }
  std::swap(o[12], o[13]);
  for (int c = 15; c < 24; ++c)
    o[c] = -o[c];
  for (int c = 27; c < 30; ++c)
    o[c] = -o[c];
  const Vec3 d = v3(r, 0) - v3(r, 3);
  const double dist = d.norm(), delta = r[31];
  const Vec3 n = d / dist;
  // r1 / (r1 + r2) from the contact point
  const double share = (v3(r, 32) - v3(r, 0)).norm() / dist;
  const double r1 = share * (dist + delta), r2 = dist + delta - r1;
  const Vec3 nxft = n.cross(v3(r, 21));
  const Vec3 rolling = v3(r, 24) + (r1 - 0.5 * delta) * nxft;
  const Vec3 other = -(r2 - 0.5 * delta) * nxft - rolling;
  for (int c = 0; c < 3; ++c)
    o[24 + c] = other[c];
  return o;
}

}  // namespace

TEST_CASE("compute pair/gran/local: a resting overlap gives the Hertz force", "[pair_gran_local][mpi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  const double delta = 6e-5;
  two_spheres(s, delta);
  s.cmds(
      {"compute c all pair/gran/local pos vel id force force_normal force_tangential torque history "
       "contactArea delta contactPoint",
       "run 0"});
  const std::vector<Row> rows = all_rows(s.e, "c");
  REQUIRE(rows.size() == 1);
  const Row& r = rows[0];
  REQUIRE(r.size() == 35);
  // the first particle is the one whose neighbour list holds the contact
  const bool first_is_1 = r[12] == 1.0;
  CHECK(r[12] + r[13] == 3.0);
  CHECK(r[14] == 0.0);  // not across a periodic boundary
  const Vec3 x1(0, 0.0003, -0.0002), x2(0.0018 - delta, 0.0003, -0.0002);
  const Vec3 xi = first_is_1 ? x1 : x2, xj = first_is_1 ? x2 : x1;
  const double ri = first_is_1 ? 0.001 : 0.0008, rj = first_is_1 ? 0.0008 : 0.001;
  CHECK(v3(r, 0) == xi);
  CHECK(v3(r, 3) == xj);
  CHECK(v3(r, 6).norm() == 0.0);
  CHECK(v3(r, 9).norm() == 0.0);
  // Hertz: F = 4/3 Y* sqrt(R* delta) delta along the line of centres, pushing i away from j
  const double ystar = 1.0 / ((1 - 0.45 * 0.45) / 5e6 + (1 - 0.3 * 0.3) / 1e7);
  const double rstar = 0.001 * 0.0008 / 0.0018;
  const double fn = 4.0 / 3.0 * ystar * std::sqrt(rstar * delta) * delta;
  const Vec3 n = (xi - xj).normalized();
  CHECK((v3(r, 15) - fn * n).norm() < 1e-12 * fn);
  CHECK((v3(r, 18) - fn * n).norm() < 1e-12 * fn);
  CHECK(v3(r, 21).norm() < 1e-15 * fn);  // no tangential force at rest
  CHECK(v3(r, 24).norm() == 0.0);        // nor torque
  CHECK(v3(r, 27).norm() == 0.0);        // a new contact: no history yet
  // the circle where the sphere surfaces meet: a^2 = ri^2 - s^2, s its distance from i
  const double d = 0.0018 - delta;
  const double sdist = (d * d + ri * ri - rj * rj) / (2 * d);
  CHECK(r[30] == Approx(kPi * (ri * ri - sdist * sdist)).epsilon(1e-12));
  CHECK(r[31] == Approx(delta).epsilon(1e-12));
  CHECK((v3(r, 32) - (xi + (xj - xi) * (ri / (ri + rj)))).norm() < 1e-15);

  // the same force as the pair style's on particle 1
  Vec3 f1 = Vec3::Zero();
  const auto& p = s.p();
  for (int i = 0; i < p.nlocal; ++i)
    if (p.id[i] == 1) f1 = p.f[i];
  Vec3 f1_all;
  MPI_Allreduce(f1.data(), f1_all.data(), 3, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  const Vec3 on1 = first_is_1 ? v3(r, 15) : Vec3(-v3(r, 15));
  CHECK((f1_all - on1).norm() < 1e-14 * fn);
}

// LIGGGHTS 3.8 (dump local of every column, %.17g) for the same script, run
// unchanged by Granary (its dump local, and dump local/gran/vtk besides). The
// contact forces of LIGGGHTS' compute are those of the current positions,
// velocities and history; Granary's are the same to round-off.
TEST_CASE(
    "compute pair/gran/local, dump local and dump local/gran/vtk: LIGGGHTS 3.8's values for four spheres",
    "[pair_gran_local][mpi][liggghts]") {
  const fs::path src(GRANARY_SOURCE_DIR);
  const auto reference = read_dump_local((src / "unittest/reference/pair_gran_local.liggghts.dump").string());
  REQUIRE(reference.size() == 4);
  const std::string dir = fresh_dir("liggghts");
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  for (std::string line :
       script_lines((src / "unittest/scripts/pair_gran_local/in.pair_gran_local").string())) {
    // the script's dumps (local and local/gran/vtk) write to the test's directory
    for (const std::string name : {"pair_gran_local.dump", "forcechain*.vtp"}) {
      const auto at = line.find(" " + name);
      if (at != std::string::npos) line.replace(at + 1, name.size(), dir + "/" + name);
    }
    s.cmd(line);
  }
  const auto written = read_dump_local(dir + "/pair_gran_local.dump");
  CHECK(written.size() == reference.size());
  for (const auto& [step, expect] : reference)
    for (const char* source : {"dump local", "dump local/gran/vtk"}) {
      INFO("step " << step << ", " << source);
      std::vector<Row> got;
      if (source == std::string("dump local")) {
        REQUIRE(written.count(step));
        got = written.at(step);
      } else {
        const auto ds = read_xml<vtkXMLPolyDataReader>(dir + "/forcechain" + std::to_string(step) + ".vtp");
        REQUIRE(ds);
        got = frame_rows(ds);
      }
      REQUIRE(got.size() == expect.size());
      for (const Row& want : expect) {
        REQUIRE(want.size() == 35);
        // the same contact, in either order of its particles
        const Row* match = nullptr;
        for (const Row& g : got)
          if ((g[12] == want[12] && g[13] == want[13]) || (g[12] == want[13] && g[13] == want[12]))
            match = &g;
        INFO("contact " << want[12] << "-" << want[13]);
        REQUIRE(match);
        Row g = *match;
        if (g[12] != want[12]) g = seen_from_other(g);
        // positions and velocities of the integration: the same to round-off
        for (int c = 0; c < 12; ++c)
          CHECK(g[c] == Approx(want[c]).epsilon(1e-12).margin(1e-15));
        CHECK(g[14] == want[14]);
        // forces and torques (to 1e-9 of the largest component of each vector)
        for (int at : {15, 18, 21, 24, 27}) {
          const double scale = std::max({std::abs(want[at]), std::abs(want[at + 1]), std::abs(want[at + 2])});
          INFO("columns " << at + 1 << "-" << at + 3);
          CHECK((v3(g, at) - v3(want, at)).norm() <= 1e-12 * scale + 1e-300);
        }
        CHECK(g[30] == Approx(want[30]).epsilon(1e-12));  // contact area
        CHECK(g[31] == Approx(want[31]).epsilon(1e-10));  // overlap
        for (int c = 32; c < 35; ++c)
          CHECK(g[c] == Approx(want[c]).epsilon(1e-12).margin(1e-15));  // contact point
      }
    }
}

TEST_CASE("compute pair/gran/local: every contact once on any number of ranks, with periodic images",
          "[pair_gran_local][mpi]") {
  for (const char* newton : {"on", "off"}) {
    INFO("newton " << newton);
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    // a jittered lattice of spheres of two sizes, 2.4 mm apart, periodic in x
    // and y: many overlaps, also across the periodic and rank boundaries
    s.cmds({"units si", "atom_style granular", "boundary p p f", std::string("newton ") + newton,
            "region box block 0 0.0192 0 0.0192 0 0.0192", "create_box 2 box",
            granary::test::materials(2, 5.e6, 0.45, 0.7, 0.5),
            "pair_style gran model hertz tangential history", "pair_coeff * *", "timestep 1e-5"});
    int n = 0;
    for (int i = 0; i < 8; ++i)
      for (int j = 0; j < 8; ++j)
        for (int k = 0; k < 8; ++k) {
          char line[160];
          std::snprintf(line, sizeof line, "create_atoms %d single %.6f %.6f %.6f",
                        1 + (i * 7 + j * 3 + k) % 2, 0.0012 + 0.0024 * i + 0.0002 * ((j * 5 + k) % 3),
                        0.0012 + 0.0024 * j + 0.0002 * (k % 2),
                        0.0012 + 0.0024 * k + 0.00015 * ((i + j) % 3));
          s.cmd(line);
          ++n;
        }
    s.cmds({"set type 1 diameter 0.0024 density 2500", "set type 2 diameter 0.0026 density 2500",
            "region left block INF 0.0096 INF INF INF INF", "group left region left", "neighbor 0.0005 bin",
            "compute all_c all pair/gran/local id force delta", "compute left_c left pair/gran/local id",
            "run 0"});
    // the particles, gathered
    std::vector<double> local(5 * n, 0.0), all(5 * n);
    const auto& p = s.p();
    for (int i = 0; i < p.nlocal; ++i) {
      const auto k = static_cast<std::size_t>(p.id[i] - 1);
      for (int d = 0; d < 3; ++d)
        local[5 * k + d] = p.x[i][d];
      local[5 * k + 3] = p.radius[i];
      local[5 * k + 4] = p.type[i];
    }
    MPI_Allreduce(local.data(), all.data(), 5 * n, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
    const double prd = 0.0192;
    const double ystar = 5e6 / (2 * (1 - 0.45 * 0.45));
    // every overlapping pair (nearest image): its overlap and whether it crosses x or y
    std::map<std::pair<int, int>, std::pair<double, bool>> expect;
    for (int a = 0; a < n; ++a)
      for (int b = a + 1; b < n; ++b) {
        Vec3 d(all[5 * a] - all[5 * b], all[5 * a + 1] - all[5 * b + 1], all[5 * a + 2] - all[5 * b + 2]);
        bool across = false;
        for (int q = 0; q < 2; ++q) {
          const double shift = prd * std::round(d[q] / prd);
          across = across || shift != 0.0;
          d[q] -= shift;
        }
        const double rsum = all[5 * a + 3] + all[5 * b + 3];
        if (d.norm() < rsum) expect[{a + 1, b + 1}] = {rsum - d.norm(), across};
      }
    REQUIRE(expect.size() > static_cast<std::size_t>(n));
    const std::vector<Row> rows = all_rows(s.e, "all_c");
    CHECK(rows.size() == expect.size());
    std::map<std::pair<int, int>, int> seen;
    int across = 0;
    for (const Row& r : rows) {
      const int a = static_cast<int>(r[0]), b = static_cast<int>(r[1]);
      const std::pair<int, int> key{std::min(a, b), std::max(a, b)};
      ++seen[key];
      INFO("contact " << a << "-" << b);
      REQUIRE(expect.count(key));
      CHECK(r[2] == (expect[key].second ? 1.0 : 0.0));
      across += expect[key].second;
      const double delta = r[6];
      CHECK(delta == Approx(expect[key].first).epsilon(1e-9));
      // at rest: the Hertz force alone
      const double ra = all[5 * (a - 1) + 3], rb = all[5 * (b - 1) + 3];
      const double rstar = ra * rb / (ra + rb);
      CHECK(v3(r, 3).norm() == Approx(4.0 / 3.0 * ystar * std::sqrt(rstar * delta) * delta).epsilon(1e-12));
    }
    CHECK(across > 0);
    for (const auto& [key, count] : seen)
      CHECK(count == 1);
    // the group: contacts of two spheres of the left half only
    std::size_t nleft = 0;
    for (const auto& [key, v] : expect)
      nleft += all[5 * (key.first - 1)] < 0.0096 && all[5 * (key.second - 1)] < 0.0096;
    CHECK(all_rows(s.e, "left_c").size() == nleft);
    CHECK(nleft > 0);
    CHECK(nleft < expect.size());
  }
}

TEST_CASE("dump local/gran/vtk: lines, pieces, legacy files, groups and the .pvd",
          "[pair_gran_local][mpi][vtk]") {
  const std::string dir = fresh_dir("formats");
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  // a bed of spheres settling on a floor, periodic in x and y: many contacts, over every rank
  s.cmds({"processors * * 1",
          "units si",
          "atom_style granular",
          "boundary p p f",
          "newton off",
          "region box block 0 0.02 0 0.02 0 0.03 units box",
          "create_box 2 box",
          "neighbor 0.0005 bin",
          granary::test::materials(2, 5.e6, 0.45, 0.7, 0.5),
          "pair_style gran model hertz tangential history rolling_friction cdt",
          "fix m5 all property/global coefficientRollingFriction peratomtypepair 2 0.1 0.1 0.1 0.1",
          "pair_coeff * *",
          "timestep 1e-5",
          "region fill block 0.001 0.019 0.001 0.019 0.001 0.012 units box",
          "create_atoms 1 random 150 4711 fill overlap 0.0021 maxtry 200",
          "create_atoms 2 random 60 815 fill overlap 0.0021 maxtry 200",
          "set type 1 diameter 0.002 density 2500",
          "set type 2 diameter 0.0015 density 2000",
          "fix gravi all gravity 9.81 vector 0.0 0.0 -1.0",
          "fix zwall all wall/gran model hertz tangential history primitive type 1 zplane 0.0",
          "fix integr all nve/sphere",
          "group small type 2",
          "run 8000",
          "compute cpgl all pair/gran/local pos vel id force force_normal force_tangential torque history "
          "contactArea delta contactPoint",
          "dump a all local/gran/vtk 100 " + dir + "/lines*.vtp cpgl",
          "dump b all local/gran/vtk 100 " + dir + "/grid*.vtu cpgl",
          "dump c all local/gran/vtk 100 " + dir + "/legacy*.vtk cpgl",
          "dump d all local/gran/vtk 100 " + dir + "/pieces*.pvtp cpgl",
          "dump e small local/gran/vtk 100 " + dir + "/small*.vtp cpgl",
          "dump_modify a binary no",
          "run 100"});
  const std::vector<Row> rows = all_rows(s.e, "cpgl");
  REQUIRE(rows.size() > 50);
  // the frame of step 8100 as contacts keyed by (id1, id2)
  auto keyed = [](const std::vector<Row>& rs) {
    std::map<std::pair<long long, long long>, Row> out;
    for (const Row& r : rs)
      out[{static_cast<long long>(r[12]), static_cast<long long>(r[13])}] = r;
    return out;
  };
  const auto want = keyed(rows);
  auto same = [&](const std::vector<Row>& got, double tol) {
    REQUIRE(got.size() == want.size());
    for (const auto& [key, g] : keyed(got)) {
      REQUIRE(want.count(key));
      const Row& w = want.at(key);
      for (std::size_t c = 0; c < w.size(); ++c)
        CHECK(g[c] == Approx(w[c]).epsilon(tol).margin(1e-300));
    }
  };
  if (world_rank() == 0) {
    auto lines = read_xml<vtkXMLPolyDataReader>(dir + "/lines8100.vtp");
    REQUIRE(lines);
    for (vtkIdType k = 0; k < lines->GetNumberOfCells(); ++k)
      REQUIRE(lines->GetCellType(k) == VTK_LINE);
    CHECK(lines->GetNumberOfPoints() == 2 * lines->GetNumberOfCells());
    REQUIRE(lines->GetFieldData()->GetArray("TimeValue"));
    CHECK(lines->GetFieldData()->GetArray("TimeValue")->GetComponent(0, 0) == Approx(0.081));
    same(frame_rows(lines), 1e-15);  // ASCII with every digit
    auto grid = read_xml<vtkXMLUnstructuredGridReader>(dir + "/grid8100.vtu");
    REQUIRE(grid);
    for (vtkIdType k = 0; k < grid->GetNumberOfCells(); ++k)
      REQUIRE(grid->GetCellType(k) == VTK_LINE);
    same(frame_rows(grid), 0.0);
    auto reader = vtkSmartPointer<vtkPolyDataReader>::New();
    reader->SetFileName((dir + "/legacy8100.vtk").c_str());
    reader->Update();
    same(frame_rows(reader->GetOutput()), 0.0);
    auto pieces = read_xml<vtkXMLPPolyDataReader>(dir + "/pieces8100.pvtp");
    REQUIRE(pieces);
    same(frame_rows(pieces), 0.0);
    for (int r = 0; r < world_size(); ++r)
      CHECK(fs::exists(dir + "/pieces8100_" + std::to_string(r) + ".vtp"));
    // .pvd collections list frames 8000 and 8100 (the first frame of the run)
    for (const char* stem : {"lines", "grid", "pieces"}) {
      INFO(stem);
      std::ifstream in(dir + "/" + stem + ".pvd");
      std::stringstream text;
      text << in.rdbuf();
      const std::string ext = std::string(stem) == "grid"     ? ".vtu"
                              : std::string(stem) == "pieces" ? ".pvtp"
                                                              : ".vtp";
      CHECK_THAT(text.str(),
                 Contains(stem + std::string("8000") + ext) && Contains(stem + std::string("8100") + ext));
    }
    CHECK_FALSE(fs::exists(dir + "/legacy.pvd"));
  }
  // the small spheres' contacts in the dump are those with two small particles
  {
    const auto& p = s.p();
    std::vector<double> type_of(300, 0.0), all_types(300);
    for (int i = 0; i < p.nlocal; ++i)
      type_of[p.id[i]] = p.type[i];
    MPI_Allreduce(type_of.data(), all_types.data(), 300, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
    std::size_t expect = 0;
    for (const Row& r : rows)
      expect += all_types[static_cast<int>(r[12])] == 2 && all_types[static_cast<int>(r[13])] == 2;
    if (world_rank() == 0) {
      auto small = read_xml<vtkXMLPolyDataReader>(dir + "/small8100.vtp");
      CHECK(static_cast<std::size_t>(small->GetNumberOfCells()) == expect);
    }
  }
}

TEST_CASE("compute pair/gran/local and dump local/gran/vtk: errors say what to change",
          "[pair_gran_local][mpi][errors]") {
  const std::string dir = fresh_dir("errors");
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds({"units si", "atom_style granular", "boundary f f f",
          "region box block -0.01 0.01 -0.01 0.01 -0.01 0.01", "create_box 2 box"});
  CHECK_THROWS_WITH(s.cmd("compute c all pair/gran/local pos speed"),
                    Contains("unknown keyword 'speed'") && Contains("contactPoint"));
  CHECK_THROWS_WITH(s.cmd("compute c all pair/gran/local heatFlux"), Contains("heat/gran"));
  CHECK_THROWS_WITH(s.cmd("compute c all pair/gran/local ms_id"), Contains("ms_id"));
  s.cmds({"compute c all pair/gran/local pos force", "compute nopos all pair/gran/local force",
          "compute ke all ke"});
  CHECK_THROWS_WITH(s.cmd("dump d all local/gran/vtk 10 " + dir + "/a*.vtp missing"),
                    Contains("no compute 'missing'"));
  CHECK_THROWS_WITH(s.cmd("dump d all local/gran/vtk 10 " + dir + "/a*.vtp ke"),
                    Contains("must be a compute pair/gran/local"));
  CHECK_THROWS_WITH(s.cmd("dump d all local/gran/vtk 10 " + dir + "/a*.vtp nopos"),
                    Contains("add the keyword pos"));
  CHECK_THROWS_WITH(s.cmd("dump d all local/gran/vtk 10 " + dir + "/a*.txt c"), Contains(".vtp, .vtu"));
  CHECK_THROWS_WITH(s.cmd("dump d all local/gran/vtk 10 " + dir + "/a*.vtp"), Contains("compute-ID"));
  CHECK_THROWS_WITH(s.cmd("dump d all local/gran/vtk 10 " + dir + "/nodir/a*.vtp c"),
                    Contains("does not exist"));
  // a run needs a granular pair style
  s.cmds({"create_atoms 1 single 0 0 0", "set atom * diameter 0.002 density 2500", "timestep 1e-5"});
  CHECK_THROWS_WITH(s.cmd("run 0"), Contains("granular pair style") && Contains("pair_style gran"));
  s.cmds({"uncompute c", "uncompute nopos", granary::test::materials(2, 5.e6, 0.45, 0.7, 0.5),
          "pair_style gran model hertz tangential history", "pair_coeff * *",
          "compute c all pair/gran/local"});
  // before the first run there are no neighbour lists
  CHECK_THROWS_WITH(all_rows(s.e, "c"), Contains("run 0"));
  s.cmd("run 0");
  CHECK(all_rows(s.e, "c").empty());  // one sphere: no contact
  // local values are not per-atom values
  s.cmd("dump bad all custom 10 " + dir + "/a.txt id c_c[1]");
  CHECK_THROWS_WITH(s.cmd("run 0"), Contains("local values") && Contains("local/gran/vtk"));
}
