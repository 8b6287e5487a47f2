// Oblique impact of an alumina sphere on a flat wall (Chung & Ooi 2011, Test 4)
// against the measured data of Kharaz, Gorham & Salman (2001) in
// data/oblique_impact_kharaz2001 of the repository.
//
// Set-up: R = 2.5 mm, rho = 4000 kg/m3, Y = 380 GPa, nu = 0.23; the wall is a
// 1000x stiffer material of the same Poisson ratio; e = 0.98, mu = 0.092;
// |v| = 3.9 m/s at incidence angles from the wall normal, no initial spin.
// Observables after rebound: tangential restitution of the centre vt'/vt, spin
// (sign of the source: negative in the rolling sense), and rebound angle of the
// contact point, atan((vt' - R w')/vn').
#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/input.h"
#include "core/logger.h"
#include "particles/particles.h"
#include "script_engine.h"

namespace {

constexpr double kRadius = 2.5e-3, kSpeed = 3.9;

struct Rebound {
  double et, omega, rebound_deg;
};

Rebound impact(double incidence_deg, const std::string& tangential) {
  granary::Engine e(MPI_COMM_SELF);
  e.logger->set_screen(false);
  const double th = incidence_deg * M_PI / 180.0;
  char vel[128];
  std::snprintf(vel, sizeof vel, "velocity all set %.17g 0.0 %.17g", kSpeed * std::sin(th),
                -kSpeed * std::cos(th));
  const std::vector<std::string> script = {
      "units si",
      "atom_style granular",
      "boundary m m m",
      "newton off",
      "region box block -0.02 0.02 -0.01 0.01 -0.001 0.01 units box",
      "create_box 2 box",
      "neighbor 0.0005 bin",
      "fix m1 all property/global youngsModulus peratomtype 3.8e11 3.8e14",
      "fix m2 all property/global poissonsRatio peratomtype 0.23 0.23",
      "fix m3 all property/global coefficientRestitution peratomtypepair 2 0.98 0.98 0.98 0.98",
      "fix m4 all property/global coefficientFriction peratomtypepair 2 0.092 0.092 0.092 0.092",
      "pair_style gran model hertz tangential " + tangential,
      "pair_coeff * *",
      "timestep 2e-8",
      "create_atoms 1 single 0.0 0.0 0.0025001 units box",
      "set type 1 diameter 0.005 density 4000",
      vel,
      "fix wall all wall/gran model hertz tangential " + tangential + " primitive type 2 zplane 0.0",
      "fix integr all nve/sphere",
      "run 1500",
  };
  granary::test::run(e, script);
  const auto& p = *e.particles;
  REQUIRE(p.nlocal == 1);
  REQUIRE(p.v[0][2] > 0.0);  // it has rebounded
  const double vt0 = kSpeed * std::sin(th);
  Rebound r;
  r.et = vt0 > 0 ? p.v[0][0] / vt0 : 1.0;
  r.omega = -p.omega[0][1];  // positive omega_y is the rolling sense here
  r.rebound_deg = std::atan2(p.v[0][0] - kRadius * p.omega[0][1], p.v[0][2]) * 180.0 / M_PI;
  return r;
}

struct Point {
  double angle, value;
};

std::vector<Point> read_csv(const std::string& name) {
  std::ifstream in(std::string(GRANARY_SOURCE_DIR) + "/data/oblique_impact_kharaz2001/" + name);
  REQUIRE(in.good());
  std::vector<Point> out;
  std::string line;
  bool header = true;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (header) {
      header = false;
      continue;
    }
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream ss(line);
    Point p;
    ss >> p.angle >> p.value;
    out.push_back(p);
  }
  return out;
}

