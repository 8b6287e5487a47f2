// sphere_box_volume against closed forms, identities and Monte Carlo, and
// compute region-phi on sphere lattices and on a 50-sphere clump.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "geometry/sphere_box_volume.h"
#include "core/engine.h"
#include "core/error.h"
#include "fix/fix_multisphere.h"
#include "core/modify.h"
#include "script_engine.h"

using granary::sphere_box_volume;
using granary::Vec3;

namespace {

constexpr double kBig = 1e3;
double sphere_vol(double r) {
  return 4.0 / 3.0 * M_PI * r * r * r;
}
double cap(double r, double h) {
  return M_PI * h * h * (3 * r - h) / 3.0;
}

bool in_box(const Vec3& p, const Vec3& lo, const Vec3& hi) {
  return (p.array() >= lo.array()).all() && (p.array() <= hi.array()).all();
}

/// Simple cubic lattice of spheres (radius 0.5, spacing 1) at integer points
/// 0..5, type 1 or 2 by the parity of i + j + k.
std::vector<std::string> lattice_script(const std::string& boundary = "f f f", double shift = 0.0) {
  std::vector<std::string> s = {"units si", "atom_style granular", "boundary " + boundary,
                                "region box block -0.5 5.5 -0.5 5.5 -0.5 5.5", "create_box 2 box"};
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j)
      for (int k = 0; k < 6; ++k) {
        char line[160];
        const double x = i + shift >= 5.5 ? i + shift - 6.0 : i + shift;  // wrapped into the box
        std::snprintf(line, sizeof line, "create_atoms %d single %.17g %.17g %d", 1 + (i + j + k) % 2, x,
                      j + shift >= 5.5 ? j + shift - 6.0 : j + shift, k);
        s.push_back(line);
      }
  s.push_back("set group all diameter 1.0 density 1000");
  return s;
}

/// Monte Carlo solid fraction of the lattice of lattice_script in [lo, hi].
double lattice_mc(const Vec3& lo, const Vec3& hi, long n, std::uint64_t seed) {
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  long in = 0;
  for (long s = 0; s < n; ++s) {
    Vec3 p;
    for (int d = 0; d < 3; ++d)
      p[d] = lo[d] + (hi[d] - lo[d]) * u(g);
    Vec3 q = p - p.array().round().matrix();
    if (q.squaredNorm() <= 0.25) ++in;
  }
  return static_cast<double>(in) / n;
}

std::vector<std::string> clump_script(const std::string& box = "-0.01 0.01 -0.01 0.01 -0.01 0.01") {
  return {"units si",
          "atom_style granular",
          "boundary f f f",
          "region box block " + box,
          "create_box 2 box",
          std::string("fix cyl all particletemplate/multisphere 15485863 atom_type 1 density constant 1190 "
                      "nspheres 50 ntry 1000000 spheres file ") +
              GRANARY_SOURCE_DIR + "/potentials/cylinder_ellipse_50.clump scale 1.0 type 1",
          "fix integr all multisphere"};
}

/// Monte Carlo volume of the union of body 0's spheres inside [lo, hi].
double clump_mc(const granary::Bodies& B, const Vec3& lo, const Vec3& hi, long n) {
  const Eigen::Matrix3d rot = B.rotation(0);
  std::vector<Vec3> c;
  std::vector<double> r;
  Vec3 a = Vec3::Constant(1e9), b = Vec3::Constant(-1e9);
  for (int s = B.sphere_start[0]; s < B.sphere_start[1]; ++s) {
    c.push_back(B.xcm[0] + rot * B.offsets[s]);
    r.push_back(B.radii[s]);
    a = a.cwiseMin(c.back() - Vec3::Constant(r.back()));
    b = b.cwiseMax(c.back() + Vec3::Constant(r.back()));
  }
  std::mt19937_64 g(2718281);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  long in = 0;
  for (long s = 0; s < n; ++s) {
    Vec3 p;
    for (int d = 0; d < 3; ++d)
      p[d] = a[d] + (b[d] - a[d]) * u(g);
    if (!in_box(p, lo, hi)) continue;
    for (std::size_t k = 0; k < c.size(); ++k)
      if ((p - c[k]).squaredNorm() <= r[k] * r[k]) {
        ++in;
        break;
      }
  }
  return (b - a).prod() * static_cast<double>(in) / n;
}

}  // namespace

