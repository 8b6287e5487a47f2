// Agreement with LIGGGHTS 3.8 on scripts that both programs run unchanged.
//
// The LIGGGHTS thermo output of each script is stored in unittest/reference
// (made by unittest/reference/make_reference.py). When LIGGGHTS is installed,
// one test also re-runs it and checks the stored output is still what it
// prints, so the reference cannot drift silently.
//
// Tolerances:
// - particle counts are equal at every output step;
// - before the first contact (free fall from a lattice) kinetic energies agree
//   to 1e-6 relative: both integrate gravity with velocity Verlet;
// - a single sphere bouncing and rolling on a wall (in.wall_bounce) is
//   deterministic: kinetic energy within 2% at every output step; two and
//   three colliding spheres (in.two_spheres, in.three_spheres) and two bcc
//   layers landing on each other (in.bcc_layers) agree to the 8 digits
//   LIGGGHTS prints (1e-6 relative);
// - pours are chaotic after the first impacts (round-off grows), so they are
//   compared statistically: kinetic energy just after the first impact within
//   5%, the mean kinetic energy over the flowing phase within 25%, and the
//   step at which the bed comes to rest (KE < 1e-7 J) within 30%.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/input.h"
#include "core/logger.h"
#include "skip.h"

namespace {

struct Row {
  double step, atoms, ke, rke;
};

std::vector<Row> read_reference(const std::string& name) {
  std::ifstream in(std::string(GRANARY_SOURCE_DIR) + "/unittest/reference/" + name + ".liggghts.csv");
  REQUIRE(in.good());
  std::vector<Row> rows;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line[0] == 's') continue;
    for (char& c : line)
      if (c == ',') c = ' ';
    std::istringstream ss(line);
    Row r;
    ss >> r.step >> r.atoms >> r.ke >> r.rke;
    rows.push_back(r);
  }
  return rows;
}

// Thermo rows "step atoms ke rke" of a LAMMPS-style log (Granary's or LIGGGHTS').
std::vector<Row> read_log(const std::string& path) {
  std::ifstream in(path);
  std::vector<Row> rows;
  std::string line;
  bool table = false;
  while (std::getline(in, line)) {
    std::istringstream ss(line);
    std::string first;
    ss >> first;
    if (first == "Step") {
      table = true;
      continue;
    }
    if (!table) continue;
    if (line.rfind("Loop time", 0) == 0) {
      table = false;
      continue;
    }
    std::istringstream row(line);
    Row r;
    if (row >> r.step >> r.atoms >> r.ke >> r.rke) rows.push_back(r);
  }
  return rows;
}

std::vector<Row> run_granary(const std::string& name) {
  const std::string log = "agreement_" + name + ".log";
  {
    granary::Engine e(MPI_COMM_SELF);
    e.logger->set_screen(false);
    e.logger->open_log(log, false);
    e.input->file(std::string(GRANARY_SOURCE_DIR) + "/unittest/scripts/in." + name);
  }
  return read_log(log);
}

double first_rest_step(const std::vector<Row>& rows, double after) {
  for (const auto& r : rows)
    if (r.step > after && r.ke < 1e-7) return r.step;
  return rows.back().step;
}

void compare_pour(const std::string& name) {
  const auto ref = read_reference(name);
  const auto run = run_granary(name);
  REQUIRE(run.size() == ref.size());
  double mean_ref = 0, mean_run = 0;
  int n = 0, first_impact = -1;
  for (std::size_t k = 0; k < ref.size(); ++k) {
    INFO("step " << ref[k].step);
    REQUIRE(run[k].step == ref[k].step);
    CHECK(run[k].atoms == ref[k].atoms);
    if (first_impact < 0 && ref[k].rke == 0.0) {
      CHECK(run[k].ke == Approx(ref[k].ke).epsilon(1e-6));  // free fall
      CHECK(run[k].rke == 0.0);
      continue;
    }
    if (first_impact < 0) {
      first_impact = static_cast<int>(k);
      CHECK(run[k].ke == Approx(ref[k].ke).epsilon(0.05));
    }
    if (ref[k].ke > 1e-6) {  // flowing phase
      mean_ref += ref[k].ke;
      mean_run += run[k].ke;
      ++n;
    }
  }
  REQUIRE(first_impact > 0);
  REQUIRE(n > 3);
  CHECK(mean_run / n == Approx(mean_ref / n).epsilon(0.25));
  const double rest_ref = first_rest_step(ref, ref[first_impact].step);
  const double rest_run = first_rest_step(run, ref[first_impact].step);
  CHECK(rest_run == Approx(rest_ref).epsilon(0.30));
  std::printf(
      "%s: mean KE of the flowing phase %.4g J (LIGGGHTS %.4g J); at rest from step %.0f (LIGGGHTS %.0f)\n",
      name.c_str(), mean_run / n, mean_ref / n, rest_run, rest_ref);
}

}  // namespace

