// Particle insertion: particletemplate/sphere, particledistribution/discrete,
// insert/pack and insert/rate/region.
//
// insert/pack reaches its target (volume fraction, number, mass) counting the
// particles already in the region, without overlaps and (all_in yes) with
// every particle wholly inside the region; a region too small for the request
// gives a warning with the number placed; the distribution's mass, number and
// volume fractions match their definitions; insert/rate/region inserts at its
// rate up to its total.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "script_engine.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/input.h"
#include "core/logger.h"
#include "fix/fix_insert_pack.h"
#include "fix/fix_insert_rate_region.h"
#include "fix/fix_particledistribution_discrete.h"
#include "core/modify.h"
#include "particles/particles.h"

using Catch::Matchers::Contains;
using granary::Engine;
using granary::InputError;
using granary::Vec3;

namespace {

struct Sim : granary::test::ScriptEngine {
  Sim() : ScriptEngine(MPI_COMM_WORLD) {}
};

struct Part {
  long long id;
  int type;
  Vec3 x, v;
  double r, m;
};

/// Every particle, on every rank, sorted by id.
std::vector<Part> gather(Engine& e) {
  const auto& p = *e.particles;
  std::vector<double> mine;
  for (int i = 0; i < p.nlocal; ++i) {
    mine.insert(mine.end(), {static_cast<double>(p.id[i]), static_cast<double>(p.type[i]), p.x[i][0],
                             p.x[i][1], p.x[i][2], p.v[i][0], p.v[i][1], p.v[i][2], p.radius[i], p.rmass[i]});
  }
  int n = static_cast<int>(mine.size());
  std::vector<int> counts(e.nprocs), displs(e.nprocs, 0);
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, e.world);
  for (int r = 1; r < e.nprocs; ++r)
    displs[r] = displs[r - 1] + counts[r - 1];
  std::vector<double> all(static_cast<std::size_t>(displs.back() + counts.back()));
  MPI_Allgatherv(mine.data(), n, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE, e.world);
  std::vector<Part> out;
  for (std::size_t k = 0; k + 9 < all.size(); k += 10) {
    out.push_back({static_cast<long long>(all[k]), static_cast<int>(all[k + 1]),
                   Vec3(all[k + 2], all[k + 3], all[k + 4]), Vec3(all[k + 5], all[k + 6], all[k + 7]),
                   all[k + 8], all[k + 9]});
  }
  std::sort(out.begin(), out.end(), [](const Part& a, const Part& b) { return a.id < b.id; });
  return out;
}

/// Smallest (distance - r_i - r_j) over all pairs (periodic images in x and y when asked).
double min_gap(const std::vector<Part>& ps, double px = 0.0, double py = 0.0) {
  double worst = 1e300;
  for (std::size_t i = 0; i < ps.size(); ++i) {
    for (std::size_t j = i + 1; j < ps.size(); ++j) {
      Vec3 d = ps[i].x - ps[j].x;
      if (px > 0) d[0] -= px * std::round(d[0] / px);
      if (py > 0) d[1] -= py * std::round(d[1] / py);
      worst = std::min(worst, d.norm() - ps[i].r - ps[j].r);
    }
  }
  return worst;
}

double sphere_volume(double r) {
  return 4.0 / 3.0 * M_PI * r * r * r;
}

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

const std::vector<std::string> kBox = {
    "units si",
    "atom_style granular",
    "boundary f f f",
    "newton off",
    "region box block -0.05 0.05 -0.05 0.05 0.0 0.15 units box",
    "create_box 2 box",
    "neighbor 0.002 bin",
    "neigh_modify delay 0",
    granary::test::materials(2, 5.e6, 0.45, 0.3, 0.5),
    "pair_style gran model hertz tangential history",
    "pair_coeff * *",
    "timestep 0.00001",
    "fix pts1 all particletemplate/sphere 15485863 atom_type 1 density constant 2500 radius constant 0.005",
    "fix pts2 all particletemplate/sphere 15485867 atom_type 2 density constant 2500 radius constant 0.008",
};

}  // namespace

