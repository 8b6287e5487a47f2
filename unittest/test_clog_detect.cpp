// fix clog-detect: bodies through an outlet, clogs, avalanches, actions.
//
// The silo bottom of clog_scene.h (a floor of fixed spheres with a hole about
// 2.2 grain diameters wide, 400 frictional grains) is poured once and kept in
// a restart file that the tests start from. The tests check:
// - action delete: every avalanche row obeys its definitions (t_clog = t_end + T
//   within a step, the next avalanche starts at the clog), grains are
//   conserved (in the silo + passed + deleted from the arch = poured), the
//   counted mass is the number times the grain mass, the file matches f_ID,
//   the bodies deleted per clog add up to the total;
// - arch_layer 0 deletes exactly the lowest body of the arch region at each
//   clog; a layer thicker than the region deletes what the whole region does;
// - still: a clog waits until the bodies in the region are at rest;
// - a restart written during an avalanche continues with the same log;
// - action halt ends the run at the clog step; with the arch left in place the
//   next run passes nothing and clogs exactly T later; stop_height ends the
//   discharge; the fill height is the 99 % quantile of the grain heights;
// - clumps count once, with their mass, and are removed whole; with remove no
//   nothing counts twice;
// - bad input is refused with a message.
#include <mpi.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <unistd.h>
#include <vector>

#include "clog_scene.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/update.h"
#include "fix/fix_multisphere.h"
#include "core/modify.h"
#include "particles/particles.h"
#include "script_engine.h"

using Catch::Contains;
using granary::test::ScriptEngine;

namespace {

constexpr double kT = 0.05;  // timeout [s]
constexpr double kDt = clog_scene::kTimestep;
const double kGrainMass = 2500.0 * 4.0 / 3.0 * M_PI * std::pow(0.5 * clog_scene::kGrainDiameter, 3);

std::string temp_name(const std::string& prefix) {
  std::vector<char> t = granary::test::temp_template(prefix);
  const int fd = mkstemp(t.data());
  REQUIRE(fd >= 0);
  close(fd);
  return std::string(t.data());
}

/// The poured scene, written once per test program (periodic in x and y, or closed by walls).
const std::string& filled_restart(bool walled = false) {
  static std::string files[2];
  std::string& file = files[walled ? 1 : 0];
  if (file.empty()) {
    file = temp_name(walled ? "clog_fillw_" : "clog_fill_");
    ScriptEngine s;
    s.cmds(clog_scene::filled(400, walled));
    s.cmd("write_restart " + file);
  }
  return file;
}

struct Row {
  int avalanche = 0;
  double t_start = 0, t_end = 0, t_clog = 0, duration = 0;
  long long bodies = 0;
  double mass = 0, rate = 0, fill = 0;
  long long arch = 0;
  std::vector<double> per_type;
  std::string text;
};

struct Csv {
  std::vector<std::string> comments;
  std::string header;
  std::vector<Row> rows;
};

Csv read_csv(const std::string& file) {
  Csv c;
  std::ifstream in(file);
  REQUIRE(in.good());
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    if (line[0] == '#') {
      c.comments.push_back(line);
      continue;
    }
    if (c.header.empty()) {
      c.header = line;
      continue;
    }
    Row r;
    r.text = line;
    std::vector<double> v;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ','))
      v.push_back(std::stod(cell));
    REQUIRE(v.size() >= 10);
    r.avalanche = static_cast<int>(v[0]);
    r.t_start = v[1];
    r.t_end = v[2];
    r.t_clog = v[3];
    r.duration = v[4];
    r.bodies = static_cast<long long>(v[5]);
    r.mass = v[6];
    r.rate = v[7];
    r.fill = v[8];
    r.arch = static_cast<long long>(v[9]);
    r.per_type.assign(v.begin() + 10, v.end());
    c.rows.push_back(r);
  }
  return c;
}

double f(ScriptEngine& s, int index) {
  return s.e.fix_value("clog", index);
}
double grains(ScriptEngine& s) {
  return s.e.group_function("count", {"grains"});
}

