// The LIGGGHTS 3.8 tutorials meshGran, conveyor, insert_stream,
// movingMeshGran, heatTransfer_1, heatTransfer_2, packing, hydrogel_default,
// hydrogel_multicontact, sph_1 and sph_2
// (package liggghts-doc) run in Granary, in shortened form, and agree with LIGGGHTS where the comparison is
// deterministic (statistically where the random packings differ; each test says which).
//
// Each tutorial is copied from the installed package to a temporary directory
// (its input and STL files only); the copy's run lengths are cut (nothing else
// is changed) and both programs run the same copy:
// - meshGran (fix insert/stream, 20 particles every 400 steps, dump mesh/stl):
//   the number of particles after 2200 steps is 6 x 20 = 120 in both.
// - conveyor (insert/stream by mass, 38.3 particles per batch, surface_vel
//   belt): after 30001 steps (4 batches) the counts differ by at most 2 (the
//   programs round the fractional batches differently: 153 and 155).
// - insert_stream (300 particles per batch, oblique velocity): the kinetic
//   energy right after the first batch is that of the normal velocity only,
//   47.118654 J in LIGGGHTS (a batch has the same mass in both programs).
// - movingMeshGran (move/mesh linear, then rotate, dump mesh/stl): the bucket
//   mesh written by dump mesh/stl at step 600, after 100 steps of linear motion
//   and 200 steps of rotation, has the same corners in both files (LIGGGHTS
//   writes 6 significant digits: tolerance 1e-5 m on a 1 m bucket).
// - mesh_tet (region mesh/tet of a VTK file, create_atoms in it): 13121
//   particles in both.
// - hysteresis (model hooke/hysteresis, three batches of insert/pack): the
//   same kinetic energy in free fall; after landing within 10 % (the packings
//   differ).
// - chute_wear (mesh/surface/stress wear finnie, dump mesh/gran/VTK): the
//   eroded mass of the chute (wear times area, summed) after 30000 steps
//   agrees with LIGGGHTS' within the scatter of the random insertion.
// - sph_1, sph_2 (SPH dam breaks, 3d and 2d): the kinetic energy of the
//   first 2000 steps (deterministic lattice start) within 1.5 %.
//
// Without LIGGGHTS the Granary runs and their own checks still happen; the
// test is skipped (with a warning) when the tutorials are not installed.
#include <unistd.h>
#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkPolyData.h>
#include <vtkPolyDataReader.h>
#include <vtkSmartPointer.h>

#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/input.h"
#include "particles/particles.h"
#include "script_engine.h"
#include "skip.h"

namespace {

std::string shell(const std::string& cmd) {
  std::string out;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return out;
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0)
    out.append(buf, n);
  pclose(p);
  return out;
}

bool have_liggghts() {
  static const bool have = std::system("command -v liggghts > /dev/null 2>&1") == 0;
  return have;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void write_text(const std::string& path, const std::string& text) {
  std::ofstream(path) << text;
}

/// Copy the input file, meshes and data files of tutorial `name` into a fresh directory
/// (with an empty post/); "" (and a warning) when the package is missing.
std::string copy_tutorial(const std::string& name, const std::string& input) {
  const std::string listing = shell("dpkg -L liggghts-doc 2>/dev/null");
  const std::string key = "Tutorials_public/" + name + "/";
  std::vector<std::string> files;
  std::istringstream in(listing);
  std::string line;
  while (std::getline(in, line)) {
    const auto at = line.find(key);
    if (at == std::string::npos) continue;
    const std::string rel = line.substr(at + key.size());
    const bool wanted = rel == input || rel == input + ".gz" ||
                        (rel.rfind("meshes/", 0) == 0 && rel.find(".stl") != std::string::npos) ||
                        rel.rfind("data/", 0) == 0;
    if (wanted) files.push_back(line);
  }
  if (files.empty()) {
    granary::test::skip("LIGGGHTS tutorial " + name + " (package liggghts-doc) not found");
    return "";
  }
  auto t = granary::test::temp_template("granary_tut_");
  REQUIRE(mkdtemp(t.data()) != nullptr);
  const std::string dir = t.data();
  REQUIRE(std::system(("mkdir -p '" + dir + "/meshes' '" + dir + "/data' '" + dir + "/post'").c_str()) == 0);
  for (const std::string& f : files) {
    std::string rel = f.substr(f.find(key) + key.size());
    const bool gz = rel.size() > 3 && rel.compare(rel.size() - 3, 3, ".gz") == 0;
    if (gz) rel.resize(rel.size() - 3);
    const std::string cmd = (gz ? "gunzip -c '" : "cat '") + f + "' > '" + dir + "/" + rel + "'";
    REQUIRE(std::system(cmd.c_str()) == 0);
  }
  return dir;
}

/// Replace the first line that starts with `from` (after leading blanks,
/// blanks collapsed) by `to`.
void replace_line(std::string& text, const std::string& from, const std::string& to) {
  std::istringstream in(text);
  std::string line, out;
  bool done = false;
  while (std::getline(in, line)) {
    std::istringstream words(line);
    std::string w, norm;
    while (words >> w)
      norm += (norm.empty() ? "" : " ") + w;
    if (!done && norm.rfind(from, 0) == 0) {
      out += to + "\n";
      done = true;
    } else {
      out += line + "\n";
    }
  }
  REQUIRE(done);
  text = out;
}

/// Run `input` in `dir` in this process; returns the engine's final state via f.
template <class F>
void run_granary(const std::string& dir, const std::string& input, F&& f) {
  char cwd[4096];
  REQUIRE(getcwd(cwd, sizeof cwd) != nullptr);
  REQUIRE(chdir(dir.c_str()) == 0);
  {
    granary::test::ScriptEngine s;
    try {
      s.e.input->file(input);
    } catch (...) {
      REQUIRE(chdir(cwd) == 0);
      throw;
    }
    f(s);
  }
  REQUIRE(chdir(cwd) == 0);
}

/// Run LIGGGHTS on `input` in `dir` with extra lines appended; its screen output.
std::string run_liggghts(const std::string& dir, const std::string& input) {
  const std::string cmd = "cd '" + dir + "' && liggghts -in " + input + " -log none 2>&1";
  return shell(cmd);
}

/// The number after `key` in `text` (last occurrence), NaN when absent.
double value_after(const std::string& text, const std::string& key) {
  const auto at = text.rfind(key);
  if (at == std::string::npos) return std::nan("");
  return std::atof(text.c_str() + at + key.size());
}

double kinetic_energy(const granary::Particles& p) {
  double ke = 0;
  for (int i = 0; i < p.nlocal; ++i)
    ke += 0.5 * p.rmass[i] * p.v[i].squaredNorm();
  return ke;
}

/// The eroded mass of a mesh frame of dump mesh/gran/VTK (legacy VTK, either
/// program): the "wear" cell array times the triangles' areas, summed [kg];
/// NaN when the file or the array is missing.
double eroded_mass(const std::string& file) {
  auto reader = vtkSmartPointer<vtkPolyDataReader>::New();
  reader->SetFileName(file.c_str());
  reader->ReadAllFieldsOn();
  reader->Update();
  vtkPolyData* pd = reader->GetOutput();
  vtkDataArray* wear = pd ? pd->GetCellData()->GetArray("wear") : nullptr;
  if (!wear || wear->GetNumberOfTuples() != pd->GetNumberOfCells()) return std::nan("");
  double sum = 0.0;
  for (vtkIdType c = 0; c < pd->GetNumberOfCells(); ++c) {
    double p[3][3];
    for (int k = 0; k < 3; ++k)
      pd->GetPoint(pd->GetCell(c)->GetPointId(k), p[k]);
    double a[3], b[3];
    for (int d = 0; d < 3; ++d) {
      a[d] = p[1][d] - p[0][d];
      b[d] = p[2][d] - p[0][d];
    }
    const double cx = a[1] * b[2] - a[2] * b[1], cy = a[2] * b[0] - a[0] * b[2],
                 cz = a[0] * b[1] - a[1] * b[0];
    sum += wear->GetTuple1(c) * 0.5 * std::sqrt(cx * cx + cy * cy + cz * cz);
  }
  return sum;
}

using Corners = std::vector<std::array<double, 3>>;
Corners stl_corners(const std::string& file) {
  Corners c;
  std::istringstream in(read_text(file));
  std::string w;
  while (in >> w)
    if (w == "vertex") {
      std::array<double, 3> v;
      in >> v[0] >> v[1] >> v[2];
      c.push_back(v);
    }
  std::sort(c.begin(), c.end());
  return c;
}

}  // namespace