TEST_CASE("insert/pack reaches the volume fraction without overlaps, all inside the region", "[insert]") {
  Sim s;
  s.cmds(kBox);
  s.cmds({"fix pdd1 all particledistribution/discrete 32452843 2 pts1 0.3 pts2 0.7",
          "region ins block -0.05 0.05 -0.05 0.05 0.0 0.1 units box",
          "fix ins all insert/pack seed 32452867 distributiontemplate pdd1 maxattempt 200 insert_every once "
          "overlapcheck yes all_in yes vel constant 0. 0. -0.1 region ins volumefraction_region 0.3",
          "run 1"});
  const auto ps = gather(s.e);
  // LIGGGHTS 3.8 inserts 270 particles for this input (mean volume 1.1125e-6 m^3)
  REQUIRE(ps.size() >= 265);
  REQUIRE(ps.size() <= 275);
  CHECK(s.e.fix_value("ins", 1) == static_cast<double>(ps.size()));
  double vol = 0.0, mass = 0.0;
  for (const auto& p : ps) {
    vol += sphere_volume(p.r);
    mass += p.m;
    CHECK(p.v[2] == Approx(-0.1));
    CHECK(p.type == (p.r < 0.006 ? 1 : 2));
    // all_in: the whole sphere in the block
    for (int d = 0; d < 2; ++d) {
      CHECK(p.x[d] - p.r >= -0.05);
      CHECK(p.x[d] + p.r <= 0.05);
    }
    CHECK(p.x[2] - p.r >= 0.0);
    CHECK(p.x[2] + p.r <= 0.1);
  }
  CHECK(s.e.fix_value("ins", 2) == Approx(mass).epsilon(1e-12));
  // documented tolerance: two volumes of the largest particle
  const double phi = vol / 1e-3;
  CHECK(std::fabs(phi - 0.3) <= 2.0 * sphere_volume(0.008) / 1e-3);
  CHECK(min_gap(ps) >= -1e-15);
  // the mass fractions of the two templates are those asked for (exact distribution)
  double m1 = 0.0;
  for (const auto& p : ps)
    m1 += p.type == 1 ? p.m : 0.0;
  CHECK(m1 / mass == Approx(0.3).margin(0.02));
  // ids are 1..N
  CHECK(ps.front().id == 1);
  CHECK(ps.back().id == static_cast<long long>(ps.size()));
}

TEST_CASE("insert/pack with all_in keeps whole spheres inside a cylinder", "[insert]") {
  Sim s;
  s.cmds(kBox);
  s.cmds({"fix pdd1 all particledistribution/discrete 32452843 1 pts1 1.0",
          "region cyl cylinder z 0.0 0.0 0.03 0.01 0.06 units box",
          "fix ins all insert/pack seed 1001 distributiontemplate pdd1 maxattempt 500 insert_every once "
          "all_in yes region cyl volumefraction_region 0.25",
          "run 1"});
  const auto ps = gather(s.e);
  REQUIRE(ps.size() > 50);
  double vol = 0.0;
  for (const auto& p : ps) {
    vol += sphere_volume(p.r);
    CHECK(std::hypot(p.x[0], p.x[1]) + p.r <= 0.03 + 1e-15);
    CHECK(p.x[2] - p.r >= 0.01);
    CHECK(p.x[2] + p.r <= 0.06);
  }
  CHECK(min_gap(ps) >= -1e-15);
  const double vregion = M_PI * 0.03 * 0.03 * 0.05;
  CHECK(std::fabs(vol / vregion - 0.25) <= 2.0 * sphere_volume(0.005) / vregion);
}

TEST_CASE("insert/pack refuses a particle count no machine holds, with the estimate", "[insert]") {
  Sim s;
  s.cmds(kBox);
  s.cmds({"fix pdd1 all particledistribution/discrete 32452843 1 pts1 1.0",
          "region ins block -0.05 0.05 -0.05 0.05 0.0 0.1 units box",
          "fix ins1 all insert/pack seed 4711 distributiontemplate pdd1 insert_every once region ins "
          "particles_in_region 1000000000000"});
  CHECK_THROWS_WITH(s.cmd("run 1"),
                    Catch::Contains("fix ins1 insert/pack: 1e+12 particles would need about"));
  CHECK(gather(s.e).empty());
}