TEST_CASE("sphere_box_volume: closed forms", "[region_phi]") {
  const double r = 1.3;
  const Vec3 c(0.2, -0.1, 0.4);
  const double v = sphere_vol(r);
  const Vec3 L = Vec3::Constant(-kBig), H = Vec3::Constant(kBig);
  CHECK(sphere_box_volume(c, r, L, H) == Approx(v).epsilon(1e-12));
  CHECK(sphere_box_volume(c, r, Vec3(5, 5, 5), H) == 0.0);
  // half, quarter (edge through the centre), eighth (corner at the centre), every axis
  for (int d = 0; d < 3; ++d) {
    Vec3 lo = L;
    lo[d] = c[d];
    CHECK(sphere_box_volume(c, r, lo, H) == Approx(v / 2).epsilon(1e-12));
    Vec3 lo2 = lo;
    lo2[(d + 1) % 3] = c[(d + 1) % 3];
    CHECK(sphere_box_volume(c, r, lo2, H) == Approx(v / 4).epsilon(1e-12));
    Vec3 hi2 = H;
    hi2[d] = c[d];
    hi2[(d + 2) % 3] = c[(d + 2) % 3];
    CHECK(sphere_box_volume(c, r, L, hi2) == Approx(v / 4).epsilon(1e-12));
  }
  for (int o = 0; o < 8; ++o) {
    Vec3 lo = L, hi = H;
    for (int d = 0; d < 3; ++d)
      ((o >> d) & 1 ? lo[d] : hi[d]) = c[d];
    CHECK(sphere_box_volume(c, r, lo, hi) == Approx(v / 8).epsilon(1e-12));
  }
  // caps at various depths, by one face and (through the quadrature) as the
  // sum of the two halves of the cap split by a plane through the centre
  for (double h : {1e-6, 0.01, 0.3, 1.0, 1.3, 2.0, 2.59, 2.6}) {
    for (int d = 0; d < 3; ++d) {
      Vec3 lo = L;
      lo[d] = c[d] + r - h;
      CHECK(sphere_box_volume(c, r, lo, H) == Approx(cap(r, h)).epsilon(1e-12).margin(1e-15 * v));
      Vec3 lo_a = lo, hi_b = H;
      const int e = (d + 1) % 3;
      lo_a[e] = c[e] + 0.37;
      hi_b[e] = c[e] + 0.37;
      const double split = sphere_box_volume(c, r, lo_a, H) + sphere_box_volume(c, r, lo, hi_b);
      CHECK(std::fabs(split - cap(r, h)) <= 1e-12 * v);
    }
  }
  // a slab cut by two parallel faces
  CHECK(sphere_box_volume(c, r, Vec3(-kBig, -kBig, c[2] - 0.5), Vec3(kBig, kBig, c[2] + 0.7)) ==
        Approx(v - cap(r, r - 0.5) - cap(r, r - 0.7)).epsilon(1e-12));
  // a box inside a much larger sphere: the box volume
  CHECK(sphere_box_volume(c, 100.0, Vec3(0, 0, 0), Vec3(1, 2, 3)) == Approx(6.0).epsilon(1e-12));
  // a box larger than the sphere in two directions, thinner in the third and partly in the sphere
  CHECK(sphere_box_volume(Vec3(0, 0, 0), 1.0, Vec3(-0.1, -0.2, -5), Vec3(0.1, 0.2, 5)) ==
        Approx(0.2 * 0.4 * 2.0).epsilon(0.05));  // sanity: close to the prism through the sphere
}