/// Rows must obey the definitions of the avalanche file.
void check_rows(const Csv& c, bool starts_at_clog) {
  for (std::size_t k = 0; k < c.rows.size(); ++k) {
    const Row& r = c.rows[k];
    INFO("row " << r.text);
    CHECK(r.avalanche == static_cast<int>(k + 1));
    CHECK(r.duration == Approx(r.t_end - r.t_start).margin(1e-9));
    // declared at the first step at least T after the last passage
    CHECK(r.t_clog - r.t_end > kT - 1e-8);
    CHECK(r.t_clog - r.t_end < kT + kDt + 1e-8);
    if (r.bodies == 0) CHECK(r.t_end == r.t_start);
    CHECK(r.mass == Approx(r.bodies * kGrainMass).epsilon(1e-8));
    CHECK(r.rate == Approx(r.duration > 0 ? r.mass / r.duration : 0.0).epsilon(1e-8).margin(1e-12));
    REQUIRE(r.per_type.size() == 4);  // two atom types
    CHECK(r.per_type[0] == r.bodies);
    CHECK(r.per_type[1] == Approx(r.mass).epsilon(1e-9));
    CHECK(r.per_type[2] == 0);
    CHECK(r.per_type[3] == 0);
    if (starts_at_clog && k > 0) CHECK(r.t_start == c.rows[k - 1].t_clog);
  }
}

/// A continued run wrote the same avalanche rows as the reference run (file
/// rows `ca`), and the fixes' outputs agree.
void check_same_log(const Csv& ca, const std::string& fb, ScriptEngine& a, ScriptEngine& b) {
  const Csv cb = read_csv(fb);
  REQUIRE(cb.rows.size() == ca.rows.size());
  for (std::size_t k = 0; k < ca.rows.size(); ++k)
    CHECK(cb.rows[k].text == ca.rows[k].text);
  for (int i = 0; i <= 12; ++i)
    CHECK(f(b, i) == f(a, i));
}

}  // namespace

TEST_CASE("clog-detect: action delete records avalanches, and grains are conserved") {
  const std::string fa = temp_name("clog_a_") + ".csv";
  const std::string fix =
      "fix clog grains clog-detect outlet out timeout 0.05 arch arch action delete height_region bed file ";
  ScriptEngine a;
  a.cmds(clog_scene::restarted(filled_restart()));
  const double poured = grains(a);
  REQUIRE(poured >= 340);  // create_atoms random placed most of the 400
  a.cmd(fix + fa);
  a.cmd("thermo_style custom step atoms f_clog f_clog[5] f_clog[7] f_clog[9]");
  a.cmd("run 12000");
  const Csv ca = read_csv(fa);
  INFO("avalanche file:\n"
       << [&] {
            std::ifstream in(fa);
            std::stringstream ss;
            ss << in.rdbuf();
            return ss.str();
          }());
  REQUIRE(ca.rows.size() >= 2);
  CHECK(f(a, 0) == ca.rows.size());
  check_rows(ca, true);
  // the first avalanche began when the fix's first run started (t = 0.125 s)
  CHECK(ca.rows[0].t_start == Approx(0.125).margin(1e-12));
  // conservation: grains in the silo + passed + deleted from the arch = poured
  CHECK(grains(a) + f(a, 5) + f(a, 11) == poured);
  CHECK(f(a, 6) == Approx(f(a, 5) * kGrainMass).epsilon(1e-10));
  CHECK(f(a, 11) > 0);
  // the file matches the outputs
  long long sum = 0;
  for (const auto& r : ca.rows)
    sum += r.bodies;
  CHECK(sum + f(a, 12) == f(a, 5));
  const Row& last = ca.rows.back();
  CHECK(f(a, 2) == last.bodies);
  CHECK(f(a, 3) == Approx(last.mass).epsilon(1e-9));
  CHECK(f(a, 4) == Approx(last.duration).epsilon(1e-9));
  CHECK(f(a, 8) == Approx(last.fill).epsilon(1e-9));
  CHECK(ca.header ==
        "avalanche,t_start,t_end,t_clog,duration,bodies,mass,flow_rate,fill_height,arch_removed,bodies_t1,"
        "mass_t1,bodies_t2,mass_t2");
  // the bodies deleted at each clog, row by row, add up to the total
  long long removed = 0;
  for (const auto& r : ca.rows)
    removed += r.arch;
  CHECK(removed == f(a, 11));
  REQUIRE(ca.comments.size() >= 3);
  CHECK_THAT(ca.comments[1], Contains("SI"));
  // a real avalanche flowed after the arch was deleted
  long long most = 0;
  for (const auto& r : ca.rows)
    most = std::max(most, r.bodies);
  CHECK(most >= 5);

  std::remove(fa.c_str());
}

