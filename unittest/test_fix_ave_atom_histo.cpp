// fix ave/atom and fix ave/histo.
//
// ave/atom: per-particle averages of known time series. Two spheres in an
// empty box, no contacts, gravity g along -z, dt = 1e-3 s: the velocity
// Verlet steps are exact for a constant force, so at step n
//   x = x0 + vx n dt,  z = z0 - g (n dt)^2 / 2,  vz = -g n dt,  fz = -m g,
// and the average of Nrepeat samples Nevery steps apart ending on a multiple
// of Nfreq follows from the sums of n and n^2 over the sampled steps.
//
// ave/histo: histograms of known values (particle velocities set one by one,
// a variable of the step) against bin counts worked out by hand, with the
// three beyond treatments, ave one and running, the file and the errors.
#include <mpi.h>
#include <unistd.h>

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
#include "particles/particles.h"
#include "script_engine.h"

using Catch::Matchers::Contains;
namespace fs = std::filesystem;

namespace {

struct Sim : granary::test::ScriptEngine {
  Sim() : ScriptEngine(MPI_COMM_WORLD) {}

  /// Per-atom column `col` of fix `id` for particle `tag` (gathered from its rank).
  double peratom(const std::string& id, int col, long long tag) {
    std::vector<double> v;
    e.fix_peratom(id, col, v);
    const granary::Particles& p = *e.particles;
    double mine = 0.0;
    int found = 0;
    for (int i = 0; i < p.nlocal; ++i)
      if (p.id[i] == tag) {
        mine = v[i];
        found = 1;
      }
    double all = 0.0;
    int nfound = 0;
    MPI_Allreduce(&mine, &all, 1, MPI_DOUBLE, MPI_SUM, e.world);
    MPI_Allreduce(&found, &nfound, 1, MPI_INT, MPI_SUM, e.world);
    REQUIRE(nfound == 1);
    return all;
  }
};

constexpr double kDt = 1e-3, kG = 9.81, kRho = 1000.0, kD = 0.1;
const double kMass = kRho * M_PI * kD * kD * kD / 6.0;

void setup(Sim& s) {
  s.cmds({"units si", "atom_style granular", "boundary f f f", "region box block 0 100 0 1 -100 1",
          "create_box 1 box", granary::test::materials(1, 5.e6, 0.45, 0.5, 0.5),
          "pair_style gran model hertz tangential history", "pair_coeff * *", "timestep 1e-3",
          "create_atoms 1 single 1 0.5 0.5", "create_atoms 1 single 50 0.5 0.5",
          "set atom 1 diameter 0.1 density 1000 vx 2", "set atom 2 diameter 0.1 density 1000 vx -1",
          "group first id 1", "fix g all gravity 9.81 vector 0 0 -1", "fix st all store/force",
          "fix nve all nve/sphere", "variable vx2 atom vx*vx"});
}

/// Mean of n and of n^2 over the steps end - (nrepeat-1)*every, ..., end.
void step_moments(long long end, long long every, long long nrepeat, double& m1, double& m2) {
  m1 = m2 = 0.0;
  for (long long k = 0; k < nrepeat; ++k) {
    const double n = static_cast<double>(end - k * every);
    m1 += n / static_cast<double>(nrepeat);
    m2 += n * n / static_cast<double>(nrepeat);
  }
}

}  // namespace