// Particles inserted during a run are checked against the timestep too: the
// box starts empty (nothing to check at setup); the 5 mm beads (Y = 5 MPa,
// nu = 0.45) have a Rayleigh time of 6.3e-4 s, shorter than dt = 1e-3 s, so the
// run stops once they appear.
TEST_CASE("inserted particles whose Rayleigh time is below the timestep stop the run", "[insert]") {
  const double r = 0.005, rho = 2500, Y = 5e6, nu = 0.45, pi = 3.14159265358979323846;
  const double t_rayleigh = pi * r * std::sqrt(rho / (Y / (2 * (1 + nu)))) / (0.1631 * nu + 0.8766);
  REQUIRE(t_rayleigh == Approx(6.3e-4).epsilon(0.01));
  Sim s;
  s.cmds(kBox);
  s.cmds({"timestep 1e-3", "fix pdd1 all particledistribution/discrete 32452843 1 pts1 1.0",
          "region ins block -0.05 0.05 -0.05 0.05 0.0 0.1 units box",
          "fix ins1 all insert/pack seed 4711 distributiontemplate pdd1 insert_every once region ins "
          "particles_in_region 10"});
  char expected[128];
  std::snprintf(expected, sizeof expected, "timestep 0.001 s is longer than the Rayleigh time %g s",
                t_rayleigh);
  CHECK_THROWS_AS(s.cmd("run 10"), granary::RunError);
  s.cmd("timestep 1e-3");  // the same timestep: the check is made again at the next run's setup
  CHECK_THROWS_WITH(s.cmd("run 10"), Catch::Contains(expected));
}

TEST_CASE("insert/pack counts the particles already in the region", "[insert]") {
  Sim s;
  s.cmds(kBox);
  s.cmds({"fix pdd1 all particledistribution/discrete 32452843 1 pts1 1.0",
          "region ins block -0.05 0.05 -0.05 0.05 0.0 0.1 units box",
          "fix ins1 all insert/pack seed 4711 distributiontemplate pdd1 insert_every once region ins "
          "particles_in_region 40",
          "run 1", "unfix ins1"});
  REQUIRE(gather(s.e).size() == 40);
  // a second fill counts the 40 particles there and avoids them
  s.cmds(
      {"fix ins2 all insert/pack seed 4713 distributiontemplate pdd1 insert_every once region ins "
       "particles_in_region 100",
       "run 1"});
  auto ps = gather(s.e);
  CHECK(ps.size() == 100);
  CHECK(s.e.fix_value("ins2", 1) == 60.0);
  CHECK(min_gap(ps) >= -1e-15);
  CHECK(ps.back().id == 100);  // ids continue after the existing ones
  s.cmd("unfix ins2");

  // mass target: the mass in the region is within one particle mass of it
  const double m1 = 2500.0 * sphere_volume(0.005);
  s.cmds(
      {"fix ins3 all insert/pack seed 4717 distributiontemplate pdd1 insert_every once region ins "
       "mass_in_region 0.3",
       "run 1"});
  ps = gather(s.e);
  double mass = 0.0;
  for (const auto& p : ps)
    mass += p.m;
  CHECK(std::fabs(mass - 0.3) < m1);
  CHECK(ps.size() > 100);
  CHECK(min_gap(ps) >= -1e-15);
}

