// Region styles (inside, bounds, volume, side out, INF/EDGE, lattice units),
// groups on a created lattice, and the particle commands lattice,
// create_atoms, set, velocity and delete_atoms.
#include <mpi.h>

#include <Eigen/Geometry>
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "script_engine.h"
#include "core/atom_properties.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/input.h"
#include "core/logger.h"
#include "core/resources.h"
#include "domain/domain.h"
#include "domain/groups.h"
#include "domain/region.h"
#include "particles/particles.h"

using Catch::Matchers::Contains;
using granary::Engine;
using granary::InputError;
using granary::Vec3;

namespace {

struct Sim : granary::test::ScriptEngine {
  Sim() : ScriptEngine(MPI_COMM_WORLD) {}
  granary::Region* region(const std::string& id) { return e.domain->find_region(id); }
  double count(const std::string& group) { return e.groups->count(e.groups->find_or_error(group, "test")); }
};

/// Positions of all particles by id, from every rank.
std::map<long long, Vec3> gather_positions(Engine& e) {
  const auto& p = *e.particles;
  std::vector<double> mine;
  for (int i = 0; i < p.nlocal; ++i) {
    mine.push_back(static_cast<double>(p.id[i]));
    for (int d = 0; d < 3; ++d)
      mine.push_back(p.x[i][d]);
  }
  int n = static_cast<int>(mine.size());
  std::vector<int> counts(e.nprocs), displs(e.nprocs, 0);
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, e.world);
  for (int r = 1; r < e.nprocs; ++r)
    displs[r] = displs[r - 1] + counts[r - 1];
  std::vector<double> all(static_cast<std::size_t>(displs.back() + counts.back()));
  MPI_Allgatherv(mine.data(), n, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE, e.world);
  std::map<long long, Vec3> out;
  for (std::size_t k = 0; k + 3 < all.size(); k += 4) {
    out[static_cast<long long>(all[k])] = Vec3(all[k + 1], all[k + 2], all[k + 3]);
  }
  return out;
}

const std::vector<std::string> kBox = {"units si", "atom_style granular", "boundary p p p",
                                       "region box block 0 1 0 1 0 1 units box", "create_box 3 box"};

}  // namespace

TEST_CASE("region block: inside, bounds, volume and side out", "[region]") {
  Sim s;
  s.cmd("region b block 0 1 0 2 0 3");
  auto* b = s.region("b");
  REQUIRE(b != nullptr);
  CHECK(b->match(Vec3(0.5, 1, 1.5)));
  CHECK(b->match(Vec3(1, 2, 3)));  // faces belong to the block
  CHECK(b->match(Vec3(0, 0, 0)));
  CHECK_FALSE(b->match(Vec3(1.1, 1, 1)));
  CHECK_FALSE(b->match(Vec3(0.5, -0.01, 1)));
  Vec3 lo, hi;
  REQUIRE(b->bounds(lo, hi));
  CHECK(lo == Vec3(0, 0, 0));
  CHECK(hi == Vec3(1, 2, 3));
  CHECK(b->volume() == Approx(6.0));

  s.cmd("region bo block 0 1 0 2 0 3 side out");
  auto* bo = s.region("bo");
  CHECK(bo->inside(Vec3(0.5, 1, 1.5)));  // the shape ignores side
  CHECK_FALSE(bo->match(Vec3(0.5, 1, 1.5)));
  CHECK(bo->match(Vec3(2, 0, 0)));
  CHECK_FALSE(bo->bounds(lo, hi));
  CHECK(bo->volume() < 0.0);

  s.cmd("region bi block INF 1 -INF INF 0 1");
  auto* bi = s.region("bi");
  CHECK(bi->match(Vec3(-1.0e6, 5.0e5, 0.5)));
  CHECK_FALSE(bi->match(Vec3(1.5, 0, 0.5)));
  CHECK_FALSE(bi->bounds(lo, hi));
  CHECK(bi->volume() < 0.0);
}

TEST_CASE("region EDGE needs the box and maps to its faces", "[region]") {
  Sim s;
  CHECK_THROWS_AS(s.cmd("region e block EDGE EDGE 0 1 0 1"), InputError);
  s.cmds(kBox);
  s.cmd("region e block EDGE 0.5 0.2 EDGE EDGE EDGE");
  Vec3 lo, hi;
  REQUIRE(s.region("e")->bounds(lo, hi));
  CHECK(lo == Vec3(0, 0.2, 0));
  CHECK(hi == Vec3(0.5, 1, 1));
}

TEST_CASE("region cylinder along z and x", "[region]") {
  Sim s;
  s.cmd("region c cylinder z 0.5 0.5 0.2 0 1");
  auto* c = s.region("c");
  CHECK(c->match(Vec3(0.6, 0.5, 0.5)));
  CHECK(c->match(Vec3(0.7, 0.5, 1.0)));  // on the mantle and the top face
  CHECK_FALSE(c->match(Vec3(0.71, 0.5, 0.5)));
  CHECK_FALSE(c->match(Vec3(0.5, 0.5, 1.2)));
  CHECK_FALSE(c->match(Vec3(0.5, 0.5, -0.1)));
  Vec3 lo, hi;
  REQUIRE(c->bounds(lo, hi));
  CHECK(lo.isApprox(Vec3(0.3, 0.3, 0)));
  CHECK(hi.isApprox(Vec3(0.7, 0.7, 1)));
  CHECK(c->volume() == Approx(M_PI * 0.04));

  // axis x: centre (y, z) = (1, 2)
  s.cmd("region cx cylinder x 1 2 0.5 -1 1");
  auto* cx = s.region("cx");
  CHECK(cx->match(Vec3(0, 1.4, 2)));
  CHECK(cx->match(Vec3(0.9, 1, 2.3)));
  CHECK_FALSE(cx->match(Vec3(0, 1, 2.6)));
  CHECK_FALSE(cx->match(Vec3(1.5, 1, 2)));
  REQUIRE(cx->bounds(lo, hi));
  CHECK(lo.isApprox(Vec3(-1, 0.5, 1.5)));
  CHECK(hi.isApprox(Vec3(1, 1.5, 2.5)));
  CHECK(cx->volume() == Approx(M_PI * 0.25 * 2));

  // axis y: centre (x, z) = (3, 4); unbounded along the axis
  s.cmd("region cy cylinder y 3 4 1 INF INF side out");
  auto* cy = s.region("cy");
  CHECK(cy->inside(Vec3(3.5, 1.0e9, 4.5)));
  CHECK_FALSE(cy->match(Vec3(3.5, 1.0e9, 4.5)));
  CHECK(cy->match(Vec3(5, 0, 4)));
  CHECK_FALSE(cy->bounds(lo, hi));
  CHECK(cy->volume() < 0.0);
}

TEST_CASE("region sphere", "[region]") {
  Sim s;
  s.cmd("region s sphere 1 2 3 0.5");
  auto* r = s.region("s");
  CHECK(r->match(Vec3(1, 2, 3)));
  CHECK(r->match(Vec3(1.5, 2, 3)));
  CHECK_FALSE(r->match(Vec3(1.4, 2.4, 3)));
  Vec3 lo, hi;
  REQUIRE(r->bounds(lo, hi));
  CHECK(lo.isApprox(Vec3(0.5, 1.5, 2.5)));
  CHECK(hi.isApprox(Vec3(1.5, 2.5, 3.5)));
  CHECK(r->volume() == Approx(4.0 / 3.0 * M_PI * 0.125));

  s.cmd("region so sphere 1 2 3 0.5 side out");
  CHECK_FALSE(s.region("so")->match(Vec3(1, 2, 3)));
  CHECK(s.region("so")->match(Vec3(3, 2, 3)));
  CHECK_FALSE(s.region("so")->bounds(lo, hi));
  CHECK(s.region("so")->volume() < 0.0);
}