TEST_CASE("fix ave/atom: per-particle averages of attributes, fixes and atom variables", "[fix][ave/atom]") {
  Sim s;
  setup(s);
  s.cmds({"fix a first ave/atom 2 5 100 x z vz v_vx2 f_st[3]", "fix one all ave/atom 10 3 50 vx"});
  // before the first output: 0 (fix one has averaged steps 30, 40, 50 at step 50)
  s.cmd("run 99");
  CHECK(s.peratom("a", 1, 1) == 0.0);
  CHECK(s.peratom("one", 0, 1) == Approx(2.0).epsilon(1e-12));

  auto check_a = [&](long long end) {
    double m1, m2;
    step_moments(end, 2, 5, m1, m2);
    CHECK(s.peratom("a", 1, 1) == Approx(1.0 + 2.0 * kDt * m1).epsilon(1e-12));
    CHECK(s.peratom("a", 2, 1) == Approx(0.5 - 0.5 * kG * kDt * kDt * m2).epsilon(1e-9));
    CHECK(s.peratom("a", 3, 1) == Approx(-kG * kDt * m1).epsilon(1e-9));
    CHECK(s.peratom("a", 4, 1) == Approx(4.0).epsilon(1e-12));
    CHECK(s.peratom("a", 5, 1) == Approx(-kMass * kG).epsilon(1e-12));
    for (int c = 1; c <= 5; ++c)
      CHECK(s.peratom("a", c, 2) == 0.0);  // outside the group
  };
  s.cmd("run 1");  // step 100: samples at 92, 94, 96, 98, 100
  check_a(100);
  s.cmd("run 50");  // step 150: still the average of step 100
  check_a(100);
  s.cmd("run 50");  // step 200
  check_a(200);
  CHECK(s.peratom("one", 0, 1) == Approx(2.0).epsilon(1e-12));
  CHECK(s.peratom("one", 0, 2) == Approx(-1.0).epsilon(1e-12));

  // dump custom writes the averages
  const fs::path file =
      fs::temp_directory_path() / ("granary_aveatom_" + std::to_string(::getpid()) + ".dump");
  s.cmds({"dump d all custom 100 " + file.string() + " id f_a[1] f_a[3] f_one", "dump_modify d sort id",
          "run 100", "undump d"});
  if (s.e.rank == 0) {
    std::ifstream in(file);
    std::string line, last1, last2;
    while (std::getline(in, line)) {
      last1 = last2;
      last2 = line;
    }
    double m1, m2;
    step_moments(300, 2, 5, m1, m2);
    std::istringstream r1(last1), r2(last2);
    long long id = 0;
    double xa = 0, vza = 0, vxa = 0;
    r1 >> id >> xa >> vza >> vxa;
    CHECK(id == 1);
    CHECK(xa == Approx(1.0 + 2.0 * kDt * m1).epsilon(1e-5));
    CHECK(vza == Approx(-kG * kDt * m1).epsilon(1e-5));
    CHECK(vxa == Approx(2.0).epsilon(1e-5));
    r2 >> id >> xa >> vza >> vxa;
    CHECK(id == 2);
    CHECK(xa == 0.0);
    CHECK(vxa == Approx(-1.0).epsilon(1e-5));
    std::remove(file.c_str());
  }
}

TEST_CASE("fix ave/atom input errors", "[fix][ave/atom]") {
  Sim s;
  setup(s);
  s.cmd("compute ke all ke");
  s.cmd("variable e equal step");
  CHECK_THROWS_WITH(s.cmd("fix a all ave/atom 3 2 100 x"), Contains("multiple of Nevery"));
  CHECK_THROWS_WITH(s.cmd("fix a all ave/atom 10 11 100 x"), Contains("(Nrepeat-1)*Nevery"));
  CHECK_THROWS_WITH(s.cmd("fix a all ave/atom 0 1 100 x"), Contains("positive"));
  CHECK_THROWS_WITH(s.cmd("fix a all ave/atom 1 1 100"), Contains("usage"));
  CHECK_THROWS_WITH(s.cmd("fix a all ave/atom 1 1 100 radius"), Contains("unknown value 'radius'"));
  CHECK_THROWS_WITH(s.cmd("fix a all ave/atom 1 1 100 v_x[1]"), Contains("malformed"));
  auto at_run = [&](const std::string& fix, const std::string& message) {
    s.cmd(fix);
    CHECK_THROWS_WITH(s.cmd("run 0"), Contains(message));
    s.cmd("unfix a");
  };
  at_run("fix a all ave/atom 1 1 100 c_ke", "gives no per-atom values");
  at_run("fix a all ave/atom 1 1 100 c_none", "none");
  at_run("fix a all ave/atom 1 1 100 v_e", "must be atom-style");
  at_run("fix a all ave/atom 1 1 100 f_st", "per-atom array of 3 columns");
  at_run("fix a all ave/atom 1 1 100 f_st[4]", "has no column 4");
  at_run("fix a all ave/atom 1 1 100 f_a", "its own output");
}

namespace {

/// Eleven particles at rest except for vx: 0.05, 0.15, ..., 0.95 (two per
/// bin of width 0.2 in [0, 1]), then 1.5 and -0.2 outside it.
void histo_setup(Sim& s) {
  s.cmds({"units si", "atom_style granular", "boundary f f f", "region box block 0 100 0 1 -1 1",
          "create_box 1 box", granary::test::materials(1, 5.e6, 0.45, 0.5, 0.5),
          "pair_style gran model hertz tangential history", "pair_coeff * *", "timestep 1e-3"});
  const std::vector<double> vx = {0.05, 0.15, 0.25, 0.35, 0.45, 0.55, 0.65, 0.75, 0.85, 0.95, 1.5, -0.2};
  for (std::size_t k = 0; k < vx.size(); ++k) {
    s.cmd("create_atoms 1 single " + std::to_string(1.0 + 5.0 * k) + " 0.5 0");
    s.cmd("set atom " + std::to_string(k + 1) + " diameter 0.1 density 1000 vx " + std::to_string(vx[k]));
  }
  s.cmds({"fix nve all nve/sphere", "variable s equal step", "variable vxa atom vx"});
}

std::vector<std::vector<double>> histo_blocks(const fs::path& file) {
  std::ifstream in(file);
  std::string line;
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream r(line);
    std::vector<double> row;
    double x;
    while (r >> x)
      row.push_back(x);
    rows.push_back(row);
  }
  return rows;
}

}  // namespace