TEST_CASE("insert/pack warns with the number placed when the region is too small", "[insert]") {
  const std::string log = "insertion_too_small.log";
  long long placed = 0;
  {
    Sim s;
    s.e.logger->open_log(log, false);
    s.cmds(kBox);
    s.cmds({"fix pdd1 all particledistribution/discrete 32452843 1 pts1 1.0",
            "region tiny block 0.0 0.03 0.0 0.03 0.0 0.03 units box",
            "fix ins all insert/pack seed 4711 distributiontemplate pdd1 insert_every once all_in yes region "
            "tiny "
            "particles_in_region 100",
            "run 1"});
    const auto ps = gather(s.e);
    placed = static_cast<long long>(ps.size());
    CHECK(placed > 5);
    CHECK(placed < 100);
    CHECK(min_gap(ps) >= -1e-15);
    s.e.logger->close_log();
  }
  const std::string text = read_file(log);
  CHECK_THAT(text, Contains("WARNING"));
  CHECK_THAT(text, Contains("placed only " + std::to_string(placed) + " of the 100 particles"));
  CHECK_THAT(text, Contains("INFO: fix ins (insert/pack) inserted " + std::to_string(placed) +
                            " particles (target 100)"));
  std::remove(log.c_str());
}

TEST_CASE("insert/pack avoids primitive walls", "[insert]") {
  Sim s;
  s.cmds(kBox);
  s.cmds({"fix pdd1 all particledistribution/discrete 32452843 1 pts1 1.0",
          "fix mid all wall/gran model hertz tangential history primitive type 1 zplane 0.05",
          "fix tube all wall/gran model hertz tangential history primitive type 1 zcylinder 0.04 0.0 0.0",
          "region ins block -0.05 0.05 -0.05 0.05 0.0 0.1 units box",
          "fix ins all insert/pack seed 77 distributiontemplate pdd1 insert_every once region ins "
          "volumefraction_region 0.2",
          "run 1"});
  const auto ps = gather(s.e);
  REQUIRE(ps.size() > 100);
  int crossing_before = 0;
  for (const auto& p : ps) {
    CHECK(std::fabs(p.x[2] - 0.05) >= p.r);
    CHECK(std::fabs(std::hypot(p.x[0], p.x[1]) - 0.04) >= p.r);
    crossing_before += std::fabs(p.x[2] - 0.05) < 0.02;
  }
  CHECK(crossing_before > 0);  // particles close to the wall exist, none touch it
}