// Mean relative error of one observable. The rebound angle passes through zero,
// so its error is taken relative to the incidence angle, with a floor of 10
// degrees: the measured angles carry about +-1 degree of measurement and
// digitising resolution, which would dominate a 2-degree incidence.
double mean_error(const std::vector<Point>& data, const std::string& tangential, int which,
                  std::string& table) {
  double sum = 0.0;
  for (const auto& d : data) {
    const Rebound r = impact(d.angle, tangential);
    const double model = which == 0 ? r.et : which == 1 ? r.omega : r.rebound_deg;
    const double scale = which == 2 ? std::max(d.angle, 10.0) : std::fabs(d.value);
    sum += std::fabs(model - d.value) / scale;
    char buf[160];
    std::snprintf(buf, sizeof buf, "  %6.2f  measured %10.4g  model %10.4g\n", d.angle, d.value, model);
    table += buf;
  }
  return sum / data.size();
}

}  // namespace

TEST_CASE("oblique impact agrees with Kharaz et al. (2001) with tangential history") {
  const char* files[3] = {"tangential_restitution.csv", "angular_velocity.csv", "rebound_angle.csv"};
  double err_history[3], err_coulomb[3];
  std::string report = "Oblique impact (Chung & Ooi Test 4) against Kharaz et al. (2001)\n";
  for (int k = 0; k < 3; ++k) {
    const auto data = read_csv(files[k]);
    REQUIRE(data.size() >= 8);
    std::string t_hist, t_coul;
    err_history[k] = mean_error(data, "history", k, t_hist);
    err_coulomb[k] = mean_error(data, "no_history", k, t_coul);
    char buf[200];
    std::snprintf(buf, sizeof buf, "%s: mean relative error, history %.1f%%, Coulomb-only %.1f%%\n", files[k],
                  100 * err_history[k], 100 * err_coulomb[k]);
    report += buf + std::string(" tangential history:\n") + t_hist + " Coulomb only:\n" + t_coul;
  }
  const double mean_history = (err_history[0] + err_history[1] + err_history[2]) / 3.0;
  const double mean_coulomb = (err_coulomb[0] + err_coulomb[1] + err_coulomb[2]) / 3.0;
  char buf[200];
  std::snprintf(buf, sizeof buf, "overall: history %.1f%%, Coulomb-only %.1f%%\n", 100 * mean_history,
                100 * mean_coulomb);
  report += buf;
  std::ofstream("oblique_impact_report.txt") << report;
  std::printf("%s", report.c_str());
  INFO(report);
  CHECK(mean_history < 0.10);
  // Coulomb-only sliding misses the tangential compliance: it must do worse.
  CHECK(mean_coulomb > mean_history);
}

TEST_CASE(
    "oblique impact: partial slip (mindlin_deresiewicz) loses tangential energy where the contact sticks") {
  // Below about 5 degrees the contact sticks for the whole impact: tangential
  // history's elastic spring returns its energy (et = 0.986, measured 0.80 and
  // 0.75 at 2.2 and 4.2 degrees); Mindlin-Deresiewicz micro-slip dissipates
  // part of it (measured here: et = 0.933 and 0.858). So the model must come
  // closer to the data at both angles, and reduce the distance by at least a
  // third at 4.2 degrees; above 30 degrees, where the contact slides through
  // most of the impact, both models agree within 0.01.
  const auto data = read_csv("tangential_restitution.csv");
  int sticking = 0;
  for (const auto& d : data) {
    const Rebound h = impact(d.angle, "history");
    const Rebound m = impact(d.angle, "mindlin_deresiewicz");
    INFO("incidence " << d.angle << ": measured " << d.value << ", history " << h.et << ", partial slip "
                      << m.et);
    if (d.angle < 5.0) {
      ++sticking;
      CHECK(std::fabs(m.et - d.value) < std::fabs(h.et - d.value));
      CHECK(m.et < h.et - 0.03);
      if (d.angle > 4.0) CHECK(std::fabs(m.et - d.value) < (2.0 / 3.0) * std::fabs(h.et - d.value));
    }
    if (d.angle > 30.0) CHECK(m.et == Approx(h.et).margin(0.01));
  }
  CHECK(sticking == 2);
}