TEST_CASE("fix ave/histo: per-atom values binned with beyond ignore, end and extra", "[fix][ave/histo]") {
  Sim s;
  histo_setup(s);
  const std::string base =
      (fs::temp_directory_path() / ("granary_histo_" + std::to_string(::getpid()))).string();
  s.cmds({"fix h1 all ave/histo 1 1 10 0 1 5 vx mode vector file " + base + "_1.txt",
          "fix h2 all ave/histo 1 1 10 0 1 5 v_vxa mode vector beyond end file " + base + "_2.txt",
          "fix h3 all ave/histo 5 2 10 0 1 5 vx mode vector beyond extra file " + base + "_3.txt",
          // every column of a per-atom array: 12 x 3 zero forces, 0 on the
          // boundary of the two bins: the lower one
          "fix st all store/force",
          "fix hf all ave/histo 1 1 10 -1 1 2 f_st mode vector file " + base + "_f.txt",
          // overwrite: only the latest histogram stays in the file
          "fix hw all ave/histo 5 1 5 0 1 5 vx mode vector ave running overwrite file " + base + "_w.txt",
          "run 10"});
  CHECK(s.e.fix_value("hf", 1) == 36.0);
  CHECK(s.e.fix_value("hf", 3) == 0.0);
  CHECK(s.e.fix_value("hf", 4) == 0.0);
  // ignore: 10 binned, 2 missing; min -0.2, max 1.5
  CHECK(s.e.fix_value("h1", 1) == 10.0);
  CHECK(s.e.fix_value("h1", 2) == 2.0);
  CHECK(s.e.fix_value("h1", 3) == Approx(-0.2).epsilon(1e-12));
  CHECK(s.e.fix_value("h1", 4) == Approx(1.5).epsilon(1e-12));
  CHECK(s.e.fix_value("h2", 1) == 12.0);  // end: all binned
  CHECK(s.e.fix_value("h2", 2) == 0.0);
  CHECK(s.e.fix_value("h3", 1) == 12.0);  // extra: the average of 2 samples of 12 values
  CHECK(s.e.fix_value("h3", 2) == 0.0);
  if (s.e.rank != 0) return;
  struct Expect {
    int nbins;
    std::vector<double> coord, count;
    double total, missing;
  };
  const std::vector<Expect> expect = {
      {5, {0.1, 0.3, 0.5, 0.7, 0.9}, {2, 2, 2, 2, 2}, 10, 2},
      {5, {0.1, 0.3, 0.5, 0.7, 0.9}, {3, 2, 2, 2, 3}, 12, 0},
      {7, {0.0, 0.1, 0.3, 0.5, 0.7, 0.9, 1.0}, {1, 2, 2, 2, 2, 2, 1}, 12, 0},
  };
  {
    const auto f = histo_blocks(base + "_f.txt");
    REQUIRE(f.size() == 6);  // steps 0 and 10, 2 bins each
    CHECK(f[4] == std::vector<double>{1, -0.5, 36, 1});
    CHECK(f[5] == std::vector<double>{2, 0.5, 0, 0});
    const auto w = histo_blocks(base + "_w.txt");
    REQUIRE(w.size() == 6);  // one block: step 10, the running average of steps 0, 5, 10
    CHECK(w[0][0] == 10.0);
    CHECK(w[0][2] == 10.0);
    std::remove((base + "_f.txt").c_str());
    std::remove((base + "_w.txt").c_str());
  }
  for (int f = 0; f < 3; ++f) {
    const std::string name = base + "_" + std::to_string(f + 1) + ".txt";
    const auto all = histo_blocks(name);
    const Expect& e = expect[f];
    // two outputs: step 0 (the first step of the run is a sampling step of h1
    // and h2, Nrepeat 1) or none (h3), and step 10; the same velocities
    const std::size_t block = 1 + static_cast<std::size_t>(e.nbins);
    REQUIRE(all.size() == (f < 2 ? 2 : 1) * block);
    if (f < 2) CHECK(all[0][0] == 0.0);
    const std::vector<std::vector<double>> rows(all.end() - static_cast<std::ptrdiff_t>(block), all.end());
    REQUIRE(rows[0].size() == 6);
    CHECK(rows[0][0] == 10.0);
    CHECK(rows[0][1] == e.nbins);
    CHECK(rows[0][2] == e.total);
    CHECK(rows[0][3] == e.missing);
    CHECK(rows[0][4] == Approx(-0.2));
    CHECK(rows[0][5] == Approx(1.5));
    for (int b = 0; b < e.nbins; ++b) {
      REQUIRE(rows[1 + b].size() == 4);
      CHECK(rows[1 + b][0] == b + 1);
      CHECK(rows[1 + b][1] == Approx(e.coord[b]).margin(1e-12));
      CHECK(rows[1 + b][2] == e.count[b]);
      CHECK(rows[1 + b][3] == Approx(e.count[b] / e.total).epsilon(1e-9));
    }
    std::remove(name.c_str());
  }
}