TEST_CASE("clog-detect: action halt ends the run at the clog, and stop_height ends the discharge") {
  const std::string fh = temp_name("clog_h_") + ".csv";
  ScriptEngine s;
  s.cmds(clog_scene::restarted(filled_restart()));
  s.cmd(
      "fix clog grains clog-detect outlet out timeout 0.05 arch arch action halt stop_height 0.015 "
      "height_region bed file " +
      fh);
  auto& u = *s.e.update;
  s.cmd("run 100000");
  REQUIRE(u.ntimestep < u.laststep);  // halted
  Csv c = read_csv(fh);
  REQUIRE(c.rows.size() == 1);
  CHECK(c.rows[0].t_clog == Approx(u.time()).margin(1e-12));
  CHECK(f(s, 7) == 1);  // clogged
  CHECK(f(s, 10) == 0);
  CHECK(f(s, 9) > kT - 1e-8);

  // the fill height: the 99 % quantile of the grain centre heights in region bed
  {
    const auto& p = *s.e.particles;
    std::vector<double> z;
    for (int i = 0; i < p.nlocal; ++i)
      if (p.type[i] == 1 && p.x[i][2] > 0.0005) z.push_back(p.x[i][2]);
    std::sort(z.begin(), z.end());
    const std::size_t k = static_cast<std::size_t>(std::ceil(0.99 * z.size()));
    CHECK(f(s, 8) == z[k - 1]);
    CHECK(c.rows[0].fill == Approx(z[k - 1]).epsilon(1e-9));
  }

  // with the grains held still, the next run passes nothing and clogs again
  // after exactly T (an arch that has held for T may still give way later, so
  // the grains are not integrated for this run)
  const auto step0 = u.ntimestep;
  const double t0 = u.time();
  const double atoms0 = s.e.particles->natoms;
  s.cmd("unfix integr");
  s.cmd("run 100000");
  s.cmd("fix integr grains nve/sphere");
  CHECK(u.ntimestep - step0 == static_cast<long long>(std::llround(kT / kDt)));
  CHECK(s.e.particles->natoms == atoms0);
  c = read_csv(fh);
  REQUIRE(c.rows.size() == 2);
  CHECK(c.rows[1].bodies == 0);
  CHECK(c.rows[1].t_start == Approx(t0).margin(1e-12));
  CHECK(c.rows[1].t_clog == Approx(t0 + kT).margin(1e-9));

  // the script removes the arch and runs on, until the fill height is below stop_height
  const double passed0 = f(s, 5);
  for (int k = 0; k < 8 && f(s, 10) == 0; ++k) {
    s.cmd("delete_atoms region arch");
    s.cmd("run 100000");
    REQUIRE(u.ntimestep < u.laststep);
  }
  CHECK(f(s, 10) == 1);
  CHECK(f(s, 7) == 2);
  CHECK(f(s, 5) > passed0);
  c = read_csv(fh);
  REQUIRE(c.rows.size() >= 3);
  check_rows(c, false);
  for (std::size_t k = 0; k + 1 < c.rows.size(); ++k)
    CHECK(c.rows[k].fill >= 0.015);
  CHECK(c.rows.back().fill < 0.015);
  CHECK(c.rows.back().t_clog == Approx(u.time()).margin(1e-12));
  std::remove(fh.c_str());
}

// stop_empty: when the flow no longer restarts (here the grains are held
// still), the discharge ends after N empty avalanches in a row, each T long.
TEST_CASE("clog-detect: stop_empty ends the discharge after empty avalanches") {
  const std::string fe = temp_name("clog_e_") + ".csv";
  ScriptEngine s;
  s.cmds(clog_scene::restarted(filled_restart()));
  s.cmd("unfix integr");
  s.cmd("fix clog grains clog-detect outlet out timeout 0.05 arch arch action delete stop_empty 3 file " +
        fe);
  auto& u = *s.e.update;
  const auto step0 = u.ntimestep;
  s.cmd("run 100000");
  CHECK(u.ntimestep - step0 == 3 * static_cast<long long>(std::llround(kT / kDt)));
  CHECK(f(s, 10) == 1);
  CHECK(f(s, 7) == 2);
  const Csv c = read_csv(fe);
  REQUIRE(c.rows.size() == 3);
  for (const auto& r : c.rows)
    CHECK(r.bodies == 0);
  check_rows(c, true);
  std::remove(fe.c_str());
}