// A ball with a block cut out of it and a block with a ball removed, tested
// at points whose answer is known; the sub-regions' own side counts; the
// group of a lattice in the union counts what both parts hold minus the
// overlap; insert/pack measures the union's volume by Monte Carlo.
TEST_CASE("region union and intersect combine regions with their sides", "[region]") {
  Sim s;
  s.cmds({"region ball sphere 0 0 0 1 units box", "region slab block -2 2 -2 2 0 2 units box",
          "region noslab block -2 2 -2 2 0 2 side out units box", "region u union 2 ball slab units box",
          "region i intersect 2 ball slab units box", "region cut intersect 2 ball noslab units box",
          "region iout intersect 2 ball slab side out units box"});
  const Vec3 centre_top(0, 0, 0.5), centre_bottom(0, 0, -0.5), far_top(1.5, 1.5, 1.5), far_bottom(0, 0, -1.5);
  CHECK(s.region("u")->match(centre_top));
  CHECK(s.region("u")->match(centre_bottom));
  CHECK(s.region("u")->match(far_top));
  CHECK_FALSE(s.region("u")->match(far_bottom));
  CHECK(s.region("i")->match(centre_top));
  CHECK_FALSE(s.region("i")->match(centre_bottom));
  CHECK_FALSE(s.region("i")->match(far_top));
  CHECK(s.region("cut")->match(centre_bottom));  // the ball below the slab
  CHECK_FALSE(s.region("cut")->match(centre_top));
  CHECK_FALSE(s.region("iout")->match(centre_top));  // side out of the intersection
  CHECK(s.region("iout")->match(far_top));
  Vec3 lo, hi;
  REQUIRE(s.region("u")->bounds(lo, hi));
  CHECK(lo == Vec3(-2, -2, -1));
  CHECK(hi == Vec3(2, 2, 2));
  REQUIRE(s.region("i")->bounds(lo, hi));
  CHECK(lo == Vec3(-1, -1, 0));
  CHECK(hi == Vec3(1, 1, 1));
  REQUIRE(s.region("cut")->bounds(lo, hi));  // only the ball is bounded
  CHECK(lo == Vec3(-1, -1, -1));
  CHECK(hi == Vec3(1, 1, 1));
  s.cmd("region u2 union 2 ball noslab units box");  // one part unbounded
  CHECK_FALSE(s.region("u2")->bounds(lo, hi));
  CHECK_FALSE(s.region("iout")->bounds(lo, hi));
  CHECK(s.region("u")->volume() < 0.0);
  CHECK_THROWS_WITH(s.cmd("region ball delete"), Contains("region u (union) is made of it"));
  CHECK_THROWS_WITH(s.cmd("region x union 1 ball"), Contains("combines 2 to 1000 regions"));
  CHECK_THROWS_WITH(s.cmd("region x union 2 ball nosuch"), Contains("nosuch"));
  CHECK_THROWS_WITH(s.cmd("region x intersect 3 ball slab"), Contains("needs 4 arguments"));
  CHECK_THROWS_WITH(s.cmd("region x union two ball slab"), Contains("number of regions"));
  CHECK_THROWS_WITH(s.cmd("region x union 2 ball x"), Contains("cannot contain itself"));
}

TEST_CASE("region union: a group and an insertion over two separate blocks", "[region]") {
  Sim s;
  s.cmds(kBox);
  s.cmds({"region a block 0 0.25 0 1 0 1 units box", "region b block 0.75 1 0 1 0 1 units box",
          "region ab union 2 a b units box", "lattice sc 0.1", "create_atoms 1 box", "group both region ab",
          "group ga region a", "group gb region b"});
  CHECK(s.count("both") == s.count("ga") + s.count("gb"));
  CHECK(s.count("both") > 0);
}

TEST_CASE("region plane: the half-space the normal points to", "[region]") {
  Sim s;
  s.cmd("region p plane 0 0 1 0 0 2");  // normal is normalised
  auto* p = s.region("p");
  CHECK(p->match(Vec3(5, 5, 1)));  // on the plane
  CHECK(p->match(Vec3(0, 0, 1.1)));
  CHECK_FALSE(p->match(Vec3(0, 0, 0.9)));
  Vec3 lo, hi;
  CHECK_FALSE(p->bounds(lo, hi));
  CHECK(p->volume() < 0.0);

  s.cmd("region q plane 1 1 1 1 1 0 side out");
  CHECK(s.region("q")->match(Vec3(0, 0, 7)));
  CHECK_FALSE(s.region("q")->match(Vec3(2, 1, 0)));
}

TEST_CASE("region units lattice scales by the lattice spacing", "[region]") {
  Sim s;
  CHECK_THROWS_WITH(s.cmd("region l block 0 2 0 2 0 2 units lattice"), Contains("lattice"));
  s.cmd("lattice sc 0.5");
  s.cmd("region l block 0 2 0 2 0 2 units lattice");
  Vec3 lo, hi;
  REQUIRE(s.region("l")->bounds(lo, hi));
  CHECK(hi.isApprox(Vec3(1, 1, 1)));
  s.cmd("region lb block 0 2 0 2 0 2");  // box units by default
  REQUIRE(s.region("lb")->bounds(lo, hi));
  CHECK(hi.isApprox(Vec3(2, 2, 2)));
  s.cmd("region ls sphere 1 1 1 1 units lattice");
  CHECK(s.region("ls")->volume() == Approx(4.0 / 3.0 * M_PI * 0.125));
}