TEST_CASE("fix ave/histo: global values over time, boundaries, ave one and running", "[fix][ave/histo]") {
  Sim s;
  histo_setup(s);
  // steps 1..10 give 1..10: each value on the upper edge of its bin [k-1, k]
  // (the lower of the two bins it touches); averaged over Nrepeat = 10
  // samples each bin holds 0.1; steps 11..20 lie above hi
  s.cmds({"fix one all ave/histo 1 10 10 0 10 10 v_s",
          "fix run all ave/histo 1 10 10 0 10 10 v_s ave running",
          "fix win all ave/histo 1 10 10 0 10 10 v_s ave window 2", "run 10"});
  CHECK(s.e.fix_value("one", 1) == Approx(1.0).epsilon(1e-12));
  CHECK(s.e.fix_value("one", 2) == 0.0);
  CHECK(s.e.fix_value("one", 3) == 1.0);
  CHECK(s.e.fix_value("one", 4) == 10.0);
  s.cmd("run 10");
  CHECK(s.e.fix_value("one", 1) == 0.0);
  CHECK(s.e.fix_value("one", 2) == Approx(1.0).epsilon(1e-12));
  CHECK(s.e.fix_value("one", 3) == 11.0);
  CHECK(s.e.fix_value("run", 1) == Approx(0.5).epsilon(1e-12));  // (1 + 0) / 2
  CHECK(s.e.fix_value("run", 2) == Approx(0.5).epsilon(1e-12));
  CHECK(s.e.fix_value("run", 3) == 1.0);
  CHECK(s.e.fix_value("run", 4) == 20.0);
  s.cmd("run 20");
  CHECK(s.e.fix_value("run", 1) == Approx(0.25).epsilon(1e-12));  // (1 + 0 + 0 + 0) / 4
  CHECK(s.e.fix_value("win", 1) == 0.0);                          // steps 21..40 only
  CHECK(s.e.fix_value("win", 3) == 21.0);
}

TEST_CASE("fix ave/histo input errors", "[fix][ave/histo]") {
  Sim s;
  histo_setup(s);
  CHECK_THROWS_WITH(s.cmd("fix h all ave/histo 1 1 10 1 0 5 v_s"), Contains("larger than lo"));
  CHECK_THROWS_WITH(s.cmd("fix h all ave/histo 1 1 10 0 1 0 v_s"), Contains("Nbin"));
  CHECK_THROWS_WITH(s.cmd("fix h all ave/histo 3 1 10 0 1 5 v_s"), Contains("multiple of Nevery"));
  CHECK_THROWS_WITH(s.cmd("fix h all ave/histo 1 1 10 0 1 5 vx"), Contains("needs mode vector"));
  CHECK_THROWS_WITH(s.cmd("fix h all ave/histo 1 1 10 0 1 5 v_s beyond far"),
                    Contains("ignore, end or extra"));
  CHECK_THROWS_WITH(s.cmd("fix h all ave/histo 1 1 10 0 1 5 v_s overwrite"), Contains("ave running"));
  CHECK_THROWS_WITH(s.cmd("fix h all ave/histo 1 1 10 0 1 5 v_s file /nonexistent/dir/h.txt"),
                    Contains("writable"));
  s.cmd("fix h all ave/histo 1 1 10 0 1 5 v_vxa");
  CHECK_THROWS_WITH(s.cmd("run 0"), Contains("needs mode vector"));
  s.cmd("unfix h");
  s.cmd("fix h all ave/histo 1 1 10 0 1 5 v_s mode vector");
  CHECK_THROWS_WITH(s.cmd("run 0"), Contains("must be atom-style"));
  s.cmd("unfix h");
}