TEST_CASE("clog-detect: arch_layer deletes only the lowest layer of the arch region") {
  // arch_layer 0: at each clog only the lowest body of region arch goes
  const std::string f0 = temp_name("clog_l0_") + ".csv";
  ScriptEngine a;
  a.cmds(clog_scene::restarted(filled_restart()));
  const double poured = grains(a);
  a.cmd("fix clog grains clog-detect outlet out timeout 0.05 arch arch arch_layer 0 action delete file " +
        f0);
  a.cmd("run 12000");
  const Csv c0 = read_csv(f0);
  REQUIRE(c0.rows.size() >= 2);
  check_rows(c0, true);
  for (const auto& r : c0.rows) {
    INFO("row " << r.text);
    CHECK(r.arch == 1);
  }
  CHECK(f(a, 11) == static_cast<double>(c0.rows.size()));
  CHECK(grains(a) + f(a, 5) + f(a, 11) == poured);

  // a layer thicker than the region: the same avalanches as without arch_layer
  const std::string fw = temp_name("clog_lw_") + ".csv", fa = temp_name("clog_la_") + ".csv";
  ScriptEngine w, all;
  w.cmds(clog_scene::restarted(filled_restart()));
  all.cmds(clog_scene::restarted(filled_restart()));
  w.cmd("fix clog grains clog-detect outlet out timeout 0.05 arch arch arch_layer 1.0 action delete file " +
        fw);
  all.cmd("fix clog grains clog-detect outlet out timeout 0.05 arch arch action delete file " + fa);
  w.cmd("run 6000");
  all.cmd("run 6000");
  const Csv cw = read_csv(fw), ca = read_csv(fa);
  REQUIRE(ca.rows.size() >= 1);
  REQUIRE(cw.rows.size() == ca.rows.size());
  for (std::size_t k = 0; k < ca.rows.size(); ++k)
    CHECK(cw.rows[k].text == ca.rows[k].text);
  // ... and more than one body there: the lowest layer is a real choice
  CHECK(ca.rows[0].arch > 1);
  for (const auto& name : {f0, fw, fa})
    std::remove(name.c_str());
}

TEST_CASE("clog-detect: final_action deletes the arch of the clog that ends the discharge") {
  const std::string ff = temp_name("clog_f_") + ".csv";
  ScriptEngine s;
  s.cmds(clog_scene::restarted(filled_restart()));
  const double poured = grains(s);
  s.cmd(
      "fix clog grains clog-detect outlet out timeout 0.05 arch arch action delete stop_height 1.0 "
      "final_action yes file " +
      ff);
  s.cmd("run 100000");
  // the first clog ends the discharge (every fill height is below 1 m), and its arch is gone
  const Csv c = read_csv(ff);
  REQUIRE(c.rows.size() == 1);
  CHECK(f(s, 10) == 1);
  CHECK(c.rows[0].arch > 0);
  CHECK(f(s, 11) == c.rows[0].arch);
  CHECK(s.e.group_function("count", {"grains", "arch"}) == 0);
  CHECK(grains(s) + f(s, 5) + f(s, 11) == poured);
  std::remove(ff.c_str());
}

TEST_CASE("clog-detect: still waits until the bodies in the region are at rest") {
  constexpr double kStill = 2e-3;  // [m/s]
  const std::string fs = temp_name("clog_s_") + ".csv", fn = temp_name("clog_n_") + ".csv";
  ScriptEngine s, n;
  s.cmds(clog_scene::restarted(filled_restart()));
  n.cmds(clog_scene::restarted(filled_restart()));
  s.cmd("fix clog grains clog-detect outlet out timeout 0.05 arch arch action halt still arch 0.002 file " +
        fs);
  n.cmd("fix clog grains clog-detect outlet out timeout 0.05 arch arch action halt file " + fn);
  s.cmd("run 100000");
  n.cmd("run 100000");
  const Csv cs = read_csv(fs), cn = read_csv(fn);
  REQUIRE(cs.rows.size() == 1);
  REQUIRE(cn.rows.size() == 1);
  // the same trajectory up to the clog without the rest condition
  CHECK(cs.rows[0].t_end == cn.rows[0].t_end);
  CHECK(cs.rows[0].bodies == cn.rows[0].bodies);
  CHECK(cs.rows[0].t_clog >= cn.rows[0].t_clog);
  // at the clog every grain in the region moves slower than the given speed
  s.cmd("variable sp atom sqrt(vx*vx+vy*vy+vz*vz)");
  s.cmd("compute vmax grains reduce/region arch max v_sp");
  s.cmd("thermo_style custom step c_vmax");
  s.cmd("run 0");
  const double vmax = s.e.compute_value("vmax", 0);
  CHECK(vmax < kStill);
  CHECK(vmax > 0.0);
  // a speed no grain reaches: the clog comes after exactly the timeout, as without the condition
  const std::string fr = temp_name("clog_r_") + ".csv";
  ScriptEngine r;
  r.cmds(clog_scene::restarted(filled_restart()));
  r.cmd("fix clog grains clog-detect outlet out timeout 0.05 arch arch action halt still arch 100 file " +
        fr);
  r.cmd("run 100000");
  const Csv cr = read_csv(fr);
  REQUIRE(cr.rows.size() == 1);
  CHECK(cr.rows[0].text == cn.rows[0].text);
  for (const auto& name : {fs, fn, fr})
    std::remove(name.c_str());
}