TEST_CASE("sphere_box_volume: octant identity and Monte Carlo", "[region_phi]") {
  std::mt19937_64 g(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  // the eight boxes around any point partition the sphere
  double worst = 0.0;
  for (int t = 0; t < 3000; ++t) {
    const double r = 0.5 + std::fabs(u(g));
    const Vec3 c(u(g), u(g), u(g));
    Vec3 p = c + Vec3(u(g), u(g), u(g)) * r * 1.05;
    if (t % 7 == 0) p[0] = c[0] + r * (1 - 1e-9);  // near tangency
    if (t % 11 == 0) p[1] = c[1];
    double s = 0.0;
    for (int o = 0; o < 8; ++o) {
      Vec3 lo, hi;
      for (int d = 0; d < 3; ++d) {
        lo[d] = (o >> d) & 1 ? p[d] : -kBig;
        hi[d] = (o >> d) & 1 ? kBig : p[d];
      }
      s += sphere_box_volume(c, r, lo, hi);
    }
    worst = std::max(worst, std::fabs(s - sphere_vol(r)) / sphere_vol(r));
  }
  INFO("worst relative error of the octant sum " << worst);
  CHECK(worst < 1e-12);
  // random boxes against Monte Carlo (4e6 points in the sphere's cube)
  const long n = 4000000;
  for (int t = 0; t < 6; ++t) {
    Vec3 lo(0.9 * u(g), 0.9 * u(g), 0.9 * u(g));
    const Vec3 hi = lo + Vec3(0.2 + std::fabs(u(g)), 0.2 + std::fabs(u(g)), 0.2 + std::fabs(u(g)));
    long in = 0;
    for (long s = 0; s < n; ++s) {
      const Vec3 p(u(g), u(g), u(g));
      if (p.squaredNorm() <= 1.0 && in_box(p, lo, hi)) ++in;
    }
    const double mc = 8.0 * in / n;
    const double exact = sphere_box_volume(Vec3(0, 0, 0), 1.0, lo, hi);
    INFO("box " << lo.transpose() << " / " << hi.transpose() << ": " << exact << " vs MC " << mc);
    CHECK(std::fabs(exact - mc) <= 0.01 * std::max(exact, 0.05 * sphere_vol(1.0)));
    CHECK(std::fabs(exact - mc) <= 6.0 * 8.0 * std::sqrt(in + 1.0) / n);  // six standard deviations
  }
}

TEST_CASE("region-phi: simple cubic lattice", "[region_phi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds(lattice_script());
  // a block commensurate with the lattice, cutting through spheres: pi/6
  s.cmd("region cut block 0.3 4.3 0.1 3.1 -0.2 1.8");
  s.cmd("compute phi all region-phi cut");
  CHECK(s.e.compute_value("phi", 0) == Approx(M_PI / 6).epsilon(1e-9));
  const double t1 = s.e.compute_value("phi", 1), t2 = s.e.compute_value("phi", 2);
  CHECK(t1 + t2 == Approx(M_PI / 6).epsilon(1e-12));
  // listed types, one type only
  s.cmd("compute phi2 all region-phi cut type 2");
  CHECK(s.e.compute_value("phi2", 1) == Approx(t2).epsilon(1e-14));
  // a block not commensurate with the lattice: Monte Carlo
  s.cmd("region odd block 0.3 3.9 0.25 4.1 0.7 2.2");
  s.cmd("compute phi3 all region-phi odd");
  const double phi = s.e.compute_value("phi3", 0);
  const double mc = lattice_mc(Vec3(0.3, 0.25, 0.7), Vec3(3.9, 4.1, 2.2), 4000000, 99);
  INFO("phi " << phi << " Monte Carlo " << mc);
  CHECK(std::fabs(phi - mc) < 6 * std::sqrt(mc * (1 - mc) / 4000000));
  CHECK(s.e.compute_value("phi3", 1) + s.e.compute_value("phi3", 2) == Approx(phi).epsilon(1e-12));
  // usable in variables and thermo
  s.cmd("variable p equal c_phi3");
  s.cmd("variable q equal c_phi3[1]+c_phi3[2]");
  s.cmd("thermo_style custom step c_phi c_phi3[1]");
  CHECK_NOTHROW(s.cmd("run 0"));
}

TEST_CASE("region-phi: periodic images", "[region_phi]") {
  // spheres at 0..5 in a periodic box [-0.5, 5.5): a block through the
  // periodic boundary still gives pi/6 when commensurate
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  auto script = lattice_script("p p p");
  s.cmds(script);
  s.cmd("region cut block -0.5 5.5 -0.5 5.5 1.2 3.2");
  s.cmd("compute phi all region-phi cut");
  CHECK(s.e.compute_value("phi", 0) == Approx(M_PI / 6).epsilon(1e-9));
  // a lattice shifted by half a spacing in x and y: the spheres straddling
  // the boundary count through their images
  granary::test::ScriptEngine t(MPI_COMM_WORLD);
  t.cmds(lattice_script("p p p", 0.5));
  t.cmd("region cut block -0.5 5.5 -0.5 5.5 1.2 3.2");
  t.cmd("compute phi all region-phi cut");
  CHECK(t.e.compute_value("phi", 0) == Approx(M_PI / 6).epsilon(1e-9));
}

TEST_CASE("region-phi: errors", "[region_phi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds(lattice_script());
  s.cmd("region ball sphere 1 1 1 0.5");
  CHECK_THROWS_WITH(s.cmd("compute a all region-phi ball"), Catch::Matchers::Contains("block"));
  s.cmd("region half block 0 1 0 1 0 INF");
  CHECK_THROWS_AS(s.cmd("compute b all region-phi half"), granary::InputError);
  s.cmd("region outside block 0 1 0 1 0 1 side out");
  CHECK_THROWS_AS(s.cmd("compute c all region-phi outside"), granary::InputError);
  s.cmd("region ok block 0 1 0 1 0 1");
  CHECK_THROWS_AS(s.cmd("compute d all region-phi ok type 3"), granary::InputError);
  CHECK_THROWS_AS(s.cmd("compute e all region-phi ok clump exact"), granary::InputError);
  CHECK_THROWS_AS(s.cmd("compute f all region-phi nothere"), granary::InputError);
}

TEST_CASE("region-phi: a 50-sphere cylinder clump", "[region_phi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds(clump_script());
  s.cmd("create_clump cyl 0.0001 -0.0002 0.0003 quat 0.9238795 0.2209424 0.2209424 0.2209424");
  const auto* ms = dynamic_cast<granary::FixMultisphere*>(s.e.clumps);
  REQUIRE(ms);
  const granary::Bodies& B = ms->bodies();
  REQUIRE(B.size() == 1);
  const double vbody = B.volume[0];
  // wholly inside: the template volume exactly
  s.cmd("region big block -0.004 0.005 -0.005 0.004 -0.003 0.006");
  s.cmd("compute in all region-phi big");
  const double vbig = 0.009 * 0.009 * 0.009;
  CHECK(s.e.compute_value("in", 0) == Approx(vbody / vbig).epsilon(1e-12));
  CHECK(s.e.compute_value("in", 1) == Approx(vbody / vbig).epsilon(1e-12));
  CHECK(s.e.compute_value("in", 2) == 0.0);
  // a face through the clump: Monte Carlo of the union (within 1% of the clump volume)
  int n = 0;
  for (double face : {0.0001, 0.0006, -0.0009}) {
    char line[160];
    const std::string rid = "cut" + std::to_string(++n);
    std::snprintf(line, sizeof line, "region %s block %.6f 0.005 -0.005 0.004 -0.003 0.006", rid.c_str(),
                  face);
    s.cmd(line);
    s.cmd("compute mc all region-phi " + rid);
    s.cmd("compute sc all region-phi " + rid + " clump scale");
    const Vec3 lo(face, -0.005, -0.003), hi(0.005, 0.004, 0.006);
    const double vblock = (hi - lo).prod();
    const double ref = clump_mc(B, lo, hi, 4000000);
    const double vmc = s.e.compute_value("mc", 0) * vblock;
    const double vsc = s.e.compute_value("sc", 0) * vblock;
    INFO("face " << face << ": reference " << ref / vbody << ", mc " << vmc / vbody << ", scale "
                 << vsc / vbody << " of the clump volume");
    CHECK(std::fabs(vmc - ref) < 0.01 * vbody);
    CHECK(std::fabs(vsc - ref) < 0.06 * vbody);  // measured up to 4.7%
    s.cmd("uncompute mc");
    s.cmd("uncompute sc");
  }
}