TEST_CASE("LIGGGHTS tutorial meshGran: insert/stream batches and dump mesh/stl", "[liggghts][tutorial]") {
  const std::string dir = copy_tutorial("meshGran", "in.meshGran");
  if (dir.empty()) return;
  std::string text = read_text(dir + "/in.meshGran");
  replace_line(text, "run 10000 upto", "run 2001 upto");
  replace_line(text, "run 40000 upto", "run 2200 upto");
  write_text(dir + "/in.short", text + "variable nn equal atoms\nprint \"NATOMS ${nn}\"\n");
  long long n = 0;
  run_granary(dir, "in.short", [&](granary::test::ScriptEngine& s) { n = s.p().natoms; });
  CHECK(n == 120);  // batches of 1000/s * 400 * 5e-5 s = 20 at steps 1, 401, ..., 2001
  CHECK(read_text(dir + "/post/dump2100.stl").find("endsolid cad") != std::string::npos);
  if (have_liggghts()) CHECK(value_after(run_liggghts(dir, "in.short"), "NATOMS ") == 120.0);
  std::system(("rm -rf '" + dir + "'").c_str());
}

TEST_CASE("LIGGGHTS tutorial mesh_tet: create_atoms in a region of tetrahedra read from a VTK file",
          "[liggghts][tutorial]") {
  const std::string dir = copy_tutorial("mesh_tet", "in.mesh_tet");
  if (dir.empty()) return;
  std::string text = read_text(dir + "/in.mesh_tet");
  replace_line(text, "run 1000", "run 10");
  write_text(dir + "/in.short", text + "variable nn equal atoms\nprint \"NATOMS ${nn}\"\n");
  long long n = 0;
  run_granary(dir, "in.short", [&](granary::test::ScriptEngine& s) { n = s.p().natoms; });
  // a 0.05 m cubic lattice in gmsh's tetrahedra of a cylinder, radius 0.75 m
  // and height 1 m; the lattice points on the mesh's surface (its bottom and
  // top, some on its side) are outside: 13121 in LIGGGHTS 3.8
  CHECK(n == 13121);
  if (have_liggghts()) CHECK(value_after(run_liggghts(dir, "in.short"), "NATOMS ") == 13121.0);
  std::system(("rm -rf '" + dir + "'").c_str());
}