namespace {

// Six dumbbell clumps and three free spheres falling through an outlet block.
std::vector<std::string> clump_scene(const std::string& remove) {
  std::vector<std::string> s = clog_scene::dumbbell_box(0.04);
  s.push_back("fix floor all wall/gran model hertz tangential history primitive type 1 zplane -0.0195");
  for (int k = 0; k < 6; ++k) {
    char line[200];
    std::snprintf(line, sizeof line, "create_clump dumb %.4f %.4f %.4f quat 0.9 0.1 0.3 0.2",
                  0.004 + 0.006 * (k % 3), 0.005 + 0.01 * (k / 3), 0.01 + 0.004 * k);
    s.push_back(line);
  }
  for (int k = 0; k < 3; ++k)
    s.push_back("create_atoms 2 single " + std::to_string(0.004 + 0.006 * k) + " 0.010 0.03 units box");
  s.push_back("set type 2 diameter 0.002 density 2000");
  s.push_back("group free type 2");
  s.push_back("fix integr free nve/sphere");
  s.push_back("region out block 0 0.02 0 0.02 -0.02 -0.01 units box");
  s.push_back("fix clog all clog-detect outlet out timeout 1 remove " + remove);
  return s;
}

}  // namespace

TEST_CASE("clog-detect: a clump counts once, with its mass, and is removed whole") {
  for (const std::string remove : {"yes", "no"}) {
    INFO("remove " << remove);
    ScriptEngine s;
    s.cmds(clump_scene(remove));
    auto* ms = dynamic_cast<granary::FixMultisphere*>(s.e.clumps);
    REQUIRE(ms->bodies().size() == 6);
    double mass = 3 * 2000.0 * 4.0 / 3.0 * M_PI * 1e-9;
    for (int b = 0; b < 6; ++b)
      mass += ms->bodies().mass[b];
    REQUIRE(s.e.particles->natoms == 15);
    s.cmd("run 3000");  // 0.15 s: everything has fallen 0.11 m or come to rest on the floor
    CHECK(f(s, 5) == 9);
    CHECK(f(s, 6) == Approx(mass).epsilon(1e-12));
    CHECK(f(s, 12) == 9);
    CHECK(f(s, 0) == 0);  // no clog yet (timeout 1 s)
    if (remove == "yes") {
      CHECK(ms->bodies().size() == 0);
      CHECK(s.e.particles->natoms == 0);
    } else {
      CHECK(ms->bodies().size() == 6);
      CHECK(s.e.particles->natoms == 15);
      s.cmd("run 1000");  // they rest in the outlet: not counted again
      CHECK(f(s, 5) == 9);
    }
  }
}