// The surface points fix wall/region acts from: distance r and del = x - point.
TEST_CASE("region surfaces: nearest points of each face inside, of the shape outside", "[region]") {
  Sim s;
  s.cmds({"region b block 0 1 0 2 0 3", "region bo block 0 1 0 2 0 3 side out",
          "region c cylinder z 0 0 1 -1 1", "region co cylinder z 0 0 1 -1 1 side out",
          "region sp sphere 1 1 1 2", "region so sphere 1 1 1 2 side out", "region p plane 0 0 1 0 0 2",
          "region po plane 0 0 1 0 0 2 side out", "region half block INF INF INF INF 0 INF"});
  std::vector<granary::Region::SurfacePoint> pts;
  auto check = [&](const char* id, const Vec3& x, double cutoff, std::vector<std::pair<double, Vec3>> want) {
    INFO("region " << id << " at " << x.transpose());
    s.region(id)->surface(x, cutoff, pts);
    REQUIRE(pts.size() == want.size());
    for (std::size_t k = 0; k < want.size(); ++k) {
      CHECK(pts[k].r == Approx(want[k].first).margin(1e-15));
      CHECK((pts[k].del - want[k].second).norm() < 1e-15);
    }
  };
  // block inside: each face within the cutoff (a corner: three)
  check("b", Vec3(0.5, 1, 1.5), 0.4, {});
  check("b", Vec3(0.9, 1, 1.5), 0.4, {{0.1, Vec3(-0.1, 0, 0)}});
  check("b", Vec3(0.1, 1.8, 2.95), 0.4,
        {{0.1, Vec3(0.1, 0, 0)}, {0.2, Vec3(0, -0.2, 0)}, {0.05, Vec3(0, 0, -0.05)}});
  check("b", Vec3(2, 1, 1), 0.4, {});  // not in the region
  // block outside: the nearest point of the box (an edge here)
  check("bo", Vec3(1.3, 2.4, 1), 1.0, {{0.5, Vec3(0.3, 0.4, 0)}});
  check("bo", Vec3(0.5, 1, 1), 1.0, {});
  // infinite bounds have no face
  check("half", Vec3(5, -7, 0.25), 0.5, {{0.25, Vec3(0, 0, 0.25)}});
  // cylinder inside: curved face towards the axis and the end faces
  check("c", Vec3(0.6, 0.8, 0.9), 0.2, {{0.0, Vec3(0, 0, 0)}, {0.1, Vec3(0, 0, -0.1)}});
  check("c", Vec3(0.48, 0.64, 0.0), 0.3, {{0.2, Vec3(-0.12, -0.16, 0)}});
  check("c", Vec3(0, 0, 0.0), 2.0,
        {{1.0, Vec3(0, 0, 1)}, {1.0, Vec3(0, 0, -1)}});  // on the axis: no radial point
  // cylinder outside: beside it, above it, beyond its rim
  check("co", Vec3(1.2, 1.6, 0.5), 2.0, {{1.0, Vec3(0.6, 0.8, 0)}});
  check("co", Vec3(0.3, 0.4, 1.5), 2.0, {{0.5, Vec3(0, 0, 0.5)}});
  check("co", Vec3(1.2, 1.6, 1.5), 2.0, {{std::sqrt(1.25), Vec3(0.6, 0.8, 0.5)}});
  // sphere inside and outside
  check("sp", Vec3(1, 1, 2.5), 1.0, {{0.5, Vec3(0, 0, -0.5)}});
  check("sp", Vec3(1, 1, 1), 3.0, {});  // the centre
  check("so", Vec3(1, 4, 1), 1.5, {{1.0, Vec3(0, 1, 0)}});
  // plane: along the normal on its side, against it on the other
  check("p", Vec3(3, 4, 1.5), 1.0, {{0.5, Vec3(0, 0, 0.5)}});
  check("po", Vec3(3, 4, 0.7), 1.0, {{0.3, Vec3(0, 0, -0.3)}});
  check("po", Vec3(3, 4, 1.5), 1.0, {});
}

TEST_CASE("region cone, prism and wedge pick the lattice points LIGGGHTS 3.8 picks", "[region]") {
  // a simple cubic lattice of 8000 points, shifted off the shapes' boundaries;
  // the group counts are LIGGGHTS 3.8's for the same script
  Sim s;
  s.cmds({"units si",
          "atom_style granular",
          "atom_modify map array",
          "boundary f f f",
          "region box block -1 1 -1 1 -1 1 units box",
          "create_box 1 box",
          "lattice sc 0.1 origin 0.123 0.271 0.377",
          "region c1 cone z 0.05 -0.1 0.6 0.2 -0.7 0.8 units box",
          "region c2 cone x 0.1 0.0 0.0 0.5 -0.5 0.5 units box",
          "region c3 cone y 0 0 0.3 0.3 INF INF units box",
          "region c4 cone z 0 0 0.5 0.1 -0.5 0.5 side out units box",
          "region p1 prism -0.5 0.5 -0.4 0.4 -0.3 0.6 0.3 -0.2 0.25 units box",
          "region p2 prism -0.6 0.2 -0.5 0.5 -0.5 0.5 0 0 0 units box",
          "region p3 prism 0 5 0 4 0 3 1 0.5 -1 units lattice",
          "region w1 wedge axis y center 0 0 radius 0.9 bounds -0.5 0.5 angle0 -22.5 angle 45 units box",
          "region w2 wedge axis z center 0.1 -0.2 radius 0.7 bounds -0.8 0.6 angle0 100 angle 200 units box",
          "region w3 wedge axis x center 0.05 0.1 radius 0.8 bounds -0.9 0.9 angle0 300 angle 120 units box",
          "region w4 wedge axis z center 0 0 radius 0.6 bounds INF INF angle0 45 angle 90 side out units box",
          "region w5 wedge axis x center 0 0 radius 5 bounds 0 5 angle0 10 angle 30 units lattice",
          "create_atoms 1 box"});
  REQUIRE(s.count("all") == 8000);
  const std::vector<std::pair<std::string, long long>> liggghts = {
      {"c1", 829}, {"c2", 234}, {"c3", 560},  {"c4", 7670}, {"p1", 720},  {"p2", 800},
      {"p3", 60},  {"w1", 330}, {"w2", 1232}, {"w3", 1206}, {"w4", 7400}, {"w5", 30}};
  for (const auto& [id, n] : liggghts) {
    s.cmd("group g_" + id + " region " + id);
    INFO("region " << id);
    CHECK(s.count("g_" + id) == n);
  }
  // the volumes: a lattice point per 1e-3 m^3 (within the count's discreteness)
  CHECK(s.region("c1")->volume() == Approx(M_PI * 1.5 * (0.36 + 0.12 + 0.04) / 3).epsilon(1e-12));
  CHECK(829 * 1e-3 == Approx(s.region("c1")->volume()).epsilon(0.03));
  CHECK(s.region("p1")->volume() == Approx(0.72).epsilon(1e-12));
  CHECK(s.region("w2")->volume() == Approx(M_PI * 0.49 * 1.4 * 200 / 360).epsilon(1e-12));
  CHECK(1232 * 1e-3 == Approx(s.region("w2")->volume()).epsilon(0.03));
  CHECK_THROWS_WITH(s.cmd("region bad wedge axis z centre 0 0 radius 1 bounds 0 1 angle0 0 angle 90"),
                    Contains("expected 'center'"));
  CHECK_THROWS_WITH(s.cmd("region bad wedge axis z center 0 0 radius 1 bounds 0 1 angle0 0 angle 400"),
                    Contains("(0, 360]"));
  CHECK_THROWS_WITH(s.cmd("lattice sc 0.1 origin 1.2 0 0"), Contains("[0, 1)"));
  CHECK_THROWS_WITH(s.cmd("lattice sc 0.1 origin 0.5 0.5"), Contains("three values"));
  CHECK_THROWS_WITH(s.cmd("lattice sc 0.1 orient x 1 0 0"), Contains("unknown lattice keyword 'orient'"));
  CHECK_THROWS_WITH(s.cmd("region bad cone z 0 0 1 0.5 INF INF"), Contains("equal radii"));
  CHECK_THROWS_WITH(s.cmd("region bad prism INF INF 0 1 0 1 0.5 0 0"), Contains("finite bounds"));
  Vec3 lo, hi;
  REQUIRE(s.region("p1")->bounds(lo, hi));  // corners o + i A + j B + k C
  CHECK(lo.isApprox(Vec3(-0.7, -0.4, -0.3)));
  CHECK(hi.isApprox(Vec3(0.8, 0.65, 0.6)));
  CHECK_FALSE(s.region("c3")->bounds(lo, hi));  // INF along its axis
  CHECK_FALSE(s.region("c4")->bounds(lo, hi));  // side out
}