TEST_CASE("LIGGGHTS tutorial hysteresis: batches fall and settle with model hooke/hysteresis",
          "[liggghts][tutorial]") {
  const std::string dir = copy_tutorial("hysteresis", "in.hysteresis");
  if (dir.empty()) return;
  std::string text = read_text(dir + "/in.hysteresis");
  replace_line(text, "run 10000", "run 6001");
  replace_line(text, "run 50000 upto", "run 20000 upto");
  replace_line(text, "dump dmp", "");
  const std::string probe =
      "variable nn equal atoms\nvariable k equal ke\nvariable r equal c_rke\n"
      "print \"NATOMS ${nn} KE ${k} RKE ${r}\"\n";
  replace_line(text, "run 20000 upto", "run 8000 upto\n" + probe + "run 20000 upto");
  write_text(dir + "/in.short", text + probe);
  // LIGGGHTS 3.8 on the same copy: three batches of 250 (steps 1, 3001, 6001)
  // in free fall until step 8000, kinetic energy 0.0070835712 J; at step
  // 20000 the bed has landed: 0.00109993003 J and 9.00372225e-05 J of rotation.
  // The programs place the particles of a batch differently (their random
  // numbers differ), so after the first impacts they agree only in the mean:
  // within 10 % at step 20000 (measured: 1.6 % and 3.8 %).
  const std::string out = shell("cd '" + dir + "' && '" + std::string(GRANARY_BINARY) +
                                "' -in in.short -log none 2>&1 | grep NATOMS");
  std::istringstream in(out);
  std::string w;
  double n1 = 0, ke1 = 0, rke1 = 0, n2 = 0, ke2 = 0, rke2 = 0;
  in >> w >> n1 >> w >> ke1 >> w >> rke1 >> w >> n2 >> w >> ke2 >> w >> rke2;
  CHECK(n1 == 750);
  CHECK(ke1 == Approx(0.0070835712).epsilon(1e-7));
  CHECK(rke1 == 0.0);
  CHECK(n2 == 750);
  CHECK(ke2 == Approx(0.00109993003).epsilon(0.1));
  CHECK(rke2 == Approx(9.00372225e-05).epsilon(0.1));
  if (have_liggghts()) {
    const std::string live = run_liggghts(dir, "in.short");
    CHECK(value_after(live, " KE ") == Approx(0.00109993003).epsilon(1e-7));
  }
  std::system(("rm -rf '" + dir + "'").c_str());
}

TEST_CASE("LIGGGHTS tutorial conveyor: insert/stream by mass onto a surface_vel belt",
          "[liggghts][tutorial]") {
  const std::string dir = copy_tutorial("conveyor", "in.conveyor");
  if (dir.empty()) return;
  std::string text = read_text(dir + "/in.conveyor");
  replace_line(text, "run 140000 upto", "run 30001 upto");
  write_text(dir + "/in.short", text + "variable nn equal atoms\nprint \"NATOMS ${nn}\"\n");
  long long n = 0;
  run_granary(dir, "in.short", [&](granary::test::ScriptEngine& s) { n = s.p().natoms; });
  // 30 kg/s * 0.1 s per batch over a mean particle mass 7.833e-2 kg: 38.30
  // particles per batch, 4 batches: floor(153.2) (38, 38, 38, 39)
  CHECK(n == 153);
  if (have_liggghts()) {
    // LIGGGHTS rounds each batch on its own and more often up (observed 39,
    // 38, 39, 39 = 155): at most 2 apart after 4 batches
    const double nl = value_after(run_liggghts(dir, "in.short"), "NATOMS ");
    CHECK(std::fabs(nl - static_cast<double>(n)) <= 2.0);
  }
  std::system(("rm -rf '" + dir + "'").c_str());
}

TEST_CASE("LIGGGHTS tutorial insert_stream: held particles move at the normal velocity",
          "[liggghts][tutorial]") {
  const std::string dir = copy_tutorial("insert_stream", "in.insert_stream");
  if (dir.empty()) return;
  std::string text = read_text(dir + "/in.insert_stream");
  replace_line(text, "run 1", "run 1\nvariable kk equal ke\nprint \"KE1 ${kk}\"");
  replace_line(text, "run 100000", "run 10");
  write_text(dir + "/in.short", text);
  double ke1 = 0;
  // the state after run 10: all 300 particles still held (the nearest needs
  // r / 2 m/s = 7.5 ms = 750 steps to reach the face)
  run_granary(dir, "in.short", [&](granary::test::ScriptEngine& s) {
    CHECK(s.p().natoms == 300);
    ke1 = kinetic_energy(s.p());
    for (int i = 0; i < s.p().nlocal; ++i)
      CHECK(s.p().v[i] == granary::Vec3(0.0, 0.0, -2.0));
  });
  if (have_liggghts()) CHECK(ke1 == Approx(value_after(run_liggghts(dir, "in.short"), "KE1 ")).epsilon(1e-7));
  std::system(("rm -rf '" + dir + "'").c_str());
}

TEST_CASE("LIGGGHTS tutorial movingMeshGran: move/mesh linear then rotate, written by dump mesh/stl",
          "[liggghts][tutorial]") {
  const std::string dir = copy_tutorial("movingMeshGran", "in.movingMeshGran");
  if (dir.empty()) return;
  std::string text = read_text(dir + "/in.movingMeshGran");
  replace_line(text, "run 8000 upto", "run 200 upto");
  replace_line(text, "run 29999 upto", "run 299 upto");
  replace_line(text, "run 30000 upto", "run 300 upto");
  replace_line(text, "run 15000", "run 100");
  replace_line(text, "run 25000", "run 300");
  write_text(dir + "/in.short", text);
  run_granary(dir, "in.short", [&](granary::test::ScriptEngine&) {});
  const Corners mine = stl_corners(dir + "/post/dump600.stl");
  REQUIRE(mine.size() == 84);  // the bucket's 28 triangles
  if (have_liggghts()) {
    REQUIRE(std::system(("mkdir -p '" + dir + "/ref' && mv '" + dir + "/post/dump600.stl' '" + dir + "/ref/'")
                            .c_str()) == 0);
    run_liggghts(dir, "in.short");
    const Corners ref = stl_corners(dir + "/post/dump600.stl");
    REQUIRE(ref.size() == mine.size());
    // pair the corners by nearest match (the two files may order them differently)
    double worst = 0;
    for (const auto& c : stl_corners(dir + "/ref/dump600.stl")) {
      double best = 1e30;
      for (const auto& r : ref)
        best = std::min(best, std::hypot(c[0] - r[0], c[1] - r[1], c[2] - r[2]));
      worst = std::max(worst, best);
    }
    CHECK(worst < 1e-5);
  }
  std::system(("rm -rf '" + dir + "'").c_str());
}