namespace {

// Two bursts of free-falling spheres (no contacts, so the trajectories do not
// depend on round-off): 6 spheres reach the outlet at about 0.03 s, 4 at about
// 0.119 s; with timeout 0.035 s each burst is one avalanche (action none).
std::vector<std::string> burst_scene() {
  std::vector<std::string> s = clog_scene::box(0.07);
  clog_scene::append(s, clog_scene::materials());
  clog_scene::append(s, {
                            "fix g all gravity 9.81 vector 0 0 -1",
                            "fix integr all nve/sphere",
                            "region out block 0 0.02 0 0.02 -0.02 -0.01 units box",
                        });
  return s;
}

std::vector<std::string> burst_particles() {
  std::vector<std::string> s;
  for (int k = 0; k < 6; ++k)
    s.push_back("create_atoms " + std::to_string(1 + k % 2) + " single " + std::to_string(0.003 + 0.003 * k) +
                " 0.005 " + std::to_string(-0.006 + 0.0002 * k) + " units box");
  for (int k = 0; k < 4; ++k)
    s.push_back("create_atoms 2 single " + std::to_string(0.004 + 0.004 * k) + " 0.015 0.06 units box");
  s.push_back("set type 1 diameter 0.002 density 2500");
  s.push_back("set type 2 diameter 0.003 density 2000");
  return s;
}

}  // namespace

TEST_CASE("clog-detect: a restart written during an avalanche continues with the same log") {
  const std::string fa = temp_name("clog_ra_") + ".csv", fb = temp_name("clog_rb_") + ".csv";
  const std::string mid = temp_name("clog_rmid_");
  const std::string fix = "fix clog all clog-detect outlet out timeout 0.035 action none file ";
  ScriptEngine a;
  a.cmds(burst_scene());
  a.cmds(burst_particles());
  a.cmd(fix + fa);
  a.cmd("run 1000");  // 0.05 s: the first burst has passed, the clog is not yet declared
  REQUIRE(f(a, 12) == 6);
  REQUIRE(f(a, 0) == 0);
  a.cmd("write_restart " + mid);
  a.cmd("run 2400");
  const Csv ca = read_csv(fa);
  REQUIRE(ca.rows.size() == 2);
  CHECK(ca.rows[0].bodies == 6);
  CHECK(ca.rows[1].bodies == 4);
  const double m1 = 2500.0 * 4.0 / 3.0 * M_PI * 1e-9, m2 = 2000.0 * 4.0 / 3.0 * M_PI * std::pow(0.0015, 3);
  CHECK(ca.rows[0].mass == Approx(3 * m1 + 3 * m2).epsilon(1e-9));
  CHECK(ca.rows[1].mass == Approx(4 * m2).epsilon(1e-9));
  REQUIRE(ca.rows[0].per_type.size() == 4);
  CHECK(ca.rows[0].per_type[0] == 3);
  CHECK(ca.rows[0].per_type[2] == 3);
  CHECK(ca.rows[1].per_type[0] == 0);
  CHECK(ca.rows[1].per_type[2] == 4);
  // free fall from 0.06 m to the outlet top at -0.01 m: t = sqrt(2 * 0.07 / g)
  CHECK(ca.rows[1].t_start == Approx(std::sqrt(2 * 0.07 / 9.81)).margin(3 * kDt));
  CHECK(ca.rows[1].t_clog - ca.rows[1].t_end == Approx(0.035).margin(kDt));
  CHECK(f(a, 7) == 1);  // clogged (action none)

  ScriptEngine b;
  b.cmds({"atom_style granular", "atom_modify map array", "read_restart " + mid});
  auto scene = burst_scene();
  for (std::size_t k = clog_scene::box(0.07).size(); k < scene.size(); ++k)  // without the box
    b.cmd(scene[k]);
  b.cmd(fix + fb);
  b.cmd("run 2400");
  check_same_log(ca, fb, a, b);
  std::remove(fa.c_str());
  std::remove(fb.c_str());
  std::remove(mid.c_str());
}

// The orifice scene (closed by walls: see clog_scene::physics): a restart
// written in the middle of the discharge (arches forming and deleted) continues,
// in a fresh engine, with the avalanche log of the uninterrupted run, row for
// row and digit for digit.
TEST_CASE("clog-detect: a restart in the middle of the discharge gives the same avalanche log") {
  const std::string fa = temp_name("clog_sa_") + ".csv", fb = temp_name("clog_sb_") + ".csv";
  const std::string fm = temp_name("clog_sm_") + ".csv", mid = temp_name("clog_smid_");
  const std::string fix =
      "fix clog grains clog-detect outlet out timeout 0.05 arch arch action delete height_region bed file ";
  ScriptEngine a;
  a.cmds(clog_scene::restarted(filled_restart(true), true));
  a.cmd(fix + fa);
  a.cmd("run 12000");
  const Csv ca = read_csv(fa);
  REQUIRE(ca.rows.size() >= 2);
  {
    ScriptEngine m;
    m.cmds(clog_scene::restarted(filled_restart(true), true));
    m.cmd(fix + fm);
    m.cmd("run 6000");
    m.cmd("write_restart " + mid);
  }
  const Csv cm = read_csv(fm);
  // the restart lies between avalanches' clogs: some rows before it, some after
  REQUIRE(cm.rows.size() >= 1);
  REQUIRE(cm.rows.size() < ca.rows.size());
  ScriptEngine b;
  b.cmds(clog_scene::restarted(mid, true));
  b.cmd(fix + fb);
  b.cmd("run 6000");
  check_same_log(ca, fb, a, b);
  CHECK(grains(b) == grains(a));
  // the continuation is exact: positions agree to the bit
  CHECK(b.e.group_function("xcm", {"grains", "z"}) == a.e.group_function("xcm", {"grains", "z"}));
  for (const auto& file : {fa, fb, fm, mid})
    std::remove(file.c_str());
}

