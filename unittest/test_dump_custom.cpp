// dump custom (LAMMPS text format), dump_modify keywords, undump and write_dump.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/error.h"
#include "core/input.h"
#include "core/logger.h"
#include "domain/domain.h"
#include "particles/particles.h"
#include "script_engine.h"

namespace {

namespace fs = std::filesystem;
using Catch::Matchers::Contains;

std::string fresh_dir(const std::string& name) {
  const std::string dir = "dump_custom_out/" + name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void setup_bed(granary::Engine& e) {
  e.logger->set_screen(false);
  const std::vector<std::string> lines = {
      "units si",
      "atom_style granular",
      "boundary f f m",
      "region box block 0 0.02 0 0.02 0 0.03 units box",
      "create_box 2 box",
      "neighbor 0.0005 bin",
      granary::test::materials(2, 5.e6, 0.45, 0.7, 0.5),
      "pair_style gran model hertz tangential history",
      "pair_coeff * *",
      "timestep 1e-5",
      "region fill block 0.001 0.019 0.001 0.019 0.001 0.012 units box",
      "create_atoms 1 random 80 4711 fill overlap 0.0021 maxtry 200",
      "create_atoms 2 random 40 815 fill overlap 0.0021 maxtry 200",
      "set type 1 diameter 0.002 density 2500",
      "set type 2 diameter 0.0015 density 2000",
      "velocity all set 0.05 -0.1 -0.5",
      "fix gravi all gravity 9.81 vector 0.0 0.0 -1.0",
      "fix zwall all wall/gran model hertz tangential history primitive type 1 zplane 0.0",
      "fix integr all nve/sphere",
  };
  granary::test::run(e, lines);
}

std::vector<std::string> read_lines(const std::string& file) {
  std::ifstream in(file);
  std::vector<std::string> out;
  std::string line;
  while (std::getline(in, line))
    out.push_back(line);
  return out;
}

std::vector<double> numbers(const std::string& line) {
  std::istringstream in(line);
  std::vector<double> out;
  double v;
  while (in >> v)
    out.push_back(v);
  return out;
}

// One frame: header lines and rows (from the line after "ITEM: ATOMS").
struct Frame {
  long long step = -1;
  std::string box, atoms;
  std::vector<std::string> bounds, rows;
};

std::vector<Frame> parse(const std::string& file) {
  const auto lines = read_lines(file);
  std::vector<Frame> frames;
  for (std::size_t k = 0; k < lines.size(); ++k) {
    if (lines[k] != "ITEM: TIMESTEP") continue;
    Frame f;
    f.step = std::stoll(lines[k + 1]);
    const int n = std::stoi(lines[k + 3]);
    f.box = lines[k + 4];
    f.bounds = {lines[k + 5], lines[k + 6], lines[k + 7]};
    f.atoms = lines[k + 8];
    for (int i = 0; i < n; ++i)
      f.rows.push_back(lines[k + 9 + i]);
    frames.push_back(f);
  }
  return frames;
}

std::map<long long, int> index_of(granary::Engine& e) {
  std::map<long long, int> m;
  for (int i = 0; i < e.particles->nlocal; ++i)
    m[e.particles->id[i]] = i;
  return m;
}

}  // namespace

TEST_CASE("dump custom writes the LAMMPS text format with the particle state", "[dump][custom]") {
  const std::string dir = fresh_dir("format");
  granary::Engine e(MPI_COMM_WORLD);
  setup_bed(e);
  e.input->one("dump d all custom 10 " + dir +
               "/dump_*.txt id type x y z vx vy vz fx omegaz radius diameter mass density");
  e.input->one("dump_modify d precision 17 pad 4");
  e.input->one("run 20");
  for (const char* f : {"dump_0000.txt", "dump_0010.txt", "dump_0020.txt"})
    CHECK(fs::exists(dir + "/" + f));

  const auto frames = parse(dir + "/dump_0020.txt");
  REQUIRE(frames.size() == 1);
  const Frame& f = frames[0];
  CHECK(f.step == 20);
  CHECK(f.box == "ITEM: BOX BOUNDS ff ff mm");
  CHECK(numbers(f.bounds[0]) == std::vector<double>{e.domain->boxlo.x(), e.domain->boxhi.x()});
  CHECK(numbers(f.bounds[2]) == std::vector<double>{e.domain->boxlo.z(), e.domain->boxhi.z()});
  CHECK(f.atoms == "ITEM: ATOMS id type x y z vx vy vz fx omegaz radius diameter mass density");
  const granary::Particles& p = *e.particles;
  REQUIRE(static_cast<int>(f.rows.size()) == p.nlocal);
  auto idx = index_of(e);
  int bad = 0;
  for (const auto& row : f.rows) {
    const auto v = numbers(row);
    REQUIRE(v.size() == 14);
    const int i = idx.at(static_cast<long long>(v[0]));
    const std::vector<double> expect = {static_cast<double>(p.id[i]),
                                        static_cast<double>(p.type[i]),
                                        p.x[i].x(),
                                        p.x[i].y(),
                                        p.x[i].z(),
                                        p.v[i].x(),
                                        p.v[i].y(),
                                        p.v[i].z(),
                                        p.f[i].x(),
                                        p.omega[i].z(),
                                        p.radius[i],
                                        2 * p.radius[i],
                                        p.rmass[i],
                                        p.density[i]};
    if (v != expect) ++bad;
  }
  CHECK(bad == 0);
}

TEST_CASE("dump custom: default formats are %d and %g", "[dump][custom]") {
  const std::string dir = fresh_dir("default_format");
  granary::Engine e(MPI_COMM_WORLD);
  setup_bed(e);
  e.input->one("dump d all custom 1 " + dir + "/d.txt id x");
  e.input->one("run 0");
  const auto frames = parse(dir + "/d.txt");
  REQUIRE(frames.size() == 1);
  auto idx = index_of(e);
  for (const auto& row : frames[0].rows) {
    std::istringstream in(row);
    std::string id, x;
    in >> id >> x;
    char buf[64];
    std::snprintf(buf, sizeof buf, "%g", e.particles->x[idx.at(std::stoll(id))].x());
    CHECK(x == buf);
    CHECK(id.find_first_not_of("0123456789") == std::string::npos);
  }
}

TEST_CASE("dump custom: sort id gives ascending ids, sort -N descending values", "[dump][custom]") {
  const std::string dir = fresh_dir("sort");
  granary::Engine e(MPI_COMM_WORLD);
  setup_bed(e);
  e.input->one("atom_modify sort 1 0.0");  // storage order differs from id order
  e.input->one("dump a all custom 5 " + dir + "/a.txt x id");
  e.input->one("dump_modify a sort id");
  e.input->one("dump b all custom 5 " + dir + "/b.txt id z");
  e.input->one("dump_modify b sort -2");
  e.input->one("run 5");
  for (const auto& frame : parse(dir + "/a.txt")) {
    REQUIRE(frame.rows.size() == 120);
    for (std::size_t k = 1; k < frame.rows.size(); ++k)
      CHECK(numbers(frame.rows[k])[1] > numbers(frame.rows[k - 1])[1]);
  }
  for (const auto& frame : parse(dir + "/b.txt")) {
    for (std::size_t k = 1; k < frame.rows.size(); ++k)
      CHECK(numbers(frame.rows[k])[1] <= numbers(frame.rows[k - 1])[1]);
  }
}

TEST_CASE("dump custom: one file holds every frame, and append yes keeps it", "[dump][custom]") {
  const std::string dir = fresh_dir("append");
  const std::string file = dir + "/all.txt";
  {
    granary::Engine e(MPI_COMM_WORLD);
    setup_bed(e);
    e.input->one("dump d all custom 5 " + file + " id type");
    e.input->one("run 10");
    e.input->one("run 5");  // the file stays open across runs
    e.input->one("undump d");
    CHECK(parse(file).size() == 4);
    e.input->one("dump d all custom 5 " + file + " id type");
    e.input->one("dump_modify d append yes time yes units yes");
    e.input->one("run 5");
  }
  const auto frames = parse(file);
  REQUIRE(frames.size() == 6);
  CHECK(frames[0].step == 0);
  CHECK(frames[3].step == 15);
  CHECK(frames[4].step == 15);
  CHECK(frames[5].step == 20);
  const auto lines = read_lines(file);
  int units = 0, times = 0;
  for (std::size_t k = 0; k < lines.size(); ++k) {
    if (lines[k] == "ITEM: UNITS") {
      ++units;
      CHECK(lines[k + 1] == "si");
    }
    if (lines[k] == "ITEM: TIME") {
      ++times;
      CHECK(lines[k + 2] == "ITEM: TIMESTEP");
    }
  }
  CHECK(units == 1);
  CHECK(times == 2);
}

TEST_CASE("dump custom: dump_modify format, region, label and groups", "[dump][custom]") {
  const std::string dir = fresh_dir("modify");
  granary::Engine e(MPI_COMM_WORLD);
  setup_bed(e);
  e.input->one("region low block INF INF INF INF INF 0.006 units box");
  e.input->one("group small type 2");
  e.input->one("dump a all custom 1 " + dir + "/a.txt id type x y z");
  e.input->one("dump_modify a format line \"%d %d %.3f %.3f %.3f\" sort id");
  e.input->one("dump b all custom 1 " + dir + "/b.txt id type x");
  e.input->one("dump_modify b format \"%5d %d %g\" format float %.2e format 2 %3d label GRAINS");
  e.input->one("dump c small custom 1 " + dir + "/c.txt id type z");
  e.input->one("dump_modify c region low");
  e.input->one("run 0");

  const auto a = parse(dir + "/a.txt")[0];
  for (const auto& row : a.rows) {
    std::istringstream in(row);
    std::string id, type, x;
    in >> id >> type >> x;
    CHECK(x.size() - x.find('.') == 4);  // three decimals
  }
  const auto b = parse(dir + "/b.txt")[0];
  CHECK(b.atoms == "ITEM: GRAINS id type x");
  CHECK(b.rows[0].substr(0, 5).find_first_not_of(' ') != std::string::npos);
  CHECK(b.rows[0].size() >= 5);
  CHECK(b.rows[0].find("e-0") != std::string::npos);  // %.2e for floats
  const auto c = parse(dir + "/c.txt")[0];
  int expected = 0;
  for (int i = 0; i < e.particles->nlocal; ++i)
    if (e.particles->type[i] == 2 && e.particles->x[i].z() <= 0.006) ++expected;
  CHECK(static_cast<int>(c.rows.size()) == expected);
  for (const auto& row : c.rows) {
    CHECK(numbers(row)[1] == 2);
    CHECK(numbers(row)[2] <= 0.006);
  }
  CHECK_THROWS_WITH(e.input->one("dump_modify a format line \"%d %d\""),
                    Contains("2 conversions for 5 columns"));
  CHECK_THROWS_WITH(e.input->one("dump_modify a format float %s"), Contains("not a number format"));
  CHECK_THROWS_WITH(e.input->one("dump_modify a sort 9"), Contains("column"));
  CHECK_THROWS_WITH(e.input->one("dump_modify a binary no"), Contains("binary"));
  e.input->one("undump a");
  CHECK_THROWS_WITH(e.input->one("undump a"), Contains("unknown dump ID"));
}

TEST_CASE("write_dump writes the current state once", "[dump][write_dump]") {
  const std::string dir = fresh_dir("write_dump");
  granary::Engine e(MPI_COMM_WORLD);
  setup_bed(e);
  e.input->one("run 3");
  e.input->one("write_dump all custom " + dir + "/now_*.txt id vx modify sort id precision 17");
  const auto frames = parse(dir + "/now_3.txt");
  REQUIRE(frames.size() == 1);
  CHECK(frames[0].step == 3);
  auto idx = index_of(e);
  long long prev = 0;
  for (const auto& row : frames[0].rows) {
    const auto v = numbers(row);
    CHECK(v[0] > prev);
    prev = static_cast<long long>(v[0]);
    CHECK(v[1] == e.particles->v[idx.at(prev)].x());
  }
  e.input->one("write_dump all custom/vtk " + dir + "/now.vtp id vx vy vz");
  CHECK(fs::exists(dir + "/now.vtp"));
  CHECK_FALSE(fs::exists(dir + "/now.pvd"));
  CHECK_THROWS_WITH(e.input->one("write_dump all nosuch " + dir + "/x.txt id"),
                    Contains("unknown dump style"));
}

TEST_CASE("dump custom: unwritable paths and bad fields give clear errors", "[dump][custom][errors]") {
  const std::string dir = fresh_dir("errors");
  granary::Engine e(MPI_COMM_WORLD);
  setup_bed(e);
  const std::string missing = dir + "/no/such/dir/d_*.txt";
  CHECK_THROWS_AS(e.input->one("dump d all custom 1 " + missing + " id"), granary::InputError);
  CHECK_THROWS_WITH(e.input->one("dump d all custom 1 " + missing + " id"),
                    Contains(missing) && Contains("does not exist"));
  CHECK_THROWS_WITH(e.input->one("write_dump all custom " + missing + " id"), Contains(missing));
  CHECK_THROWS_WITH(e.input->one("dump d all custom 1 " + dir + "/d.txt id vq"),
                    Contains("unknown field 'vq'"));
  CHECK_THROWS_WITH(e.input->one("dump d all custom 1 " + dir + "/d.txt"), Contains("field"));
  CHECK_THROWS_WITH(e.input->one("dump d all custom 1 " + dir + "/d.txt.gz id"), Contains(".gz"));

  // a file name that is an existing directory fails when the first frame is written
  fs::create_directories(dir + "/taken");
  e.input->one("dump d all custom 1 " + dir + "/taken id");
  CHECK_THROWS_WITH(e.input->one("run 1"), Contains(dir + "/taken"));
  e.input->one("undump d");

  e.input->one("dump v all custom 1 " + dir + "/v.txt id c_nosuch v_nosuch");
  CHECK_THROWS_WITH(e.input->one("run 0"), Contains("nosuch"));
  e.input->one("undump v");
  e.input->one("variable eq equal 2*3");
  e.input->one("dump v all custom 1 " + dir + "/v.txt id v_eq");
  CHECK_THROWS_WITH(e.input->one("run 0"), Contains("not an atom-style variable"));
}

// dump xyz: the count, "Atoms. Timestep: N", then type x y z (%g), as
// LIGGGHTS 3.8 writes it; the same text from the same script (sorted by id),
// compared with LIGGGHTS run live when it is installed.
TEST_CASE("dump xyz writes the count, the step line and type x y z as LIGGGHTS does", "[dump][xyz]") {
  const std::string dir = fresh_dir("xyz");
  const std::string script =
      "units si\natom_style granular\natom_modify map array\nboundary p f f\nnewton off\n"
      "communicate single vel yes\nregion box block 0 0.01 0 0.01 0 0.01 units box\ncreate_box 2 box\n"
      "create_atoms 1 single 0.005 0.005 0.005\ncreate_atoms 2 single 0.009 0.005 0.002\n"
      "create_atoms 1 single 0.001 0.008 0.007\nset atom 1 diameter 0.001 density 2500\n"
      "set atom 2 diameter 0.0012 density 2000\nset atom 3 diameter 0.001 density 2500\n"
      "dump x all xyz 1 frames.xyz\ndump_modify x sort id\n"
      "fix m1 all property/global youngsModulus peratomtype 7e6 7e6\n"
      "fix m2 all property/global poissonsRatio peratomtype 0.3 0.3\n"
      "fix m3 all property/global coefficientRestitution peratomtypepair 2 0.9 0.9 0.9 0.9\n"
      "fix m4 all property/global coefficientFriction peratomtypepair 2 0.3 0.3 0.3 0.3\n"
      "pair_style gran model hertz tangential history\npair_coeff * *\nvelocity all set 0.3 0.1 0.2\n"
      "timestep 1e-6\nfix integr all nve/sphere\nrun 1\n";
  std::ofstream(dir + "/in.xyz") << script;
  const std::string run_granary =
      "cd " + dir + " && " + GRANARY_BINARY + " -in in.xyz -log none > /dev/null 2>&1";
  REQUIRE(std::system(run_granary.c_str()) == 0);
  const std::vector<std::string> expect = {"3",
                                           "Atoms. Timestep: 0",
                                           "1 0.005 0.005 0.005",
                                           "2 0.009 0.005 0.002",
                                           "1 0.001 0.008 0.007",
                                           "3",
                                           "Atoms. Timestep: 1",
                                           "1 0.0050003 0.0050001 0.0050002",
                                           "2 0.0090003 0.0050001 0.0020002",
                                           "1 0.0010003 0.0080001 0.0070002"};
  CHECK(read_lines(dir + "/frames.xyz") == expect);
  if (std::system("command -v liggghts > /dev/null 2>&1") == 0) {
    fs::rename(dir + "/frames.xyz", dir + "/granary.xyz");
    REQUIRE(std::system(("cd " + dir + " && liggghts -in in.xyz -log none > /dev/null 2>&1").c_str()) == 0);
    CHECK(read_lines(dir + "/frames.xyz") == expect);
  }
  granary::test::ScriptEngine s;
  setup_bed(s.e);
  CHECK_THROWS_WITH(s.cmd("dump bad all xyz 1 " + dir + "/b.xyz id x"), Contains("xyz takes no fields"));
  s.cmd("dump ok all xyz 1 " + dir + "/ok.xyz");
  CHECK_THROWS_WITH(s.cmd("dump_modify ok time yes"), Contains("not available for dump xyz"));
}