// LIGGGHTS' insert_stream tutorial in two parts: in.insert_stream inserts 300
// particles every 30000 steps (extrude_length 0.6 m at 2 m/s, dt 1e-5 s) from
// step 1 and writes a restart file; in.insert_stream_reset_timestep reads it,
// defines the insertion again and sets the step counter back (reset_timestep 0,
// then 50000). The schedule moves with the step counter: the next insertion
// keeps its distance from the step at which the restart was written.
//
// Both inputs and face.stl are copied unchanged from LIGGGHTS 3.8's
// Tutorials_public/insert_stream to unittest/scripts/insert_stream. The test
// shortens the first run from 100000 to 40000 steps (batches at 1 and 30001,
// restart at 40001, next batch due at 60001) and leaves out the dumps; the
// second part runs from step 50001 to 100000 in four runs that print the
// particle count at 69999, 70000, 99999 and 100000. The next batch is due
// 60001 - 40001 = 20000 steps after the restart step, that is at 50000 +
// 20000 = 70000, and the one after it at 100000, as in the full tutorial
// (where LIGGGHTS 3.8 also inserts at 70000 and 100000).
//
// LIGGGHTS 3.8 figures (stored: the test also runs where LIGGGHTS is not
// installed), from `liggghts -in in.first -log none; liggghts -in in.second
// -log none` on the shortened files this test writes:
// N69999 600, N70000 900, N99999 900, N100000 1200.
TEST_CASE(
    "LIGGGHTS tutorial insert_stream_reset_timestep: insertion continues after read_restart and "
    "reset_timestep",
    "[liggghts][tutorial][restart]") {
  namespace fs = std::filesystem;
  const fs::path src = fs::path(GRANARY_SOURCE_DIR) / "unittest" / "scripts" / "insert_stream";
  auto t = granary::test::temp_template("granary_tut_");
  REQUIRE(mkdtemp(t.data()) != nullptr);
  const fs::path dir = t.data();
  fs::copy(src, dir, fs::copy_options::recursive);
  fs::create_directories(dir / "post");

  std::string first = read_text((dir / "in.insert_stream").string());
  replace_line(first, "dump dmp", "");
  replace_line(first, "run 100000", "run 40000");
  write_text((dir / "in.first").string(), first);
  std::string second = read_text((dir / "in.insert_stream_reset_timestep").string());
  replace_line(second, "dump dmp", "");
  replace_line(second, "run 50000",
               "variable nn equal atoms\nrun 19998\nprint \"N69999 ${nn}\"\nrun 1\nprint \"N70000 "
               "${nn}\"\nrun 29999\nprint \"N99999 ${nn}\"\nrun 1\nprint \"N100000 ${nn}\"");
  write_text((dir / "in.second").string(), second);

  const std::vector<std::string> keys = {"N69999 ", "N70000 ", "N99999 ", "N100000 "};
  const std::vector<double> liggghts = {600, 900, 900, 1200};
  long long n_first = 0;
  run_granary(dir.string(), "in.first", [&](granary::test::ScriptEngine& s) { n_first = s.p().natoms; });
  CHECK(n_first == 600);
  // the second part with a log file, to read the printed counts back
  write_text((dir / "in.second_logged").string(), "log granary.log\ninclude in.second\n");
  run_granary(dir.string(), "in.second_logged",
              [&](granary::test::ScriptEngine& s) { CHECK(s.e.fix_value("ins", 1) == 1200.0); });
  const std::string out = read_text((dir / "granary.log").string());
  for (std::size_t k = 0; k < keys.size(); ++k)
    CHECK(value_after(out, keys[k]) == liggghts[k]);
  if (have_liggghts()) {
    run_liggghts(dir.string(), "in.first");
    const std::string live = run_liggghts(dir.string(), "in.second");
    for (std::size_t k = 0; k < keys.size(); ++k)
      CHECK(value_after(live, keys[k]) == liggghts[k]);
  }
  fs::remove_all(dir);
}

namespace {

/// Rows "id x y z T heatSource" of a dump custom file written by write_dump (both programs).
std::vector<std::array<double, 6>> read_dump_rows(const std::string& file) {
  std::vector<std::array<double, 6>> rows;
  std::istringstream in(read_text(file));
  std::string line;
  bool atoms = false;
  while (std::getline(in, line)) {
    if (line.rfind("ITEM: ATOMS", 0) == 0) {
      atoms = true;
      continue;
    }
    if (!atoms || line.empty()) continue;
    std::istringstream w(line);
    std::array<double, 6> r;
    if (w >> r[0] >> r[1] >> r[2] >> r[3] >> r[4] >> r[5]) rows.push_back(r);
  }
  return rows;
}

/// A heat tutorial, shortened: settle to step 20000 as the tutorial does, then
/// 10000 steps (0.25 s) of conduction (to step 30000 instead of 50000); the
/// thermal energy printed before (E0) and after (E1) the `set` of
/// temperatures or sources and at the end (E2), and the particles' final
/// temperatures written by write_dump.
std::string shorten_heat_tutorial(const std::string& dir) {
  std::string text = read_text(dir + "/in.heatGran");
  replace_line(text, "dump", "");
  replace_line(text, "run 20000 upto",
               "run 20000 upto\nvariable eh equal f_heattransfer\nprint \"E0 ${eh}\"");
  replace_line(
      text, "run 50000 upto",
      "print \"E1 ${eh}\"\nrun 30000 upto\nprint \"E2 ${eh}\"\nwrite_dump all custom post/final.txt id x y "
      "z f_Temp[0] f_heatSource[0]");
  write_text(dir + "/in.short", text);
  return "in.short";
}

}  // namespace