TEST_CASE("region cone: the surface points fix wall/region acts from", "[region]") {
  // radius 1 at z = 0, 0.5 at z = 2; in the (rho, z) half-plane the slanted
  // face runs from (1, 0) to (0.5, 2)
  Sim s;
  s.cmds({"region k cone z 0 0 1 0.5 0 2", "region ko cone z 0 0 1 0.5 0 2 side out",
          "region apex cone x 0 0 0 1 0 1"});
  std::vector<granary::Region::SurfacePoint> pts;
  const double len = std::sqrt(4.25);
  const Vec3 out_n(2 / len, 0, 0.5 / len);  // outward normal of the slanted face at azimuth 0
  // inside, at (0.5, 0, 1): the slanted face at 0.5/sqrt(4.25), both ends at 1
  s.region("k")->surface(Vec3(0.5, 0, 1), 1.5, pts);
  REQUIRE(pts.size() == 3);
  CHECK(pts[0].r == Approx(0.5 / len).epsilon(1e-14));
  CHECK((pts[0].del + pts[0].r * out_n).norm() < 1e-14);
  CHECK(pts[1].r == 1.0);
  CHECK(pts[1].del == Vec3(0, 0, 1));
  CHECK(pts[2].r == 1.0);
  CHECK(pts[2].del == Vec3(0, 0, -1));
  s.region("k")->surface(Vec3(0.5, 0, 1), 0.2, pts);  // all farther than the cutoff
  CHECK(pts.empty());
  // the same at azimuth 90 degrees
  s.region("k")->surface(Vec3(0, 0.5, 1), 0.3, pts);
  REQUIRE(pts.size() == 1);
  CHECK((pts[0].del + pts[0].r * Vec3(0, 2 / len, 0.5 / len)).norm() < 1e-14);
  // outside, beside the slanted face: its foot at (rho, z) = (1, 0) + t (-0.5, 2), t = 1.5/4.25
  s.region("ko")->surface(Vec3(2, 0, 1), 3.0, pts);
  REQUIRE(pts.size() == 1);
  const double t = 1.5 / 4.25;
  const Vec3 foot(1 - 0.5 * t, 0, 2 * t);
  CHECK((pts[0].del - (Vec3(2, 0, 1) - foot)).norm() < 1e-14);
  CHECK(pts[0].r == Approx((Vec3(2, 0, 1) - foot).norm()).epsilon(1e-14));
  // outside, below the base and beyond the rim: the rim
  s.region("ko")->surface(Vec3(0, -1.6, -0.8), 3.0, pts);
  REQUIRE(pts.size() == 1);
  CHECK((pts[0].del - Vec3(0, -0.6, -0.8)).norm() < 1e-14);
  // outside, above the top face: straight down onto it
  s.region("ko")->surface(Vec3(0.1, 0.2, 2.5), 3.0, pts);
  REQUIRE(pts.size() == 1);
  CHECK((pts[0].del - Vec3(0, 0, 0.5)).norm() < 1e-14);
  // a cone with its apex at x = 0 has no end face there
  s.region("apex")->surface(Vec3(0.5, 0.1, 0), 2.0, pts);
  REQUIRE(pts.size() == 2);  // the slanted face and the base at x = 1
  CHECK(pts[1].del == Vec3(-0.5, 0, 0));
}

namespace {

// A unit cube in the six tetrahedra around its diagonal 0-7 and a tetrahedron
// standing on the face (4 5 7) of one of them, with a vertex, a line and a
// triangle cell beside them (skipped), as gmsh writes its meshes.
const char* kTetMesh = R"(# vtk DataFile Version 2.0
unit cube in six tetrahedra and a tetrahedron on top
ASCII
DATASET UNSTRUCTURED_GRID
POINTS 9 double
0 0 0
1 0 0
0 1 0
1 1 0
0 0 1
1 0 1
0 1 1
1 1 1
0.8 0.3 1.6
CELLS 10 41
1 0
2 0 7
3 0 1 3
4 0 1 3 7
4 0 1 5 7
4 0 4 5 7
4 0 2 3 7
4 0 2 6 7
4 0 4 6 7
4 4 5 7 8
CELL_TYPES 10
1
3
5
10
10
10
10
10
10
10
)";

std::string write_text(const std::string& dir, const std::string& name, const std::string& text) {
  const std::string file = dir + "/" + name;
  std::ofstream(file) << text;
  return file;
}

}  // namespace

TEST_CASE("region mesh/tet picks the lattice points LIGGGHTS 3.8 picks, moved, scaled and rotated",
          "[region]") {
  const std::string dir = granary::test::shared_temp_dir("granary_mesh_tet_");
  const std::string mesh = write_text(dir, "tets.vtk", kTetMesh);
  Sim s;
  s.cmds({"units si", "atom_style granular", "atom_modify map array", "boundary f f f",
          "region box block -1 2 -1 2 -1 2 units box", "create_box 1 box",
          "lattice sc 0.1 origin 0.123 0.271 0.377",
          "region t1 mesh/tet file " + mesh + " scale 1 move 0 0 0 rotate 0 0 0 units box",
          "region t2 mesh/tet file " + mesh + " scale 0.8 move 0.1 -0.2 0.05 rotate 10 20 30 units box",
          "region t3 mesh/tet file " + mesh + " scale 1.3 move -0.5 -0.5 -0.5 rotate 0 0 45 units box",
          "region t4 mesh/tet file " + mesh + " scale 1 move 0 0 0 rotate 0 0 90 side out units box",
          "create_atoms 1 box"});
  REQUIRE(s.count("all") == 27000);
  // LIGGGHTS 3.8's group counts for the same script and file
  const std::vector<std::pair<std::string, long long>> liggghts = {
      {"t1", 1111}, {"t2", 563}, {"t3", 2415}, {"t4", 25891}};
  for (const auto& [id, n] : liggghts) {
    s.cmd("group g_" + id + " region " + id);
    INFO("region " << id);
    CHECK(s.count("g_" + id) == n);
  }
  // volume: the cube and the tetrahedron on top (0.5 x 0.6 / 3 = 0.1), times scale^3
  CHECK(s.region("t1")->volume() == Approx(1.1).epsilon(1e-12));
  CHECK(s.region("t2")->volume() == Approx(0.512 * 1.1).epsilon(1e-12));
  CHECK(1111 * 1e-3 == Approx(s.region("t1")->volume()).epsilon(0.03));
  CHECK(s.region("t4")->volume() == -1.0);
  Vec3 lo, hi;
  REQUIRE(s.region("t1")->bounds(lo, hi));
  CHECK(lo.isApprox(Vec3(0, 0, 0)));
  CHECK(hi.isApprox(Vec3(1, 1, 1.6)));
  // t3: moved by -0.5, scaled by 1.3, turned 45 degrees about z: the cube's
  // corner (1, 1, 1) goes to (0, 0.65 sqrt 2, 0.65)
  REQUIRE(s.region("t3")->bounds(lo, hi));
  CHECK(hi[1] == Approx(0.65 * std::sqrt(2.0)).epsilon(1e-12));
  CHECK_FALSE(s.region("t4")->bounds(lo, hi));
  // points on faces: between two tetrahedra inside (the diagonal, a shared
  // face, the face under the top tetrahedron), on the mesh's surface outside
  granary::Region& t1 = *s.region("t1");
  CHECK(t1.match(Vec3(0.5, 0.5, 0.5)));        // on the diagonal 0-7, an edge of all six
  CHECK(t1.match(Vec3(0.6, 0.3, 0.3)));        // on the face (0 1 7) between two tetrahedra
  CHECK(t1.match(Vec3(0.7, 0.2, 1.0)));        // on the face (4 5 7) under the top one
  CHECK_FALSE(t1.match(Vec3(0.2, 0.7, 1.0)));  // on the cube's top, beside the top tetrahedron
  CHECK_FALSE(t1.match(Vec3(0.5, 0.5, 0.0)));  // on the bottom face
  CHECK_FALSE(t1.match(Vec3(0, 0, 0)));        // a corner
  CHECK_FALSE(t1.match(Vec3(1, 0.5, 0.5)));    // on a side
  CHECK(t1.match(Vec3(0.8, 0.3, 1.5)));        // inside the top tetrahedron
  CHECK_FALSE(t1.match(Vec3(0.2, 0.8, 1.5)));
  std::filesystem::remove_all(dir);
}