TEST_CASE("particledistribution/discrete: mass, number and volume fractions", "[insert]") {
  Sim s;
  s.cmds(kBox);
  // two templates whose mass and volume fractions differ (different densities)
  s.cmds({"fix a all particletemplate/sphere 10007 atom_type 1 density constant 2500 radius constant 0.001",
          "fix b all particletemplate/sphere 10009 atom_type 2 density constant 1000 radius constant 0.002"});
  const double va = sphere_volume(0.001), vb = sphere_volume(0.002);
  const double ma = 2500 * va, mb = 1000 * vb;
  const char* modes[] = {"mass", "number", "volume"};
  for (const char* mode : modes) {
    s.cmd(std::string("fix d all particledistribution/discrete 15485863 2 a 0.3 b 0.7 fractions ") + mode);
    auto* d = dynamic_cast<granary::FixParticleDistributionDiscrete*>(s.e.modify->find_fix("d"));
    REQUIRE(d);
    const auto p = d->number_probabilities();
    // the definitions
    const std::string m = mode;
    if (m == "mass") CHECK(p[0] * ma / (p[0] * ma + p[1] * mb) == Approx(0.3).epsilon(1e-12));
    if (m == "number") CHECK(p[0] == Approx(0.3).epsilon(1e-12));
    if (m == "volume") CHECK(p[0] * va / (p[0] * va + p[1] * vb) == Approx(0.3).epsilon(1e-12));
    CHECK(d->mean_volume() == Approx(p[0] * va + p[1] * vb));
    CHECK(d->mean_mass() == Approx(p[0] * ma + p[1] * mb));
    // independent draws: the share of template a within 3 sigma
    const int n = 20000;
    int na = 0;
    double mass_a = 0.0, mass = 0.0, vol_a = 0.0, vol = 0.0;
    for (int k = 0; k < n; ++k) {
      const auto t = d->draw();
      const bool is_a = t.type == 1;
      na += is_a;
      mass += t.mass;
      vol += t.volume;
      mass_a += is_a ? t.mass : 0.0;
      vol_a += is_a ? t.volume : 0.0;
    }
    const double sigma = std::sqrt(p[0] * (1 - p[0]) / n);
    INFO("fractions " << mode << ": share of a " << static_cast<double>(na) / n << ", expected " << p[0]);
    CHECK(std::fabs(static_cast<double>(na) / n - p[0]) < 3 * sigma);
    // the drawn fraction in the distribution's own measure, within 3 sigma
    // (delta method: d f / d share = f (1 - f) / (share (1 - share)))
    const double share = static_cast<double>(na) / n;
    const double f = m == "mass" ? mass_a / mass : m == "volume" ? vol_a / vol : share;
    const double sf = 0.3 * 0.7 / (p[0] * (1 - p[0])) * sigma;
    CHECK(std::fabs(f - 0.3) < 3 * sf);
    // exact batches: counts are n p rounded, largest first
    const auto batch = d->draw_batch(1001, true);
    REQUIRE(batch.size() == 1001);
    long long ca = 0;
    for (const auto& b : batch)
      ca += b.particle.type == 1;
    CHECK(std::fabs(static_cast<double>(ca) - 1001 * p[0]) < 1.0);
    CHECK(batch.front().particle.radii[0] == 0.002);  // the larger template first
    s.cmd("unfix d");
  }
  // weights that do not sum to 1 are normalised; wrong input is refused
  s.cmd("fix d all particledistribution/discrete 15485863 2 a 3 b 7 fractions number");
  auto* d = dynamic_cast<granary::FixParticleDistributionDiscrete*>(s.e.modify->find_fix("d"));
  CHECK(d->weights()[0] == Approx(0.3));
  s.cmd("fix dn all particledistribution/discrete/numberbased 15485863 2 a 0.3 b 0.7");
  d = dynamic_cast<granary::FixParticleDistributionDiscrete*>(s.e.modify->find_fix("dn"));
  CHECK(d->fractions() == granary::FixParticleDistributionDiscrete::Fractions::Number);
  REQUIRE_THROWS_WITH(s.cmd("fix e all particledistribution/discrete 15485863 2 a 0.3 c 0.7"),
                      Contains("unknown particle template 'c'"));
  REQUIRE_THROWS_WITH(s.cmd("fix e all particledistribution/discrete 15485863 2 a 0.3 m1 0.7"),
                      Contains("not a particle template"));
  REQUIRE_THROWS_WITH(s.cmd("fix e all particledistribution/discrete 15485863 2 a 0.3 b 0.7 fractions area"),
                      Contains("mass, number or volume"));
  REQUIRE_THROWS_WITH(s.cmd("fix e all particletemplate/sphere 10007 atom_type 3 radius constant 0.001"),
                      Contains("outside 1..2"));
}

TEST_CASE("particletemplate/sphere with a uniform radius", "[insert]") {
  Sim s;
  s.cmds(kBox);
  s.cmd("fix u all particletemplate/sphere 10007 density constant 2000 radius uniform 0.001 0.002");
  auto* t = dynamic_cast<granary::FixParticleTemplate*>(s.e.modify->find_fix("u"));
  REQUIRE(t);
  const int n = 20000;
  double vsum = 0.0, rmin = 1, rmax = 0;
  for (int k = 0; k < n; ++k) {
    const auto p = t->draw();
    vsum += p.volume;
    rmin = std::min(rmin, p.radii[0]);
    rmax = std::max(rmax, p.radii[0]);
    CHECK(p.mass == Approx(2000 * p.volume));
  }
  CHECK(rmin >= 0.001);
  CHECK(rmax <= 0.002);
  CHECK(vsum / n == Approx(t->mean_volume()).epsilon(0.01));
  CHECK(t->max_bounding_radius() == 0.002);
}