// heatTransfer_1: 890 spheres (r 4 mm, 8000 kg/m^3, c = 10 J/(kg K), k = 100
// W/(m K)) settle at 300 K; the half at x > 0 is set to 800 K, and heat flows
// for 0.25 s. LIGGGHTS 3.8 figures (stored; the shortened script this test
// writes, `liggghts -in in.short -log none`): 890 particles, E0 =
// 5726.24376155112 J (all at 300 K), 445 particles set to 800 K, E1 = E2 =
// 10498.1135628438 J, mean temperature of the particles at x < 0 at the end
// 369.985 K: 14.0 % of the 500 K difference crossed into the cold half. The
// packings differ (random insertion), so the crossed share is compared with a
// tolerance: 10 % of the LIGGGHTS value (Granary: 452 particles set, 14.4 %).
TEST_CASE("LIGGGHTS tutorial heatTransfer_1: conduction from a hot half of a settled bed",
          "[liggghts][tutorial][heat_gran]") {
  const std::string dir = copy_tutorial("heatTransfer_1", "in.heatGran");
  if (dir.empty()) return;
  const std::string input = shorten_heat_tutorial(dir);
  write_text(dir + "/in.logged", "log granary.log\ninclude " + input + "\n");
  run_granary(dir, "in.logged", [&](granary::test::ScriptEngine& s) { CHECK(s.p().natoms == 890); });
  const std::string out = read_text(dir + "/granary.log");
  const double pi = 3.14159265358979323846, mc = 4.0 / 3.0 * pi * 0.004 * 0.004 * 0.004 * 8000 * 10;
  CHECK(value_after(out, "E0 ") == Approx(5726.24376155112).epsilon(1e-9));
  const auto rows = read_dump_rows(dir + "/post/final.txt");
  REQUIRE(rows.size() == 890);
  double cold = 0;
  int ncold = 0;
  for (const auto& r : rows)
    if (r[1] < 0) {
      cold += r[4];
      ++ncold;
    }
  // the energy of the set temperatures, then conserved by conduction
  const double e1 = value_after(out, "E1 ");
  const double nhot = (e1 - 5726.24376155112) / (500 * mc);
  CHECK(std::fabs(nhot - std::round(nhot)) < 1e-6);
  CHECK(nhot == Approx(445).margin(30));
  CHECK(value_after(out, "E2 ") == Approx(e1).epsilon(1e-12));
  const double crossed = (cold / ncold - 300.0) / 500.0;
  CHECK(crossed == Approx(0.140).epsilon(0.10));
  if (have_liggghts()) {
    const std::string live = run_liggghts(dir, input);
    CHECK(value_after(live, "E0 ") == Approx(5726.24376155112).epsilon(1e-9));
    CHECK(value_after(live, "E2 ") == Approx(value_after(live, "E1 ")).epsilon(1e-12));
  }
  std::system(("rm -rf '" + dir + "'").c_str());
}

// heatTransfer_2: the same bed with heat sources of +1.5 W in particles at
// x > 0.03 m and -1.5 W at x < -0.03 m, for 0.25 s. Without conduction a
// source particle would warm by 1.5 W * 0.25 s / (m c) = 17.49 K. LIGGGHTS 3.8
// figures (stored, as for heatTransfer_1): E0 = E1 = 5726.24376155112 J, E2 =
// 5724.74376155119 J (124 sources and 128 sinks: -4 * 1.5 W * 0.25 s);
// conduction to their neighbours took 0.58 K of the 17.49 K from the sources
// and 0.50 K from the sinks, 0.54 K on average. The test requires E2 - E1 =
// (sources - sinks) * 1.5 W * 0.25 s to rounding, and the mean conduction loss
// of sources and sinks within 30 % of LIGGGHTS' 0.54 K (the packings differ;
// Granary: 122 sources, 123 sinks, 0.51 K).
TEST_CASE("LIGGGHTS tutorial heatTransfer_2: heat sources and sinks in a settled bed",
          "[liggghts][tutorial][heat_gran]") {
  const std::string dir = copy_tutorial("heatTransfer_2", "in.heatGran");
  if (dir.empty()) return;
  const std::string input = shorten_heat_tutorial(dir);
  write_text(dir + "/in.logged", "log granary.log\ninclude " + input + "\n");
  long long nsource = 0;
  run_granary(dir, "in.logged", [&](granary::test::ScriptEngine& s) {
    std::vector<double> q;
    s.e.fix_peratom("heatSource", 0, q);
    for (int i = 0; i < s.p().nlocal; ++i)
      nsource += q[i] > 0 ? 1 : (q[i] < 0 ? -1 : 0);
  });
  const std::string out = read_text(dir + "/granary.log");
  const double pi = 3.14159265358979323846, mc = 4.0 / 3.0 * pi * 0.004 * 0.004 * 0.004 * 8000 * 10;
  CHECK(value_after(out, "E0 ") == Approx(5726.24376155112).epsilon(1e-9));
  CHECK(value_after(out, "E1 ") == Approx(5726.24376155112).epsilon(1e-9));
  CHECK(value_after(out, "E2 ") - value_after(out, "E1 ") ==
        Approx(static_cast<double>(nsource) * 1.5 * 0.25).margin(1e-6));
  const auto rows = read_dump_rows(dir + "/post/final.txt");
  double loss = 0;
  int n = 0;
  const double free_rise = 1.5 * 0.25 / mc;
  for (const auto& r : rows) {
    if (r[5] > 0) loss += free_rise - (r[4] - 300.0), ++n;
    if (r[5] < 0) loss += free_rise + (r[4] - 300.0), ++n;
  }
  REQUIRE(n > 150);
  CHECK(loss / n == Approx(0.54).epsilon(0.30));
  if (have_liggghts()) {
    const std::string live = run_liggghts(dir, input);
    CHECK(value_after(live, "E1 ") == Approx(5726.24376155112).epsilon(1e-9));
  }
  std::system(("rm -rf '" + dir + "'").c_str());
}

