// Mass properties of sphere clumps (src/geometry/mass_properties.cpp) and the
// particle template built on them (fix particletemplate/multisphere).
//
// References: a single sphere and a dumbbell of two separate spheres are
// known in closed form; for two overlapping spheres the volume is checked
// against the analytic lens formula and all moments against a 1D quadrature of
// the solid of revolution (exact to ~1e-12). The tolerance of each check is
// 5 standard errors of the integration as reported by the estimate itself,
// and the reported relative error must be small (< 1e-4 with 1e6 samples).
#include <mpi.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "core/engine.h"
#include "core/error.h"
#include "core/input.h"
#include "core/logger.h"
#include "fix/fix_particletemplate_multisphere.h"
#include "geometry/mass_properties.h"
#include "core/modify.h"

using granary::MassProperties;
using granary::sphere_union_properties;
using granary::Vec3;

namespace {

constexpr long long kTry = 1000000;

double sphere_volume(double r) {
  return 4.0 / 3.0 * M_PI * r * r * r;
}

/// Union of two spheres on the x axis (r1 at 0, r2 at d) as a solid of
/// revolution: volume, centroid x, axial moment and transverse moment about
/// the centroid (unit density), by composite Simpson quadrature split at the
/// kink of the profile.
struct Revolution {
  double volume, xc, ixx, iyy;
};
Revolution revolution(double r1, double r2, double d) {
  auto rho2 = [&](double x) {
    const double a = r1 * r1 - x * x, b = r2 * r2 - (x - d) * (x - d);
    return std::max({a, b, 0.0});
  };
  const double lo = -r1, hi = d + r2;
  const double kink = (d * d + r1 * r1 - r2 * r2) / (2.0 * d);
  auto simpson = [&](auto f, double a, double b) {
    const int n = 200000;
    const double h = (b - a) / n;
    double s = f(a) + f(b);
    for (int k = 1; k < n; ++k)
      s += f(a + k * h) * (k % 2 ? 4.0 : 2.0);
    return s * h / 3.0;
  };
  auto both = [&](auto f) { return simpson(f, lo, kink) + simpson(f, kink, hi); };
  Revolution out;
  out.volume = both([&](double x) { return M_PI * rho2(x); });
  out.xc = both([&](double x) { return M_PI * rho2(x) * x; }) / out.volume;
  out.ixx = both([&](double x) { return 0.5 * M_PI * rho2(x) * rho2(x); });
  out.iyy = both([&](double x) {
    return 0.25 * M_PI * rho2(x) * rho2(x) + M_PI * rho2(x) * (x - out.xc) * (x - out.xc);
  });
  return out;
}

/// Check |value - exact| <= 5 sigma (sigma: reported standard error).
void check_within(double value, double exact, double sigma, const char* what) {
  INFO(what << ": " << value << " vs " << exact << " (sigma " << sigma << ")");
  CHECK(std::fabs(value - exact) <= 5.0 * sigma);
}

}  // namespace

TEST_CASE("mass properties: one sphere", "[multisphere]") {
  const double r = 1e-3;
  const MassProperties m = sphere_union_properties({Vec3(0.1, -0.2, 0.3)}, {r}, kTry, 15485863);
  const double v = sphere_volume(r);
  CHECK(m.relative_volume_error() < 1e-4);
  check_within(m.volume, v, m.volume_error, "volume");
  // centroid: the sphere's centre, within (error of the first moment) ~ sigma_V / V * r
  CHECK((m.centre - Vec3(0.1, -0.2, 0.3)).norm() < 5.0 * m.relative_volume_error() * r + 1e-12);
  // I = 2/5 V r^2 about every axis (unit density); trace error reported
  const double i0 = 0.4 * v * r * r;
  for (int d = 0; d < 3; ++d)
    check_within(m.inertia(d, d), i0, m.inertia_error, "moment");
  CHECK(std::fabs(m.inertia(0, 1)) < 5.0 * m.inertia_error);
}

TEST_CASE("mass properties: dumbbell of two separate spheres", "[multisphere]") {
  // spheres of radius r at +-a along (1, 1, 0)/sqrt 2: V = 2 V1, centre 0,
  // axial moment 2 * 2/5 V1 r^2, transverse moments 2 (2/5 V1 r^2 + V1 a^2)
  const double r = 1.0, a = 2.0;
  const Vec3 u = Vec3(1, 1, 0).normalized();
  const MassProperties m = sphere_union_properties({a * u, -a * u}, {r, r}, kTry, 32452843);
  const double v1 = sphere_volume(r);
  check_within(m.volume, 2 * v1, m.volume_error, "volume");
  CHECK(m.centre.norm() < 1e-4);
  check_within(m.principal[0], 2 * 0.4 * v1 * r * r, m.inertia_error, "axial moment");
  check_within(m.principal[1], 2 * (0.4 * v1 * r * r + v1 * a * a), m.inertia_error, "transverse moment 1");
  check_within(m.principal[2], 2 * (0.4 * v1 * r * r + v1 * a * a), m.inertia_error, "transverse moment 2");
  // the smallest moment belongs to the line of centres
  CHECK(std::fabs(m.axes.col(0).dot(u)) == Approx(1.0).epsilon(1e-6));
  CHECK(m.axes.determinant() == Approx(1.0).epsilon(1e-12));
}