TEST_CASE("insert/rate/region inserts at the given rate up to its total", "[insert]") {
  Sim s;
  s.cmds(kBox);
  s.cmds(
      {"timestep 0.0001", "fix pdd1 all particledistribution/discrete 32452843 1 pts1 1.0",
       "region ins block -0.04 0.04 -0.04 0.04 0.08 0.14 units box",
       "fix grav all gravity 9.81 vector 0 0 -1",
       "fix zwall all wall/gran model hertz tangential history primitive type 1 zplane 0.0",
       "fix integr all nve/sphere",
       // 2460 particles/s * 5 steps * 1e-4 s = 1.23 particles per batch
       "fix ins all insert/rate/region seed 5003 distributiontemplate pdd1 nparticles 30 particlerate 2460 "
       "insert_every 5 vel constant 0 0 -1 region ins",
       "run 100"});
  // batches at steps 1, 6, ..., 96: 20 batches, floor(20 * 1.23) = 24 particles
  auto ps = gather(s.e);
  CHECK(ps.size() == 24);
  CHECK(s.e.fix_value("ins", 1) == 24.0);
  s.cmd("run 100");
  ps = gather(s.e);
  CHECK(ps.size() == 30);  // stopped at nparticles
  CHECK(s.e.fix_value("ins", 1) == 30.0);
  for (const auto& p : ps)
    CHECK(p.v[2] < -0.9);       // moving down, none lost
  CHECK(min_gap(ps) >= -1e-4);  // barely touching if at all while falling apart

  // massrate: the same batches when the rate is given as mass
  Sim m;
  m.cmds(kBox);
  const double mass1 = 2500 * sphere_volume(0.005);
  char line[512];
  std::snprintf(line, sizeof line,
                "fix ins all insert/rate/region seed 5003 distributiontemplate pdd1 mass INF massrate %.17g "
                "insert_every 5 region ins",
                2460 * mass1);
  m.cmds({"timestep 0.0001", "fix pdd1 all particledistribution/discrete 32452843 1 pts1 1.0",
          "region ins block -0.04 0.04 -0.04 0.04 0.08 0.14 units box", line, "run 100"});
  CHECK(gather(m.e).size() == 24);
}

namespace {

/// A bed poured by insert/pack (periodic in x and y) settles for 400 steps,
/// then runs 100 more, optionally while insert/rate/region feeds particles far
/// above it. Returns the bed particles (ids 1..N) at the end.
std::vector<Part> bed_with_feed(bool feed) {
  Sim s;
  s.cmds(
      {"units si",
       "atom_style granular",
       "boundary p p f",
       "newton off",
       "region box block 0 0.02 0 0.02 0 0.08 units box",
       "create_box 1 box",
       "neighbor 0.0006 bin",
       "neigh_modify delay 0",
       granary::test::materials(1, 5.e6, 0.45, 0.3, 0.5),
       "pair_style gran model hertz tangential history",
       "pair_coeff * *",
       "timestep 2e-5",
       "fix pts all particletemplate/sphere 15485863 atom_type 1 density constant 2500 radius constant 0.001",
       "fix pdd all particledistribution/discrete 32452843 1 pts 1.0",
       "region bed block 0 0.02 0 0.02 0.0 0.008 units box",
       "fix grav all gravity 9.81 vector 0 0 -1",
       "fix zwall all wall/gran model hertz tangential history primitive type 1 zplane 0.0",
       "fix integr all nve/sphere",
       "fix ins all insert/pack seed 32452867 distributiontemplate pdd insert_every once vel constant 0 0 "
       "-0.5 "
       "region bed volumefraction_region 0.3",
       "run 400",
       "unfix ins",
       "region top block 0 0.02 0 0.02 0.06 0.075 units box"});
  if (feed) {
    s.cmd(
        "fix feed all insert/rate/region seed 15485927 distributiontemplate pdd nparticles INF "
        "particlerate 20000 insert_every 10 vel constant 0 0 -0.5 region top");
  }
  s.cmd("run 100");
  auto ps = gather(s.e);
  if (feed) {
    // batches at steps 401, 411, ..., 491: 10 batches of 4 particles
    const long long bed = static_cast<long long>(ps.size()) - 40;
    CHECK(s.e.fix_value("feed", 1) == 40.0);
    ps.resize(static_cast<std::size_t>(bed));
  }
  return ps;
}

}  // namespace