// packing: 338 spheres (r 5 and 8 mm) inserted at a volume fraction of 0.25
// grow by fix adapt every 40 steps (atom-style variable of the radius). With
// the growth cut to 4000 steps and the relaxation to 1000 (variables growts
// and relaxts), LIGGGHTS 3.8 prints a largest radius of 0.0111488147949157 m
// and a smallest of 0.00696800924682228 m (101 changes of x (0.67 /
// 0.25)^(40 / 12000): one at the start of the growth run, one every 40
// steps). Granary must give the same radii (the schedule of fix adapt); the
// particle count depends on the insertion, which differs (random).
TEST_CASE("LIGGGHTS tutorial packing: particles grown by fix adapt", "[liggghts][tutorial][adapt]") {
  const std::string dir = copy_tutorial("packing", "in.packing");
  if (dir.empty()) return;
  std::string text = read_text(dir + "/in.packing");
  replace_line(text, "variable growts equal 50000", "variable growts equal 4000");
  replace_line(text, "variable relaxts equal 20000", "variable relaxts equal 1000");
  replace_line(text, "dump", "");
  write_text(dir + "/in.short", text);
  double rmax = 0, rmin = 1;
  long long n = 0;
  run_granary(dir, "in.short", [&](granary::test::ScriptEngine& s) {
    n = s.p().natoms;
    for (int i = 0; i < s.p().nlocal; ++i) {
      rmax = std::max(rmax, s.p().radius[i]);
      rmin = std::min(rmin, s.p().radius[i]);
    }
  });
  CHECK(n > 250);
  CHECK(rmax == Approx(0.0111488147949157).epsilon(1e-12));
  CHECK(rmin == Approx(0.00696800924682228).epsilon(1e-12));
  std::system(("rm -rf '" + dir + "'").c_str());
}

// A hydrogel tutorial cut to the first `steps` steps of its compression and
// without its dumps; the mean piston force (fix ave/time, every 100 steps, in
// post/FORCE_FILE) must equal LIGGGHTS' at the given steps within `tol`.
static void check_hydrogel(const std::string& input, int steps, const std::string& force_file,
                           const std::map<long long, double>& liggghts, double tol) {
  const std::string dir = copy_tutorial("hydrogel_multicontact", input);
  if (dir.empty()) return;
  std::string text = read_text(dir + "/" + input);
  const auto cut = text.find("unfix piston_move");
  REQUIRE(cut != std::string::npos);
  text.resize(cut);
  replace_line(text, "run ${ts_move} upto", "run " + std::to_string(steps) + " upto");
  replace_line(text, "dump dmp all", "");
  replace_line(text, "dump dmp2 all", "");
  write_text(dir + "/in.short", text);
  run_granary(dir, "in.short", [&](granary::test::ScriptEngine& s) { CHECK(s.p().natoms == 514); });
  std::map<long long, double> fz;
  std::istringstream in(read_text(dir + "/post/" + force_file));
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream w(line);
    long long step;
    double fx, fy, f;
    if (w >> step >> fx >> fy >> f) fz[step] = f;
  }
  CHECK(fz.size() == static_cast<std::size_t>(steps / 100));
  for (const auto& kv : liggghts) {
    INFO(input << " step " << kv.first);
    REQUIRE(fz.count(kv.first) == 1);
    CHECK(fz[kv.first] == Approx(kv.second).epsilon(tol));
  }
  std::system(("rm -rf '" + dir + "'").c_str());
}

// hydrogel_multicontact/in.hydrogel_default: 514 soft spheres (Y = 23.3 kPa,
// soft_particles yes) read with read_data from the tutorial's data file
// (measured positions of Brodu et al. 2015), compressed by a mesh piston
// (fix mesh/surface/stress moved by move/mesh); fix ave/time writes the mean
// piston force every 100 steps. Cut to the first 10,000 steps of the
// compression (the piston speed is unchanged) and without the VTK dumps. The
// start is deterministic (the same particles in both programs), so the force
// follows LIGGGHTS' closely: LIGGGHTS 3.8's mean z force at steps 1000, 2500,
// 5000, 7500 and 10000 (stored from `liggghts -in in.hydrogel_default`, whose
// first 10,000 steps are those of the cut script): 0.0111372, 0.0434536,
// 0.208029, 0.439749, 0.769013 N. Tolerance 0.1 % (Granary: 0.011137,
// 0.0434537, 0.20803, 0.439749, 0.769013 N).
TEST_CASE("LIGGGHTS tutorial hydrogel_default: read_data and a mesh piston on soft spheres",
          "[liggghts][tutorial][read_data]") {
  check_hydrogel(
      "in.hydrogel_default", 10000, "piston_force_default.txt",
      {{1000, 0.0111372}, {2500, 0.0434536}, {5000, 0.208029}, {7500, 0.439749}, {10000, 0.769013}}, 1e-3);
}