TEST_CASE("a sphere bouncing and rolling on a wall matches LIGGGHTS") {
  const auto ref = read_reference("wall_bounce");
  const auto run = run_granary("wall_bounce");
  REQUIRE(run.size() == ref.size());
  double worst = 0;
  for (std::size_t k = 0; k < ref.size(); ++k) {
    REQUIRE(run[k].step == ref[k].step);
    REQUIRE(run[k].atoms == 1);
    const double total_ref = ref[k].ke + ref[k].rke, total_run = run[k].ke + run[k].rke;
    worst = std::max(worst, std::fabs(total_run - total_ref) / total_ref);
    INFO("step " << ref[k].step);
    CHECK(total_run == Approx(total_ref).epsilon(0.02));
  }
  std::printf("wall_bounce: largest relative difference of kinetic energy %.3g\n", worst);
}

// Few-particle collisions are deterministic: the same numbers to the digits
// LIGGGHTS prints (8 significant), so 1e-6 relative.
void compare_exact(const std::string& name) {
  const auto ref = read_reference(name);
  const auto run = run_granary(name);
  REQUIRE(run.size() == ref.size());
  for (std::size_t k = 0; k < ref.size(); ++k) {
    INFO(name << " step " << ref[k].step);
    REQUIRE(run[k].step == ref[k].step);
    CHECK(run[k].atoms == ref[k].atoms);
    CHECK(run[k].ke == Approx(ref[k].ke).epsilon(1e-6).margin(1e-20));
    CHECK(run[k].rke == Approx(ref[k].rke).epsilon(1e-6).margin(1e-20));
  }
}

TEST_CASE("two spheres colliding on a floor match LIGGGHTS to the printed digits") {
  compare_exact("two_spheres");
}

TEST_CASE("three spheres, one touched by two, match LIGGGHTS to the printed digits") {
  compare_exact("three_spheres");
}

// Nine spheres bounce into sixteen: each lower sphere is hit by four at the same
// step, its tangential torques cancel to round-off, and CDT rolling friction
// acts on the round-off. Deterministic, but only the LIGGGHTS order of
// floating-point evaluation in the contact kinematics gives its numbers.
TEST_CASE("two bcc layers landing on each other match LIGGGHTS to the printed digits") {
  compare_exact("bcc_layers");
}

// fix nve: translation only; the contacts' torques turn nothing (rke 0 in both)
TEST_CASE("two spheres colliding on a floor under fix nve match LIGGGHTS to the printed digits", "[nve]") {
  compare_exact("nve_two_spheres");
}

TEST_CASE("a pour into a box matches LIGGGHTS") {
  compare_pour("pour_small");
}

TEST_CASE("a pour into a cylinder matches LIGGGHTS") {
  compare_pour("cylinder_small");
}

TEST_CASE("a sphere rolling off another with rolling_friction epsd3 matches LIGGGHTS to the printed digits",
          "[rolling]") {
  compare_exact("rolling_epsd3_pair");
}

TEST_CASE("three pairs colliding with model hooke/hysteresis match LIGGGHTS to the printed digits",
          "[hysteresis]") {
  compare_exact("hysteresis_pairs");
}

// A new contact starts with no rolling spring: a sphere that bounces off
// another and lands again. With a 2 um skin the pair leaves LIGGGHTS' list
// while apart and LIGGGHTS agrees to every printed digit; Granary gives the
// same numbers with a 0.5 mm skin (LIGGGHTS 3.8 does not: it keeps the
// spring of a listed pair that separated, 2 % apart after the second landing).
TEST_CASE("a sphere bouncing on another with epsd3: a new contact starts without a rolling spring",
          "[rolling]") {
  compare_exact("rolling_epsd3_bounce");
  const std::string log = "agreement_rolling_epsd3_bounce_wide.log";
  {
    granary::Engine e(MPI_COMM_SELF);
    e.logger->set_screen(false);
    e.logger->open_log(log, false);
    e.input->one("variable skin index 0.0005");
    e.input->file(std::string(GRANARY_SOURCE_DIR) + "/unittest/scripts/in.rolling_epsd3_bounce");
  }
  const auto wide = read_log(log);
  const auto ref = read_reference("rolling_epsd3_bounce");
  REQUIRE(wide.size() == ref.size());
  for (std::size_t k = 0; k < ref.size(); ++k) {
    CHECK(wide[k].ke == Approx(ref[k].ke).epsilon(1e-6).margin(1e-20));
    CHECK(wide[k].rke == Approx(ref[k].rke).epsilon(1e-6).margin(1e-20));
  }
}