TEST_CASE("insertion during a run leaves the contacts of existing particles intact", "[insert]") {
  // New particles are added while ghosts (periodic images here) and the
  // contact history of the last neighbour build exist; the bed must move
  // exactly as without them.
  const auto with = bed_with_feed(true);
  const auto without = bed_with_feed(false);
  REQUIRE(with.size() == without.size());
  REQUIRE(with.size() > 100);
  double worst = 0.0;
  for (std::size_t k = 0; k < with.size(); ++k) {
    REQUIRE(with[k].id == without[k].id);
    worst = std::max(worst, (with[k].x - without[k].x).norm());
    worst = std::max(worst, (with[k].v - without[k].v).norm() * 1e-3);
  }
  CHECK(worst < 1e-13);
}

TEST_CASE("insert/pack tops the region up every N steps", "[insert]") {
  Sim s;
  s.cmds(kBox);
  s.cmds({"timestep 0.0001", "fix pdd1 all particledistribution/discrete 32452843 1 pts1 1.0",
          "region ins block -0.04 0.04 -0.04 0.04 0.10 0.14 units box", "fix integr all nve/sphere",
          "fix ins all insert/pack seed 5003 distributiontemplate pdd1 insert_every 50 vel constant 0 0 -2 "
          "region ins particles_in_region 20",
          "run 120"});
  // insertions at steps 1, 51 and 101; particles leave the region at 2 m/s
  // (0.01 m per 50 steps), so later insertions top it up to 20 again
  const auto ps = gather(s.e);
  CHECK(ps.size() > 20);
  CHECK(s.e.fix_value("ins", 1) == static_cast<double>(ps.size()));
  int in_region = 0;
  for (const auto& p : ps)
    in_region += p.x[2] >= 0.10;
  CHECK(in_region <= 20);
}

namespace {

std::vector<std::string> feed_physics() {
  return {"neighbor 0.0005 bin",
          "neigh_modify delay 0",
          granary::test::materials(2, 5.e6, 0.45, 0.5, 0.5),
          "pair_style gran model hertz tangential history",
          "pair_coeff * *",
          "timestep 2e-5",
          "fix grav all gravity 9.81 vector 0 0 -1",
          "fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.0",
          "fix integr all nve/sphere",
          "fix a all particletemplate/sphere 10007 atom_type 1 density constant 2500 radius uniform 0.0008 "
          "0.0012",
          "fix b all particletemplate/sphere 10009 atom_type 2 density constant 2500 radius constant 0.0015",
          "fix pdd all particledistribution/discrete 15485863 2 a 0.5 b 0.5",
          "region top block 0 0.02 0 0.02 0.02 0.035 units box",
          "fix feed all insert/rate/region seed 15485927 distributiontemplate pdd nparticles 150 "
          "particlerate 14000 "
          "insert_every 20 vel uniform 0 0 -0.5 0.1 0.1 0.1 region top"};
}

}  // namespace

TEST_CASE("insertion continues across a restart as without it", "[insert]") {
  std::vector<Part> straight, restarted;
  {
    Sim s;
    s.cmds({"units si", "atom_style granular", "boundary p p f",
            "region box block 0 0.02 0 0.02 0 0.04 units box", "create_box 2 box"});
    s.cmds(feed_physics());
    s.cmds({"run 300", "write_restart insertion.restart", "run 300"});
    straight = gather(s.e);
    CHECK(s.e.fix_value("feed", 1) == 150.0);  // the total was reached
  }
  {
    Sim s;
    s.cmds({"atom_style granular", "read_restart insertion.restart"});
    s.cmds(feed_physics());
    s.cmd("run 300");
    restarted = gather(s.e);
    CHECK(s.e.fix_value("feed", 1) == 150.0);
  }
  std::remove("insertion.restart");
  REQUIRE(straight.size() == 150);
  REQUIRE(restarted.size() == straight.size());
  double worst = 0.0;
  for (std::size_t k = 0; k < straight.size(); ++k) {
    REQUIRE(restarted[k].id == straight[k].id);
    CHECK(restarted[k].r == straight[k].r);
    worst = std::max(worst, (restarted[k].x - straight[k].x).norm());
  }
  CHECK(worst == 0.0);
}