TEST_CASE("clog-detect: bad input is refused") {
  ScriptEngine s;
  s.cmds({"units si", "atom_style granular", "region box block 0 0.01 0 0.01 0 0.01 units box",
          "create_box 1 box", "region out block 0 0.01 0 0.01 0 0.002 units box"});
  auto error = [&](const std::string& line) -> std::string {
    try {
      s.cmd(line);
    } catch (const granary::InputError& e) {
      return e.what();
    }
    FAIL("no error for: " << line);
    return "";
  };
  CHECK_THAT(error("fix c all clog-detect timeout 1"), Contains("outlet"));
  CHECK_THAT(error("fix c all clog-detect outlet nowhere timeout 1"), Contains("nowhere"));
  CHECK_THAT(error("fix c all clog-detect outlet out"), Contains("timeout"));
  CHECK_THAT(error("fix c all clog-detect outlet out timeout 0"), Contains("positive"));
  CHECK_THAT(error("fix c all clog-detect outlet out timeout -1"), Contains("positive"));
  CHECK_THAT(error("fix c all clog-detect outlet out timeout abc"), Contains("timeout"));
  CHECK_THAT(error("fix c all clog-detect outlet out timeout 1 action explode"), Contains("unknown action"));
  CHECK_THAT(error("fix c all clog-detect outlet out timeout 1 action halts"), Contains("halt"));
  CHECK_THAT(error("fix c all clog-detect outlet out timeout 1 action delete"), Contains("arch"));
  CHECK_THAT(error("fix c all clog-detect outlet out timeout 1 arch out action kick"),
             Contains("kick VX VY VZ"));
  CHECK_THAT(error("fix c all clog-detect outlet out timeout 1 arch out kick 0 0"), Contains("kick"));
  CHECK_THAT(error("fix c all clog-detect outlet out timeout 1 timout 2"), Contains("timeout"));
  CHECK_THAT(error("fix c all clog-detect outlet out timeout 1 every 0"), Contains("every"));
  CHECK_THAT(error("fix c all clog-detect outlet out timeout 1 stop_empty 0"), Contains("stop_empty"));
  CHECK_THAT(error("fix c all clog-detect outlet out timeout 1 quantile 1.5"), Contains("quantile"));
  CHECK_THAT(error("fix c all clog-detect outlet out timeout 1 height_region nowhere"), Contains("nowhere"));
  CHECK_THAT(error("fix c all clog-detect outlet out timeout 1 arch_layer 0.001"),
             Contains("give arch REGION"));
  CHECK_THAT(error("fix c all clog-detect outlet out timeout 1 arch out arch_layer -1"),
             Contains("arch_layer"));
  CHECK_THAT(error("fix c all clog-detect outlet out timeout 1 still out"), Contains("still"));
  CHECK_THAT(error("fix c all clog-detect outlet out timeout 1 still out 0"), Contains("positive speed"));
  CHECK_THAT(error("fix c all clog-detect outlet out timeout 1 still nowhere 0.1"), Contains("nowhere"));
  CHECK_THAT(error("fix c all clog-detect outlet out timeout 1 arch out final_action yes"),
             Contains("action delete or kick"));
  CHECK_THAT(error("fix c all clog-detect outlet out timeout 1 final_action maybe"),
             Contains("final_action"));
  s.cmd("fix c all clog-detect outlet out timeout 1");  // a valid definition
  CHECK(s.e.modify->find_fix("c") != nullptr);
}