// hydrogel_multicontact/in.hydrogel_multicontact: the same soft spheres and
// piston with `surface multicontact` in the pair style and every wall, and fix
// multicontact/halfspace (geometric_prefactor 1.125): each contact sees the
// radii changed by the particles' other contacts (Brodu et al. 2015). Cut to
// the first 20,000 steps of the compression (without dumps). LIGGGHTS 3.8's
// mean z force at steps 1000 ... 20000 (stored from `liggghts -in
// in.hydrogel_multicontact`): 0.0152461, 0.0624677, 0.216686, 0.580749,
// 1.04597, 5.37632 N, where the plain Hertz contacts of in.hydrogel_default
// give 0.0111, 0.0435, 0.208, 0.440, 0.769 N up to step 10000 (27 to 36 %
// less). Granary: 0.0152347, 0.0625957, 0.216809, 0.581469, 1.04946, 5.36528
// N (within 0.4 %); tolerance 1 %. (Over the whole tutorial the largest
// force is 15.49 N in LIGGGHTS and 15.60 N in Granary, at the end of the
// first stroke; 6.75 N with plain Hertz contacts.)
TEST_CASE("LIGGGHTS tutorial hydrogel_multicontact: soft spheres whose contacts deform each other",
          "[liggghts][tutorial][multicontact]") {
  check_hydrogel("in.hydrogel_multicontact", 20000, "piston_force_multicontact.txt",
                 {{1000, 0.0152461},
                  {2500, 0.0624677},
                  {5000, 0.216686},
                  {7500, 0.580749},
                  {10000, 1.04597},
                  {20000, 5.37632}},
                 0.01);
}

TEST_CASE("LIGGGHTS tutorial chute_wear: Finnie wear of a chute under a particle stream",
          "[liggghts][tutorial][wear]") {
  const std::string dir = copy_tutorial("chute_wear", "in.chute_wear");
  if (dir.empty()) return;
  std::string text = read_text(dir + "/in.chute_wear");
  replace_line(text, "run 100000 upto", "run 30000 upto");
  write_text(dir + "/in.short", text);
  long long n = 0;
  run_granary(dir, "in.short", [&](granary::test::ScriptEngine& s) { n = s.p().natoms; });
  // 0.1 kg/s in batches every 1000 steps: 382 particles in 30000 steps
  // (LIGGGHTS 377-383 with four insertion seeds)
  CHECK(std::llabs(n - 382) <= 6);
  const double mine = eroded_mass(dir + "/post/mesh_30000.vtk");
  // LIGGGHTS 3.8 with the tutorial's insertion seed and three others
  // (32452867, 15485917, 49979693, 86028121): 9.868e-3, 1.0773e-2,
  // 9.719e-3, 9.861e-3 kg, mean 1.0055e-2, within 7 % of it (Granary's four
  // runs with the same seeds: 1.013e-2 to 1.061e-2). The insertion draws
  // differ, so the two programs agree in distribution only: 12 %.
  CHECK(mine == Approx(1.0055e-2).epsilon(0.12));
  if (have_liggghts()) {
    std::system(("rm -rf '" + dir + "/post' && mkdir '" + dir + "/post'").c_str());
    run_liggghts(dir, "in.short");
    const double theirs = eroded_mass(dir + "/post/mesh_30000.vtk");
    CHECK(theirs == Approx(1.0055e-2).epsilon(0.12));
    CHECK(mine == Approx(theirs).epsilon(0.15));
  }
  std::system(("rm -rf '" + dir + "'").c_str());
}

// An SPH tutorial (sph_1: 3d dam break, 2655 particles; sph_2: 2d, 295 fluid
// and 459 stationary boundary particles) cut to the first 2000 steps with the
// gate closed (its `run 5000` becomes `run 2000`, the lines from `unfix wall`
// on and the VTK dump are removed) and with the total kinetic energy written
// every 100 steps (compute ke, fix ave/time): it must follow LIGGGHTS' from
// the same lattice start within `tol` at every 100th step. `changes`
// replaces further lines (the line starting with the first word sequence).
static void check_sph(const std::string& name, const std::vector<double>& liggghts, double tol,
                      const std::vector<std::pair<std::string, std::string>>& changes = {}) {
  const std::string dir = copy_tutorial(name, "in." + name);
  if (dir.empty()) return;
  std::string text = read_text(dir + "/in." + name);
  const auto cut = text.find("unfix         wall");
  REQUIRE(cut != std::string::npos);
  text.resize(cut);
  replace_line(text, "dump dmp all custom/vtk", "");
  replace_line(text, "run 5000", "run 2000");
  for (const auto& c : changes)
    replace_line(text, c.first, c.second);
  replace_line(text, "run 1",
               "compute ke_t all ke\nfix ke_t all ave/time 100 1 100 c_ke_t file post/ke.txt\nrun 1");
  write_text(dir + "/in.short", text);
  run_granary(dir, "in.short",
              [&](granary::test::ScriptEngine& s) { CHECK(s.p().natoms == (name == "sph_1" ? 2655 : 754)); });
  std::map<long long, double> ke;
  std::istringstream in(read_text(dir + "/post/ke.txt"));
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream w(line);
    long long step;
    double v;
    if (w >> step >> v) ke[step] = v;
  }
  REQUIRE(liggghts.size() == 20);
  double worst = 0.0;
  for (std::size_t k = 0; k < liggghts.size(); ++k) {
    const long long step = 100 * static_cast<long long>(k + 1);
    INFO(name << " step " << step);
    REQUIRE(ke.count(step) == 1);
    CHECK(ke[step] == Approx(liggghts[k]).epsilon(tol));
    worst = std::max(worst, std::fabs(ke[step] / liggghts[k] - 1.0));
  }
  INFO("largest relative deviation: " << worst);
  CHECK(worst < tol);
  std::system(("rm -rf '" + dir + "'").c_str());
}