TEST_CASE("mass properties: two overlapping spheres (lens)", "[multisphere]") {
  const double r1 = 1.0, r2 = 0.8, d = 1.2;
  const MassProperties m = sphere_union_properties({Vec3(0, 0, 0), Vec3(d, 0, 0)}, {r1, r2}, kTry, 86028121);
  // analytic lens (intersection) volume
  const double lens = M_PI * std::pow(r1 + r2 - d, 2) *
                      (d * d + 2 * d * r2 - 3 * r2 * r2 + 2 * d * r1 + 6 * r1 * r2 - 3 * r1 * r1) / (12 * d);
  const double v = sphere_volume(r1) + sphere_volume(r2) - lens;
  const Revolution ref = revolution(r1, r2, d);
  REQUIRE(ref.volume == Approx(v).epsilon(1e-10));  // the quadrature reproduces the lens formula
  CHECK(m.relative_volume_error() < 1e-4);
  check_within(m.volume, v, m.volume_error, "union volume");
  CHECK(m.centre[0] == Approx(ref.xc).margin(5.0 * m.relative_volume_error() * (r1 + r2 + d)));
  CHECK(std::fabs(m.centre[1]) < 1e-4);
  check_within(m.inertia(0, 0), ref.ixx, m.inertia_error, "axial moment");
  check_within(m.inertia(1, 1), ref.iyy, m.inertia_error, "transverse moment");
  check_within(m.inertia(2, 2), ref.iyy, m.inertia_error, "transverse moment");
  // the stated error bound holds and the estimate is deterministic
  CHECK(std::fabs(m.volume - v) <= m.volume_bound);
  const MassProperties again =
      sphere_union_properties({Vec3(0, 0, 0), Vec3(d, 0, 0)}, {r1, r2}, kTry, 86028121);
  CHECK(again.volume == m.volume);
}