// At a wall LIGGGHTS 3.8's epsd spring and dashpot torques are 0.50 % above
// its documented formula with R* = r (measured for one sphere of r = 1 mm at
// an overlap of 1e-5 m; between two spheres they agree to every printed
// digit, rolling_epsd3_pair); the sphere rolling to rest agrees to 0.055 %
// (measured), checked to 0.1 %.
TEST_CASE("a sphere rolling to rest on a wall with rolling_friction epsd matches LIGGGHTS", "[rolling]") {
  const auto ref = read_reference("rolling_epsd_wall");
  const auto run = run_granary("rolling_epsd_wall");
  REQUIRE(run.size() == ref.size());
  REQUIRE(ref.size() == 101);
  for (std::size_t k = 0; k < ref.size(); ++k) {
    REQUIRE(run[k].step == ref[k].step);
    INFO("step " << ref[k].step);
    CHECK(run[k].ke + run[k].rke == Approx(ref[k].ke + ref[k].rke).epsilon(1e-3));
  }
  // it slows to rest: the last kinetic energy is 1e-4 of the first
  CHECK(run.back().ke + run.back().rke < 2e-4 * run.front().ke);
}

// Every numeric thermo column of a LIGGGHTS reference table and of a Granary log.
std::vector<std::vector<double>> all_columns(const std::string& path, bool csv) {
  std::ifstream in(path);
  std::vector<std::vector<double>> rows;
  std::string line;
  bool table = csv;
  while (std::getline(in, line)) {
    if (csv) {
      if (line.empty() || line[0] == '#' || line[0] == 's') continue;
      for (char& c : line)
        if (c == ',') c = ' ';
    } else {
      std::istringstream ss(line);
      std::string first;
      ss >> first;
      if (first == "Step") {
        table = true;
        continue;
      }
      if (line.rfind("Loop time", 0) == 0) table = false;
      if (!table) continue;
    }
    std::istringstream row(line);
    std::vector<double> values;
    double v;
    while (row >> v)
      values.push_back(v);
    if (!values.empty() && (rows.empty() || values[0] != rows.back()[0])) rows.push_back(values);
  }
  return rows;
}

// fix spring tether and couple (NULL directions, a rest length): the
// springs' energies and forces (f_ID, f_ID[i]) and the kinetic energy to the
// digits LIGGGHTS prints.
// Every thermo column of script `name` against LIGGGHTS' table: `rows` rows
// of `cols` columns, each within the relative `eps`.
void compare_all_columns(const std::string& name, std::size_t rows, std::size_t cols, double eps) {
  run_granary(name);
  const auto ref =
      all_columns(std::string(GRANARY_SOURCE_DIR) + "/unittest/reference/" + name + ".liggghts.csv", true);
  const auto run = all_columns("agreement_" + name + ".log", false);
  REQUIRE(ref.size() == rows);
  REQUIRE(run.size() == ref.size());
  for (std::size_t k = 0; k < ref.size(); ++k) {
    REQUIRE(run[k].size() == cols);
    REQUIRE(ref[k].size() == cols);
    for (std::size_t c = 0; c < cols; ++c) {
      INFO(name << " step " << ref[k][0] << " column " << c);
      CHECK(run[k][c] == Approx(ref[k][c]).epsilon(eps).margin(1e-20));
    }
  }
}

TEST_CASE("fix spring tether and couple match LIGGGHTS to the printed digits", "[spring]") {
  compare_all_columns("spring", 101, 11, 1e-6);
}

// fix drag (a NULL direction, particles within delta left alone): the total
// drag forces (f_ID[1..3]) and the kinetic energy, printed with 15 digits.
TEST_CASE("fix drag matches LIGGGHTS to 12 digits", "[drag]") {
  compare_all_columns("drag", 21, 9, 1e-12);
}

TEST_CASE("the stored LIGGGHTS output is what LIGGGHTS prints") {
  if (std::system("command -v liggghts > /dev/null 2>&1") != 0) {
    granary::test::skip(
        "LIGGGHTS is not installed (package liggghts): the stored reference output cannot be checked");
    return;
  }
  const std::string cmd = "liggghts -in " + std::string(GRANARY_SOURCE_DIR) +
                          "/unittest/scripts/in.wall_bounce -log live_wall_bounce.log -screen none";
  REQUIRE(std::system(cmd.c_str()) == 0);
  const auto live = read_log("live_wall_bounce.log");
  const auto ref = read_reference("wall_bounce");
  REQUIRE(live.size() == ref.size());
  for (std::size_t k = 0; k < ref.size(); ++k) {
    CHECK(live[k].ke == Approx(ref[k].ke).epsilon(1e-6));
    CHECK(live[k].rke == Approx(ref[k].rke).margin(1e-15).epsilon(1e-6));
  }
}