TEST_CASE("region mesh/tet refuses bad files and arguments", "[region]") {
  const std::string dir = granary::test::shared_temp_dir("granary_mesh_tet_err_");
  const std::string text = kTetMesh;
  Sim s;
  s.cmds({"units si", "atom_style granular", "boundary f f f", "region box block -1 2 -1 2 -1 2 units box",
          "create_box 1 box"});
  auto region = [&](const std::string& file) {
    s.cmd("region m mesh/tet file " + file + " scale 1 move 0 0 0 rotate 0 0 0");
  };
  auto with = [&](const std::string& name, const std::string& from, const std::string& to) {
    std::string t = text;
    t.replace(t.find(from), from.size(), to);
    return write_text(dir, name, t);
  };
  CHECK_THROWS_WITH(region(dir + "/none.vtk"), Contains("does not exist"));
  // cut inside the cell types, inside the cells, inside the points
  CHECK_THROWS_WITH(region(write_text(dir, "cut1.vtk", text.substr(0, text.size() - 9))),
                    Contains("line 33: the file ends after 7 of its 10 cell types (a truncated file?)"));
  CHECK_THROWS_WITH(region(write_text(dir, "cut2.vtk", text.substr(0, text.find("4 0 4 6 7")))),
                    Contains("the file ends after 8 of its 10 cells (a truncated file?)"));
  CHECK_THROWS_WITH(region(write_text(dir, "cut3.vtk", text.substr(0, text.find("0.8 0.3")))),
                    Contains("the file ends after 8 of its 9 points (a truncated file?)"));
  CHECK_THROWS_WITH(region(with("bin.vtk", "ASCII", "BINARY")), Contains("reads ASCII files only"));
  CHECK_THROWS_WITH(
      region(with("poly.vtk", "UNSTRUCTURED_GRID", "POLYDATA")),
      Contains("line 4: the dataset is 'POLYDATA'; region mesh/tet needs an UNSTRUCTURED_GRID"));
  CHECK_THROWS_WITH(region(with("index.vtk", "4 4 5 7 8", "4 4 5 7 9")),
                    Contains("line 25: cell 9 uses point 9 but there are 9 points (0..8)"));
  CHECK_THROWS_WITH(region(with("types.vtk", "CELL_TYPES 10", "CELL_TYPES 9")),
                    Contains("CELL_TYPES has 9 entries but CELLS has 10"));
  CHECK_THROWS_WITH(region(with("number.vtk", "0.8 0.3 1.6", "0.8 x 1.6")),
                    Contains("line 14: 'x' is not a finite number (point 8)"));
  CHECK_THROWS_WITH(region(with("head.vtk", "# vtk DataFile", "# VTK file")), Contains("line 1: expected"));
  {
    std::string t = text;  // every cell type 5: triangles only
    const std::size_t at = t.find("CELL_TYPES 10\n") + 14;
    t = t.substr(0, at) + "1\n3\n5\n5\n5\n5\n5\n5\n5\n5\n";
    CHECK_THROWS_WITH(region(write_text(dir, "notets.vtk", t)), Contains("holds no tetrahedra"));
  }
  CHECK_THROWS_WITH(region(with("flat.vtk", "0.8 0.3 1.6", "0.8 0.3 1.0")),
                    Contains("tetrahedron 6 of '" + dir + "/flat.vtk' is flat"));
  const std::string mesh = write_text(dir, "tets.vtk", text);
  CHECK_THROWS_WITH(s.cmd("region m mesh/tet file " + mesh + " scale 1 move 0 0 0 turn 0 0 0"),
                    Contains("expected 'rotate' at argument 11, found 'turn'"));
  CHECK_THROWS_WITH(s.cmd("region m mesh/tet file " + mesh + " move 0 0 0 rotate 0 0 0"),
                    Contains("needs 12 arguments"));
  CHECK_THROWS_WITH(s.cmd("region m mesh/tet file " + mesh + " scale 0 move 0 0 0 rotate 0 0 0"),
                    Contains("scale must be positive"));
  s.cmd("lattice sc 0.1");
  CHECK_THROWS_WITH(
      s.cmd("region m mesh/tet file " + mesh + " scale 1 move 0 0 0 rotate 0 0 0 units lattice"),
      Contains("use units box"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("region input errors", "[region]") {
  Sim s;
  CHECK_THROWS_WITH(s.cmd("region b block 0 1 0 1 0"), Contains("6 arguments"));
  CHECK_THROWS_WITH(s.cmd("region b block 1 0 0 1 0 1"), Contains("lower x bound exceeds"));
  CHECK_THROWS_WITH(s.cmd("region b block 0 1 0 1 0 1 side up"), Contains("in or out"));
  CHECK_THROWS_WITH(s.cmd("region b block 0 1 0 1 0 1 sid in"), Contains("unknown keyword"));
  CHECK_THROWS_WITH(s.cmd("region b block 0 1 0 1 0 1 side"), Contains("needs a value"));
  // a number missing before a keyword: the count, not "unknown keyword 'box'"
  CHECK_THROWS_WITH(s.cmd("region b block 0 1 0 1 0 units box"),
                    Contains("needs 6 numbers after the style name but has 5 before 'units'"));
  CHECK_THROWS_WITH(s.cmd("region s sphere 0 0 0 side out"),
                    Contains("needs 4 numbers after the style name but has 3 before 'side'"));
  CHECK_THROWS_WITH(s.cmd("region b block 0 1 0 one 0 1"), Contains("one"));
  CHECK_THROWS_WITH(s.cmd("region c cylinder w 0 0 1 0 1"), Contains("x, y or z"));
  CHECK_THROWS_WITH(s.cmd("region c cylinder z 0 0 -1 0 1"), Contains("positive"));
  CHECK_THROWS_WITH(s.cmd("region s sphere 0 0 0 0"), Contains("positive"));
  CHECK_THROWS_WITH(s.cmd("region p plane 0 0 0 0 0 0"), Contains("zero"));
  CHECK_THROWS_WITH(s.cmd("region x spheer 0 0 0 1"), Contains("sphere"));
  CHECK_THROWS_WITH(s.cmd("region bad-id sphere 0 0 0 1"), Contains("letters"));
  s.cmd("region b block 0 1 0 1 0 1");
  CHECK_THROWS_WITH(s.cmd("region b sphere 0 0 0 1"), Contains("already"));
  s.cmd("region b delete");
  CHECK(s.region("b") == nullptr);
}

TEST_CASE("lattice and create_atoms box fill the box exactly once", "[particles]") {
  SECTION("sc, periodic") {
    Sim s;
    s.cmds(kBox);
    s.cmds({"lattice sc 0.1", "create_atoms 1 box"});
    CHECK(s.e.particles->natoms == 1000);
    CHECK(s.count("all") == 1000);
  }
  SECTION("fcc, periodic") {
    Sim s;
    s.cmds(kBox);
    s.cmds({"lattice fcc 0.25", "create_atoms 1 box"});
    CHECK(s.e.particles->natoms == 256);
  }
  SECTION("fcc, fixed in z: no layer on the top face (LIGGGHTS 3.8 creates 256 here too)") {
    Sim s;
    s.cmds({"units si", "atom_style granular", "boundary p p f", "region box block 0 1 0 1 0 1",
            "create_box 1 box", "lattice fcc 0.25", "create_atoms 1 box"});
    CHECK(s.e.particles->natoms == 256);
    // a box a little taller than the lattice: the layer at z = 1 lies inside and is created
    Sim t;
    t.cmds({"units si", "atom_style granular", "boundary p p f", "region box block 0 1 0 1 0 1.01",
            "create_box 1 box", "lattice fcc 0.25", "create_atoms 1 box"});
    CHECK(t.e.particles->natoms == 256 + 32);
  }
  SECTION("bcc with a basis type") {
    Sim s;
    s.cmds(kBox);
    s.cmds({"lattice bcc 0.5", "create_atoms 1 box basis 2 3", "group t3 type 3"});
    CHECK(s.e.particles->natoms == 16);
    CHECK(s.count("t3") == 8);
  }
  SECTION("ids are 1..N and defaults are diameter 1, density 1") {
    Sim s;
    s.cmds(kBox);
    s.cmds({"lattice sc 0.5", "create_atoms 2 box"});
    const auto x = gather_positions(s.e);
    REQUIRE(x.size() == 8);
    CHECK(x.begin()->first == 1);
    CHECK(x.rbegin()->first == 8);
    const auto& p = *s.e.particles;
    for (int i = 0; i < p.nlocal; ++i) {
      CHECK(p.radius[i] == 0.5);
      CHECK(p.density[i] == 1.0);
      CHECK(p.rmass[i] == Approx(M_PI / 6.0));
      CHECK(p.type[i] == 2);
    }
  }
}

TEST_CASE("create_atoms region, single and errors", "[particles]") {
  Sim s;
  s.cmds(kBox);
  CHECK_THROWS_WITH(s.cmd("create_atoms 1 box"), Contains("lattice"));
  s.cmds({"lattice sc 0.1", "region ball sphere 0.5 0.5 0.5 0.25", "create_atoms 1 region ball"});
  int expected = 0;
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j)
      for (int k = 0; k < 10; ++k)
        if ((Vec3(i, j, k) * 0.1 - Vec3(0.5, 0.5, 0.5)).norm() <= 0.25) ++expected;
  CHECK(s.e.particles->natoms == expected);

  s.cmd("create_atoms 2 single 0.05 0.05 0.05");
  CHECK(s.e.particles->natoms == expected + 1);
  s.cmd("create_atoms 2 single 1.3 0.5 0.5 remap yes");  // periodic: maps to 0.3
  const auto x = gather_positions(s.e);
  CHECK(x.at(expected + 2).isApprox(Vec3(0.3, 0.5, 0.5)));
  s.cmd("create_atoms 2 single 1 1 1 units lattice");  // 0.1 0.1 0.1
  CHECK(gather_positions(s.e).at(expected + 3).isApprox(Vec3(0.1, 0.1, 0.1)));

  CHECK_THROWS_WITH(s.cmd("create_atoms 2 single 1.3 0.5 0.5"), Contains("outside the box"));
  CHECK_THROWS_WITH(s.cmd("create_atoms 4 single 0.5 0.5 0.5"), Contains("1..3"));
  CHECK_THROWS_WITH(s.cmd("create_atoms 1 singel 0.5 0.5 0.5"), Contains("single"));
  CHECK_THROWS_WITH(s.cmd("create_atoms 1 random 10 0 NULL"), Contains("seed"));
  CHECK_THROWS_WITH(s.cmd("create_atoms 1 random 10 5 nowhere"), Contains("nowhere"));
  // a count no machine holds: refused with the estimate before anything is allocated
  const int before = s.e.particles->nlocal;
  CHECK_THROWS_WITH(s.cmd("create_atoms 1 random 1000000000000 5 NULL"),
                    Contains("1e+12 particles would need about") && Contains("GB on this machine"));
  CHECK(s.e.particles->nlocal == before);
}

TEST_CASE("a particle limit refuses creation beyond it and the command guard sees every command",
          "[particles]") {
  Sim s;
  s.cmds(kBox);
  std::vector<std::string> seen;
  s.e.command_guard = [&seen](const granary::Args& w) {
    seen.push_back(w[0]);
    if (w[0] == "delete_atoms") throw InputError("guard: refused");
  };
  granary::set_particle_limit(500);
  // 10^3 lattice points in the box: refused before any is created (the bound counts candidates)
  s.cmd("lattice sc 0.1");
  CHECK_THROWS_WITH(s.cmd("create_atoms 1 box"), Contains("limit of 500 particles"));
  CHECK(s.e.particles->natoms == 0);
  CHECK_THROWS_WITH(s.cmd("create_atoms 1 random 501 5 NULL"), Contains("limit of 500 particles"));
  s.cmd("create_atoms 1 random 400 5 NULL");
  CHECK(s.e.particles->natoms == 400);
  CHECK_THROWS_WITH(s.cmd("create_atoms 1 random 101 6 NULL"), Contains("501 particles would pass"));
  CHECK_THROWS_WITH(s.cmd("delete_atoms group all"), Contains("guard: refused"));
  CHECK(s.e.particles->natoms == 400);
  granary::set_particle_limit(-1);  // none again
  s.e.command_guard = nullptr;
  s.cmd("create_atoms 1 random 200 7 NULL");
  CHECK(s.e.particles->natoms == 600);
  CHECK(seen == std::vector<std::string>{"lattice", "create_atoms", "create_atoms", "create_atoms",
                                         "create_atoms", "delete_atoms"});
}

TEST_CASE("a periodic remap of a particle millions of box lengths away takes one step", "[domain]") {
  Engine e(MPI_COMM_SELF);
  e.logger->set_screen(false);
  for (const char* c : {"atom_style granular", "boundary p p f", "region box block 0 2 0 1 0 1 units box",
                        "create_box 1 box"})
    e.input->one(c);
  const granary::Domain& d = *e.domain;
  // 3e6 + 0.25 lengths in x (2 each), -5e6 - 0.5 lengths in y: the loops of one
  // length per pass would take millions of passes, and at 1e300 never end
  granary::Vec3 x(2.0 * 3.0e6 + 0.5, -5.0e6 - 0.5, 0.5);
  int image = granary::Particles::image_pack(0, 0, 0);
  d.remap(x, image);
  CHECK(x[0] == Approx(0.5).margin(1e-8));
  CHECK(x[1] == Approx(0.5).margin(1e-8));
  CHECK(x[2] == 0.5);
  int ix, iy, iz;
  granary::Particles::image_unpack(image, ix, iy, iz);
  // image counts wrap at 10 bits: 3e6 = 2929 * 1024 + 704 -> 704 - 1024 = -320
  CHECK(ix == -320);
  CHECK(((iy % 1024) + 1024) % 1024 == ((-5000001 % 1024) + 1024) % 1024);
  CHECK(iz == 0);
  // at 1e300 the loops alone never end (x - 2 == x): the call returns, with the
  // particle placed in the box or, where the subtraction cannot place it, left
  granary::Vec3 far(1.0e300, 0.5, 0.5);
  d.remap(far, image);
  CHECK(((far[0] >= 0.0 && far[0] < 2.0) || far[0] == 1.0e300));
  // one length over: the same arithmetic as before (x - prd)
  granary::Vec3 one(2.3, 0.5, 0.5);
  image = granary::Particles::image_pack(0, 0, 0);
  d.remap(one, image);
  CHECK(one[0] == 2.3 - 2.0);
  granary::Particles::image_unpack(image, ix, iy, iz);
  CHECK(ix == 1);
}

TEST_CASE("create_atoms random respects the region and the overlap distance", "[particles]") {
  Sim s;
  s.cmds(kBox);
  s.cmds(
      {"region ball sphere 0.5 0.5 0.5 0.3", "create_atoms 1 random 100 4711 ball overlap 0.08 maxtry 1000"});
  CHECK(s.e.particles->natoms == 100);
  const auto x = gather_positions(s.e);
  REQUIRE(x.size() == 100);
  double dmin = 1e9;
  for (auto a = x.begin(); a != x.end(); ++a) {
    CHECK((a->second - Vec3(0.5, 0.5, 0.5)).norm() <= 0.3);
    for (auto b = std::next(a); b != x.end(); ++b)
      dmin = std::min(dmin, (a->second - b->second).norm());
  }
  CHECK(dmin >= 0.08);
  CHECK(x.begin()->first == 1);
  CHECK(x.rbegin()->first == 100);

  // same seed, same points; new ids follow the old ones
  Sim t;
  t.cmds(kBox);
  t.cmds(
      {"region ball sphere 0.5 0.5 0.5 0.3", "create_atoms 1 random 100 4711 ball overlap 0.08 maxtry 1000"});
  CHECK(gather_positions(t.e) == x);
  t.cmd("create_atoms 2 random 10 99 NULL");
  const auto y = gather_positions(t.e);
  CHECK(y.size() == 110);
  CHECK(y.rbegin()->first == 110);
}

TEST_CASE("group styles on a lattice", "[group]") {
  Sim s;
  s.cmds(kBox);
  s.cmds({"lattice sc 0.1", "create_atoms 1 box"});
  s.cmd("region half block 0 0.45 EDGE EDGE EDGE EDGE");
  s.cmd("group low region half");
  CHECK(s.count("low") == 500);
  s.cmd("set group low type 2");
  s.cmds({"group t2 type 2", "group t12 type 1*2", "group tlt type < 2", "group tne type != 1",
          "group trange type <> 2 3", "group tlist type 1 3"});
  CHECK(s.count("t2") == 500);
  CHECK(s.count("t12") == 1000);
  CHECK(s.count("tlt") == 500);
  CHECK(s.count("tne") == 500);
  CHECK(s.count("trange") == 500);
  CHECK(s.count("tlist") == 500);

  s.cmds({"group ids id 1*100", "group ids2 id <> 50 149", "group both intersect ids ids2",
          "group either union ids ids2", "group only subtract ids ids2", "group idl id 3 7 9*10"});
  CHECK(s.count("ids") == 100);
  CHECK(s.count("ids2") == 100);
  CHECK(s.count("both") == 51);
  CHECK(s.count("either") == 149);
  CHECK(s.count("only") == 49);
  CHECK(s.count("idl") == 4);
  CHECK_THROWS_AS(s.cmd("group idl2 id 3 >= 995"), InputError);  // a comparison stands alone

  // group assignments add to a group
  s.cmd("group ids id 901*910");
  CHECK(s.count("ids") == 110);

  // group functions
  auto& g = *s.e.groups;
  CHECK(g.mass(0) == Approx(1000 * M_PI / 6.0));
  CHECK(g.xcm(0).isApprox(Vec3(0.45, 0.45, 0.45)));
  CHECK(g.vcm(0).norm() == 0.0);
  Vec3 lo, hi;
  g.bounds(g.find("low"), lo, hi);
  CHECK(lo.isApprox(Vec3(0, 0, 0)));
  CHECK(hi.isApprox(Vec3(0.4, 0.9, 0.9)));
  s.cmd("region corner block 0 0.15 0 0.15 0 0.15");
  CHECK(g.count(0, s.region("corner")) == 8);
  CHECK(g.count(g.find("t2"), s.region("corner")) == 8);

  // clear, empty, delete
  s.cmd("group ids2 clear");
  CHECK(s.count("ids2") == 0);
  s.cmd("group none empty");
  CHECK(s.count("none") == 0);
  s.cmd("group none delete");
  CHECK(g.find("none") == -1);
  CHECK_THROWS_AS(s.cmd("group all delete"), InputError);
  CHECK_THROWS_AS(s.cmd("group all clear"), InputError);
  CHECK_THROWS_WITH(s.cmd("group x regoin half"), Contains("region"));
  CHECK_THROWS_WITH(s.cmd("group x region nowhere"), Contains("nowhere"));
  CHECK_THROWS_WITH(s.cmd("group x union nogroup"), Contains("nogroup"));
  CHECK(g.find("x") == -1);  // a failed command leaves no group behind
  CHECK_THROWS_WITH(s.cmd("group x intersect low"), Contains("two groups"));

  s.cmd("fix f low viscous 1.0");
  CHECK_THROWS_WITH(s.cmd("group low delete"), Contains("fix f"));
}

TEST_CASE("at most 32 groups", "[group]") {
  Sim s;
  s.cmds(kBox);
  for (int k = 1; k < granary::Groups::kMaxGroups; ++k)
    s.cmd("group g" + std::to_string(k) + " empty");
  CHECK_THROWS_WITH(s.cmd("group one_more empty"), Contains("32"));
  s.cmd("group g5 delete");
  s.cmd("group one_more empty");
  CHECK(s.e.groups->find("one_more") == 5);
}

TEST_CASE("set keywords follow LIGGGHTS for diameter, density and mass", "[particles]") {
  Sim s;
  s.cmds(kBox);
  s.cmds({"create_atoms 1 single 0.5 0.5 0.5", "create_atoms 1 single 0.2 0.5 0.5"});
  auto mass_of = [&](long long id) {
    const auto& p = *s.e.particles;
    double m = 0.0;
    for (int i = 0; i < p.nlocal; ++i)
      if (p.id[i] == id) m = p.rmass[i];
    double all = 0.0;
    MPI_Allreduce(&m, &all, 1, MPI_DOUBLE, MPI_SUM, s.e.world);
    return all;
  };
  const double v01 = 4.0 / 3.0 * M_PI * 1.0e-3;  // volume of a sphere of radius 0.1
  s.cmd("set atom 2 diameter 0.2");
  CHECK(mass_of(2) == Approx(v01 * 1.0));
  CHECK(mass_of(1) == Approx(M_PI / 6.0));
  s.cmd("set atom 2 density 2500");
  CHECK(mass_of(2) == Approx(v01 * 2500));
  s.cmd("set atom 2 mass 1");
  CHECK(mass_of(2) == Approx(1.0));
  s.cmd("set atom 2 diameter 0.2");  // mass follows the density again
  CHECK(mass_of(2) == Approx(v01 * 2500));
  s.cmd("set atom * vx 1 vy 2 vz 3 omega 4 5 6 x 0.7");
  s.cmd("set type 1 type 3");
  const auto& p = *s.e.particles;
  s.cmd("set group all omegax 7");
  for (int i = 0; i < p.nlocal; ++i)
    CHECK(p.omega[i] == Vec3(7, 5, 6));
  s.cmd("set group all omega 4 5 6");
  for (int i = 0; i < p.nlocal; ++i) {
    CHECK(p.v[i] == Vec3(1, 2, 3));
    CHECK(p.omega[i] == Vec3(4, 5, 6));
    CHECK(p.x[i][0] == 0.7);
    CHECK(p.type[i] == 3);
  }
  s.cmds({"variable d atom 0.1*id", "set atom * diameter v_d"});
  for (int i = 0; i < p.nlocal; ++i)
    CHECK(p.radius[i] == Approx(0.05 * p.id[i]));
  s.cmds({"variable vz equal 4.0", "velocity all set NULL v_vz NULL sum yes"});
  for (int i = 0; i < p.nlocal; ++i)
    CHECK(p.v[i] == Vec3(1, 6, 3));
  s.cmd("variable bad atom 1-id");
  CHECK_THROWS_WITH(s.cmd("set atom * diameter v_bad"), Contains("invalid"));
  CHECK_THROWS_WITH(s.cmd("set atom * diameter v_none"), Contains("none"));
  CHECK_THROWS_WITH(s.cmd("set atom 1 diameter -1"), Contains("positive"));
  CHECK_THROWS_WITH(s.cmd("set atom 1 diametre 1"), Contains("diameter"));
  CHECK_THROWS_WITH(s.cmd("set atom 1 type 7"), Contains("1..3"));
  CHECK_THROWS_WITH(s.cmd("set group nogroup vx 1"), Contains("nogroup"));
  CHECK_THROWS_WITH(s.cmd("set atom 1 omega 1 2"), Contains("3 value"));
}

TEST_CASE("set writes through the table of per-particle properties that dump and variables read",
          "[particles]") {
  Sim s;
  s.cmds(kBox);
  s.cmds({"create_atoms 1 single 0.5 0.5 0.5", "create_atoms 1 single 0.2 0.5 0.5"});
  const auto names = granary::settable_atom_property_names();
  // type mass density diameter x y z vx vy vz omegax omegay omegaz meso_rho
  CHECK(names.size() == 14);
  double value = 0.125;
  for (const std::string& name : names) {
    const granary::AtomProperty* prop = granary::find_atom_property(name);
    REQUIRE(prop);
    if (name == "meso_rho") {  // the SPH density: atom_style sph only (test_mpi_sph.cpp)
      CHECK_THROWS_WITH(s.cmd("set group all meso_rho 1000"), Contains("needs atom_style sph"));
      continue;
    }
    value += 0.25;  // a new value for each, exact in binary
    const double v = prop->check == granary::SetCheck::Type ? 2.0 : value;
    std::ostringstream cmd;
    cmd << "set group all " << name << " " << v;
    s.cmd(cmd.str());
    const auto& p = *s.e.particles;
    for (int i = 0; i < p.nlocal; ++i)
      CHECK(prop->value(s.e, i) == v);
  }
  // what follows from a size or a density: the mass at the particle's density
  const auto& p = *s.e.particles;
  s.cmds({"set group all density 1000", "set group all diameter 0.5"});
  for (int i = 0; i < p.nlocal; ++i)
    CHECK(p.rmass[i] == Approx(1000 * M_PI / 6 * 0.125).epsilon(1e-14));
  // the others are read-only, with a message saying so
  for (const char* ro : {"fx", "id", "xu", "ix", "radius", "tqz", "body"})
    CHECK_THROWS_WITH(s.cmd(std::string("set atom 1 ") + ro + " 1"), Contains("read-only"));
  CHECK_THROWS_WITH(s.cmd("set atom 1 mass 0"), Contains("positive"));
}

TEST_CASE("velocity set, ramp and zero", "[particles]") {
  Sim s;
  s.cmds(kBox);
  s.cmds({"lattice sc 0.25", "create_atoms 1 box"});  // 64 particles
  auto& g = *s.e.groups;
  s.cmd("velocity all set 1 NULL 2");
  CHECK(g.vcm(0).isApprox(Vec3(1, 0, 2)));
  s.cmd("velocity all set 1 1 NULL sum yes");
  CHECK(g.vcm(0).isApprox(Vec3(2, 1, 2)));
  s.cmd("velocity all zero linear");
  CHECK(g.vcm(0).norm() < 1e-12);

  // ramp vx from 0 to 1 over x in [0, 0.75]: mean over the 4 layers = 0.5
  s.cmd("velocity all ramp vx 0 1 x 0 0.75");
  CHECK(g.vcm(0).isApprox(Vec3(0.5, 0, 0)));

  // a rigid rotation about z is removed by zero angular, a translation is kept
  s.cmd("velocity all set 0.3 0 0");
  auto& p = *s.e.particles;
  const Vec3 c = g.xcm(0);
  for (int i = 0; i < p.nlocal; ++i)
    p.v[i] += Vec3(0, 0, 2).cross(p.x[i] - c);
  s.cmd("velocity all zero angular");
  for (int i = 0; i < p.nlocal; ++i)
    CHECK((p.v[i] - Vec3(0.3, 0, 0)).norm() < 1e-12);

  s.cmd("velocity all setAngular 0 0 5");
  for (int i = 0; i < p.nlocal; ++i)
    CHECK(p.omega[i] == Vec3(0, 0, 5));
  CHECK_THROWS_WITH(s.cmd("velocity all create 300 4711"), Contains("not supported"));
  CHECK_THROWS_WITH(s.cmd("velocity all set 1 2"), Contains("3 values"));
  CHECK_THROWS_WITH(s.cmd("velocity all zero spin"), Contains("linear or angular"));
}

TEST_CASE("delete_atoms group and region, with and without compress", "[particles]") {
  SECTION("compress yes (default) renumbers 1..N in the old order") {
    Sim s;
    s.cmds(kBox);
    s.cmds({"lattice sc 0.1", "create_atoms 1 box", "region half block 0 0.45 EDGE EDGE EDGE EDGE",
            "group low region half", "delete_atoms group low"});
    CHECK(s.e.particles->natoms == 500);
    const auto x = gather_positions(s.e);
    REQUIRE(x.size() == 500);
    CHECK(x.begin()->first == 1);
    CHECK(x.rbegin()->first == 500);
    for (const auto& kv : x)
      CHECK(kv.second[0] > 0.45);
  }
  SECTION("compress no keeps the ids") {
    Sim s;
    s.cmds(kBox);
    s.cmds({"lattice sc 0.1", "create_atoms 1 box", "region ball sphere 0.5 0.5 0.5 0.25",
            "delete_atoms region ball compress no"});
    const auto x = gather_positions(s.e);
    CHECK(x.rbegin()->first == 1000);
    for (const auto& kv : x)
      CHECK((kv.second - Vec3(0.5, 0.5, 0.5)).norm() > 0.25);
    s.cmd("create_atoms 2 single 0.5 0.5 0.5");  // next id after the largest
    CHECK(gather_positions(s.e).rbegin()->first == 1001);
    CHECK_THROWS_WITH(s.cmd("delete_atoms region nowhere"), Contains("nowhere"));
    CHECK_THROWS_WITH(s.cmd("delete_atoms group all compress maybe"), Contains("yes or no"));
  }
}