TEST_CASE("particletemplate/multisphere: principal frame, mass and file input", "[multisphere]") {
  granary::Engine e(MPI_COMM_WORLD);
  e.logger->set_screen(false);
  for (const char* line : {"units si", "atom_style granular", "boundary f f f",
                           "region box block -1 1 -1 1 -1 1", "create_box 2 box"})
    e.input->one(line);
  // a dumbbell along y, inline form: the long axis becomes body axis x
  e.input->one(
      "fix t1 all particletemplate/multisphere 15485863 atom_type 2 density constant 2500 nspheres 2 "
      "ntry 1000000 spheres 0 0.001 0 0.001 0 -0.001 0 0.001 type 1");
  auto* t1 = dynamic_cast<granary::FixParticleTemplateMultisphere*>(e.modify->find_fix("t1"));
  REQUIRE(t1);
  const auto p = t1->draw();
  CHECK(p.multisphere);
  CHECK(p.type == 2);
  REQUIRE(p.offsets.size() == 2);
  const double v1 = sphere_volume(0.001);
  // the spheres touch at one point: V = 2 V1, m = rho V
  CHECK(p.volume == Approx(2 * v1).epsilon(5 * t1->properties().relative_volume_error() + 1e-12));
  CHECK(p.mass == Approx(2500 * p.volume).epsilon(1e-12));
  // the centre of mass carries the integration error: |dc| ~ (sigma_V / V) * size
  const double tol = 5 * t1->properties().relative_volume_error() * 0.004;
  INFO("centre tolerance " << tol << " m");
  CHECK(std::fabs(p.offsets[0][0]) == Approx(0.001).margin(tol));  // along body x
  CHECK(std::fabs(p.offsets[0][1]) < tol);
  CHECK((p.offsets[0] + p.offsets[1]).norm() < tol);  // centred
  CHECK(p.inertia[0] <= p.inertia[1]);
  CHECK(p.inertia[1] <= p.inertia[2]);
  CHECK(p.bounding_radius == Approx(0.002).margin(tol));

  // file form with comments and scale; nspheres must match the file
  const std::string path = "test_multisphere_mass_spheres.txt";
  if (e.rank == 0) {
    std::ofstream f(path);
    f << "# x y z r\n0 0 0 1.0\n\n1.5 0 0 0.5  # second sphere\n";
  }
  MPI_Barrier(MPI_COMM_WORLD);
  e.input->one(
      "fix t2 all particletemplate/multisphere 15485867 atom_type 1 density constant 1000 nspheres 2 "
      "ntry 100000 spheres file " +
      path + " scale 0.001 type 1");
  auto* t2 = dynamic_cast<granary::FixParticleTemplateMultisphere*>(e.modify->find_fix("t2"));
  REQUIRE(t2);
  CHECK(t2->draw().radii[1] == Approx(0.0005));
  // the spheres touch at x = 1 mm: the volume is the sum of the two
  CHECK(t2->draw().volume == Approx(sphere_volume(0.001) + sphere_volume(0.0005)).epsilon(1e-3));
  CHECK_THROWS_AS(
      e.input->one("fix t3 all particletemplate/multisphere 15485867 atom_type 1 density constant 1000 "
                   "nspheres 3 ntry 100000 spheres file " +
                   path + " type 1"),
      granary::InputError);
  CHECK_THROWS_AS(e.input->one("fix t4 all particletemplate/multisphere 15485867 atom_type 1 nspheres 1 "
                               "spheres 0 0 0 -1 type 1"),
                  granary::InputError);
  // a sphere file with a NaN, an infinity or a line of 3 numbers: an error naming the file and line
  const std::string bad = "test_multisphere_mass_bad.txt";
  const std::pair<const char*, const char*> cases[] = {
      {"0 0 0 1.0\nnan 0 0 0.5\n", "line 2: 'nan' is not a finite number"},
      {"0 0 0 1.0\n1.5 0 0 inf\n", "line 2: 'inf' is not a finite number"},
      {"# a sphere\n0 0 0\n1.0 1.5 0 0 0.5\n", "line 2: holds 3 numbers; each line holds one sphere"}};
  for (const auto& c : cases) {
    if (e.rank == 0) {
      std::ofstream f(bad);
      f << c.first;
    }
    MPI_Barrier(MPI_COMM_WORLD);
    CHECK_THROWS_WITH(e.input->one("fix t5 all particletemplate/multisphere 15485867 atom_type 1 "
                                   "ntry 100000 spheres file " +
                                   bad + " type 1"),
                      Catch::Contains("sphere file '" + bad + "' " + c.second));
    MPI_Barrier(MPI_COMM_WORLD);
  }
  CHECK_THROWS_WITH(e.input->one("fix t6 all particletemplate/multisphere 15485867 atom_type 1 nspheres 1 "
                                 "spheres 0 nan 0 1 type 1"),
                    Catch::Contains("'nan'"));
  MPI_Barrier(MPI_COMM_WORLD);
  if (e.rank == 0) {
    std::remove(path.c_str());
    std::remove(bad.c_str());
  }
}

TEST_CASE("potentials: the cylinder clumps have the volumes their headers state", "[multisphere]") {
  // tools/make_clump.py writes each clump's volume from a 60^3 sample grid
  // (about 0.5% uncertainty); the template's integration must agree to 1%.
  granary::Engine e(MPI_COMM_WORLD);
  e.logger->set_screen(false);
  for (const char* line : {"units si", "atom_style granular", "boundary f f f",
                           "region box block -1 1 -1 1 -1 1", "create_box 1 box"})
    e.input->one(line);
  for (int n : {10, 20, 50, 100}) {
    const std::string path =
        std::string(GRANARY_SOURCE_DIR) + "/potentials/cylinder_ellipse_" + std::to_string(n) + ".clump";
    std::ifstream in(path);
    REQUIRE(in.good());
    double stated = -1.0;
    std::string line;
    while (std::getline(in, line)) {
      const auto at = line.find("this clump: volume ");
      if (at != std::string::npos) std::istringstream(line.substr(at + 19)) >> stated;
    }
    REQUIRE(stated > 0.0);
    e.input->one("fix c" + std::to_string(n) +
                 " all particletemplate/multisphere 15485863 atom_type 1 density constant 1190 "
                 "nspheres " +
                 std::to_string(n) + " ntry 200000 spheres file " + path + " type 1");
    auto* t =
        dynamic_cast<granary::FixParticleTemplateMultisphere*>(e.modify->find_fix("c" + std::to_string(n)));
    REQUIRE(t);
    INFO(n << " spheres: header " << stated << " mm^3, integrated " << t->draw().volume * 1e9 << " mm^3");
    CHECK(t->draw().volume * 1e9 == Approx(stated).epsilon(0.01));
    // the cylinder axis (x in the file) has the smallest moment of inertia
    CHECK(std::fabs(t->axes().col(0)[0]) == Approx(1.0).epsilon(1e-3));
  }
}