// sph_1 (atom_style sph, pair_style sph/artVisc/tensCorr cubicspline with
// artificial viscosity and tensile correction, fix sph/density/continuity,
// sph/density/corr shepard every 30, sph/pressure Tait, wall/region/sph
// around the box, wall/sph as the dam's gate, nve/sph, gravity). LIGGGHTS
// 3.8's total kinetic energy (thermo ke, norm no) at steps 100 ... 2000,
// stored from `liggghts -in` the cut script. Granary: 1.21336e-4 ...
// 1.86911e-3 J, within 0.41 % at every step; tolerance 1.5 %.
TEST_CASE("LIGGGHTS tutorial sph_1: a 3d SPH dam behind a gate", "[liggghts][tutorial][sph]") {
  check_sph("sph_1", {0.00012132793, 0.00042678199, 0.00079797696, 0.001118249,  0.0013150105,
                      0.001371241,   0.0013292058,  0.0012497436,  0.0011983658, 0.0012134736,
                      0.0012602467,  0.0012943696,  0.0013036431,  0.0012759891, 0.0012241962,
                      0.0012131541,  0.0012797178,  0.0014221203,  0.0016347984, 0.0018615119},
            0.015);
}

// sph_2: the same in 2d (dimension 2, lattice sq, cubicspline2d, fix
// enforce2d, a box periodic in z), with walls made of particles of type 2
// (fix nve/sph/stationary) instead of wall/region/sph. LIGGGHTS 3.8's total
// kinetic energy at steps 100 ... 2000 (from `liggghts -in` the cut script).
// Granary: within 0.70 % at every step; tolerance 1.5 %.
TEST_CASE("LIGGGHTS tutorial sph_2: a 2d SPH dam with particle walls", "[liggghts][tutorial][sph]") {
  check_sph("sph_2",
            {0.0011484839, 0.0039595859, 0.0072148851, 0.0098545689, 0.011287401, 0.01156637, 0.011220674,
             0.010804626,  0.010768475,  0.01126581,   0.01214547,   0.013264627, 0.01457482, 0.016088185,
             0.017874148,  0.01996135,   0.02226792,   0.02463319,   0.026870215, 0.028810041},
            0.015);
}

// sph_1 and sph_2 with the Wendland kernel (`wendland`, `wendland2d` in the
// pair style and `set ... sphkernel`): LIGGGHTS' manual prints 1/(pi h^3) as
// its factor, but LIGGGHTS normalises it (21/(16 pi h^3), 7/(4 pi h^2)) as
// Granary does: kinetic energy within 0.34 % (3d) and 0.77 % (2d) of
// LIGGGHTS' over the first 2000 steps (stored from `liggghts -in` the cut
// scripts); with the unnormalised factor the forces would be 24 % smaller.
TEST_CASE("LIGGGHTS tutorials sph_1 and sph_2 with the Wendland kernel", "[liggghts][tutorial][sph]") {
  check_sph("sph_1", {0.00012129333, 0.00042506909, 0.00078648161, 0.0010848771, 0.0012516859,
                      0.0012782602,  0.0012173229,  0.0011399534,  0.0011107845, 0.001155585,
                      0.0012266779,  0.0012697882,  0.0012701701,  0.0012260689, 0.0011644754,
                      0.0011606344,  0.0012496074,  0.001417781,   0.0016380551, 0.0018371982},
            0.015,
            {{"pair_style sph/artVisc/tensCorr cubicspline",
              "pair_style sph/artVisc/tensCorr wendland $h artVisc tensCorr"},
             {"set group all sphkernel cubicspline", "set group all sphkernel wendland"}});
  check_sph("sph_2",
            {0.0011479364, 0.0039570494, 0.0072227917, 0.009888113, 0.011346661, 0.011641553, 0.011294648,
             0.010871583,  0.010839033,  0.011350711,  0.012249079, 0.013379695, 0.014689708, 0.016200958,
             0.017992386,  0.020098389,  0.022436667,  0.024840019, 0.027113388, 0.029083791},
            0.015,
            {{"pair_style sph/artVisc/tensCorr cubicspline2d",
              "pair_style sph/artVisc/tensCorr wendland2d $h artVisc tensCorr"},
             {"set group all sphkernel cubicspline2d", "set group all sphkernel wendland2d"}});
}

// sph_2 with the boundary particles' parameters changed (smoothing length
// 0.008 m instead of 0.012, speed of sound 40 m/s instead of 20, alpha 0.3
// instead of 4.2e-3): pairs of a fluid and a boundary particle take the
// means of the two types' values, as in LIGGGHTS. The change lowers the
// kinetic energy by up to 24 %; Granary follows LIGGGHTS' within 0.73 % (its
// energies at steps 100 ... 2000 stored from `liggghts -in` the changed script).
TEST_CASE("LIGGGHTS tutorial sph_2 with different parameters per type", "[liggghts][tutorial][sph]") {
  check_sph("sph_2",
            {0.0011092927, 0.0036747775, 0.0064086217, 0.0082872276, 0.0089532602, 0.0087909055, 0.0084924321,
             0.0085598482, 0.0091462559, 0.010102134,  0.011188869,  0.012380597,  0.013848397,  0.015716087,
             0.017962345,  0.020384766,  0.022669476,  0.024613777,  0.026215048,  0.027579233},
            0.015,
            {{"fix m1 all property/global speedOfSound",
              "fix m1 all property/global speedOfSound peratomtype 20. 40."},
             {"fix m2 all property/global sl", "fix m2 all property/global sl peratomtype $h 0.008"},
             {"fix m3 all property/global artViscAlpha",
              "fix m3 all property/global artViscAlpha peratomtype 4.1666e-3 0.3"}});
}