TEST_CASE("the insertion schedule moves with reset_timestep, also after read_restart", "[insert][restart]") {
  // batches every 20 steps from step 1: after 30 steps the next is due at 41,
  // 11 steps after the restart step; after reset_timestep 1000 it is due at 1011
  double n30 = 0.0, n41 = 0.0;
  {
    Sim s;
    s.cmds({"units si", "atom_style granular", "boundary p p f",
            "region box block 0 0.02 0 0.02 0 0.04 units box", "create_box 2 box"});
    s.cmds(feed_physics());
    s.cmds({"run 30", "write_restart schedule.restart"});
    n30 = s.e.fix_value("feed", 1);
    // a restart file written after reset_timestep (and the counter set back)
    s.cmds({"reset_timestep 1000", "write_restart schedule_reset.restart", "reset_timestep 30"});
    s.cmd("run 11");
    n41 = s.e.fix_value("feed", 1);
  }
  REQUIRE(n41 > n30);
  for (const int when : {0, 1, 2}) {
    // reset_timestep after the fix is defined again (0), before it (1: its
    // state waits in the restart data), or before the file was written (2)
    Sim s;
    s.cmds({"atom_style granular",
            std::string("read_restart ") + (when == 2 ? "schedule_reset.restart" : "schedule.restart")});
    if (when == 1) s.cmd("reset_timestep 1000");
    s.cmds(feed_physics());
    if (when == 0) s.cmds({"reset_timestep 0", "reset_timestep 1000"});
    s.cmd("run 10");
    CHECK(s.e.fix_value("feed", 1) == n30);
    s.cmd("run 1");
    CHECK(s.e.fix_value("feed", 1) == n41);
  }
  std::remove("schedule.restart");
  std::remove("schedule_reset.restart");
}

TEST_CASE("insertion input errors", "[insert]") {
  Sim s;
  s.cmds(kBox);
  s.cmds({"fix pdd1 all particledistribution/discrete 32452843 1 pts1 1.0",
          "region ins block -0.04 0.04 -0.04 0.04 0.08 0.14 units box"});
  REQUIRE_THROWS_WITH(
      s.cmd("fix ins all insert/pack distributiontemplate pdd1 region ins particles_in_region 5"),
      Contains("seed"));
  REQUIRE_THROWS_WITH(
      s.cmd("fix ins all insert/pack seed 5 distributiontemplate pdx region ins particles_in_region 5"),
      Contains("pdx is not defined"));
  REQUIRE_THROWS_WITH(
      s.cmd("fix ins all insert/pack seed 5 distributiontemplate pdd1 region ins particles_in_region 5 "
            "mass_in_region 2"),
      Contains("exactly one"));
  REQUIRE_THROWS_WITH(
      s.cmd("fix ins all insert/pack seed 5 distributiontemplate pdd1 region ins volumefraction_region 5"),
      Contains("between 0 and 1"));
  REQUIRE_THROWS_WITH(
      s.cmd("fix ins all insert/pack seed 5 distributiontemplate pdd1 region ins particles_in_region 5 "
            "overlap_check yes"),
      Contains("overlapcheck"));
  REQUIRE_THROWS_WITH(
      s.cmd("fix ins all insert/rate/region seed 5 distributiontemplate pdd1 region ins nparticles 5 "
            "particlerate 10"),
      Contains("insert_every"));
  REQUIRE_THROWS_WITH(s.cmd("fix ins all insert/rate/region seed 5 distributiontemplate pdd1 region ins "
                            "particlerate 10 insert_every 10"),
                      Contains("nparticles"));
}
