// The fixes of atom_style sph (LIGGGHTS 3.8 names and syntax):
//
//   fix ID group sph/density/continuity          density from the continuity equation
//   fix ID group sph/density/corr shepard every N   Shepard filter of the density every N steps
//   fix ID group sph/density/summation           density as the kernel sum of the masses
//   fix ID group sph/pressure absolut B | relativ B rho0 | Tait B rho0 gamma   equation of state
//   fix ID group wall/region/sph region-ID r0 D  repulsive wall: a region's surface
//   fix ID group wall/sph xplane|yplane|zplane lo hi r0 D   repulsive planes (lo, hi or NULL)
//   fix ID group nve/sph/stationary              particles that do not move (boundary particles)
//
// Density and pressure live in the per-particle fields of atom_style sph
// (sph_rho, sph_p); the kernel and smoothing lengths are those of pair_style
// sph/artVisc/tensCorr. All density and pressure updates happen before the
// pair forces (pre_force, after the positions and velocities of the step and
// the ghosts are current), in the order the fixes were defined; a density fix
// forwards the new densities to the ghosts. fix nve/sph is fix nve's
// integration (fix_nve.cpp).
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "comm/comm.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/force.h"
#include "core/modify.h"
#include "core/registry.h"
#include "core/update.h"
#include "domain/domain.h"
#include "domain/region.h"
#include "fix/fix.h"
#include "neighbor/neighbor.h"
#include "pair/pair_sph.h"
#include "particles/particles.h"

namespace granary {

namespace {

const PairSph& sph_pair(const Engine& e, const std::string& who) {
  const auto* pair = dynamic_cast<const PairSph*>(e.force->pair.get());
  if (!pair)
    throw InputError(who + " needs pair_style sph/artVisc/tensCorr (its kernel and smoothing lengths)");
  return *pair;
}

bool is_density_fix(const std::string& style) {
  return style == "sph/density/continuity" || style == "sph/density/corr" || style == "sph/density/summation";
}

// drho_i/dt = sum_j m_j (v_i - v_j) . grad_i W_ij; rho_i advances by dt times
// the mean of the previous and the new rate
class FixSphDensityContinuity : public Fix {
 public:
  FixSphDensityContinuity(Engine& engine, const Args& args) : Fix(engine, args) {
    require_args(args, 3, 3, "fix ID group sph/density/continuity");
  }
  unsigned hooks() const override { return PRE_FORCE; }
  void init() override {
    const std::string who = "fix " + id + " sph/density/continuity";
    for (const auto& f : engine_.modify->fixes)
      if (f.get() != this && f->style == style)
        throw InputError(who + ": there can be only one fix sph/density/continuity (fix " + f->id + ")");
    pair_ = &sph_pair(engine_, who);
    rho_ = PairSph::field(engine_, "sph_rho", who);
    drho_ = PairSph::field(engine_, "sph_drho", who);
  }
  void pre_force() override {
    Particles& p = *engine_.particles;
    const Neighbor& list = *engine_.neighbor;
    std::vector<double>& rho = p.extras[rho_].data;
    double* drho = p.extras[drho_].data.data();
    const int nlocal = p.nlocal;
    // trapezoidal rule: half of the old rate now, half of the new one below
    const bool advance = !engine_.update->in_setup_forces;  // setup forces: the current state
    const double half_dt = 0.5 * engine_.update->dt;
    if (advance)
      for (int i = 0; i < nlocal; ++i)
        if (p.mask[i] & groupbit) rho[i] += half_dt * drho[i];
    for (int i = 0; i < nlocal; ++i)
      drho[i] = 0.0;
    const sph::Kernel kernel = pair_->kernel();
    pair_->for_each_pair(p, list, [&](int i, int j, double r2, double h) {
      if (r2 == 0.0) return;
      const double r = std::sqrt(r2);
      // (v_i - v_j) . grad_i W_ij, the same for j with i's mass
      const double s = (p.v[i] - p.v[j]).dot(p.x[i] - p.x[j]) * sph::kernel_dw(kernel, r, h) / r;
      drho[i] += p.rmass[j] * s;
      if (j < nlocal) drho[j] += p.rmass[i] * s;
    });
    if (advance)
      for (int i = 0; i < nlocal; ++i)
        if (p.mask[i] & groupbit) rho[i] += half_dt * drho[i];
    engine_.comm->forward_comm_field(rho, 1);
  }

 private:
  const PairSph* pair_ = nullptr;
  int rho_ = -1, drho_ = -1;
};

// rho_i = sum_j m_j W_ij / sum_j (m_j / rho_j) W_ij (j = i included), every N steps
class FixSphDensityCorr : public Fix {
 public:
  FixSphDensityCorr(Engine& engine, const Args& args) : Fix(engine, args) {
    const char* usage = "fix ID group sph/density/corr shepard every N";
    require_args(args, 6, 6, usage);
    if (args[3] != "shepard")
      throw InputError("fix " + id + " sph/density/corr: unknown filter '" + args[3] + "'; usage: " + usage);
    if (args[4] != "every")
      throw InputError("fix " + id + " sph/density/corr: expected 'every', got '" + args[4] +
                       "'; usage: " + usage);
    every_ = static_cast<int>(parse_int(args[5], "fix sph/density/corr every"));
    if (every_ < 1) throw InputError("fix " + id + " sph/density/corr: every must be positive");
  }
  unsigned hooks() const override { return PRE_FORCE; }
  void init() override {
    const std::string who = "fix " + id + " sph/density/corr";
    pair_ = &sph_pair(engine_, who);
    rho_ = PairSph::field(engine_, "sph_rho", who);
  }
  void pre_force() override {
    if (engine_.update->ntimestep % every_ != 0) return;
    Particles& p = *engine_.particles;
    const Neighbor& list = *engine_.neighbor;
    std::vector<double>& rho = p.extras[rho_].data;
    const int nlocal = p.nlocal;
    const sph::Kernel kernel = pair_->kernel();
    num_.assign(nlocal, 0.0);
    den_.assign(nlocal, 0.0);
    for (int i = 0; i < nlocal; ++i) {
      const double w0 = sph::kernel_w(kernel, 0.0, pair_->h(p.type[i]));
      num_[i] += p.rmass[i] * w0;
      den_[i] += p.rmass[i] / rho[i] * w0;
    }
    pair_->for_each_pair(p, list, [&](int i, int j, double r2, double h) {
      const double w = sph::kernel_w(kernel, std::sqrt(r2), h);
      num_[i] += p.rmass[j] * w;
      den_[i] += p.rmass[j] / rho[j] * w;
      if (j < nlocal) {
        num_[j] += p.rmass[i] * w;
        den_[j] += p.rmass[i] / rho[i] * w;
      }
    });
    for (int i = 0; i < nlocal; ++i)
      if ((p.mask[i] & groupbit) && den_[i] > 0.0) rho[i] = num_[i] / den_[i];
    engine_.comm->forward_comm_field(rho, 1);
  }

 private:
  const PairSph* pair_ = nullptr;
  int rho_ = -1, every_ = 1;
  std::vector<double> num_, den_;
};

// rho_i = sum_j m_j W_ij (j = i included), every step
class FixSphDensitySummation : public Fix {
 public:
  FixSphDensitySummation(Engine& engine, const Args& args) : Fix(engine, args) {
    require_args(args, 3, 3, "fix ID group sph/density/summation");
  }
  unsigned hooks() const override { return PRE_FORCE; }
  void init() override {
    const std::string who = "fix " + id + " sph/density/summation";
    pair_ = &sph_pair(engine_, who);
    rho_ = PairSph::field(engine_, "sph_rho", who);
  }
  void pre_force() override {
    Particles& p = *engine_.particles;
    const Neighbor& list = *engine_.neighbor;
    std::vector<double>& rho = p.extras[rho_].data;
    const int nlocal = p.nlocal;
    const sph::Kernel kernel = pair_->kernel();
    sum_.assign(nlocal, 0.0);
    for (int i = 0; i < nlocal; ++i)
      sum_[i] = p.rmass[i] * sph::kernel_w(kernel, 0.0, pair_->h(p.type[i]));
    pair_->for_each_pair(p, list, [&](int i, int j, double r2, double h) {
      const double w = sph::kernel_w(kernel, std::sqrt(r2), h);
      sum_[i] += p.rmass[j] * w;
      if (j < nlocal) sum_[j] += p.rmass[i] * w;
    });
    for (int i = 0; i < nlocal; ++i)
      if (p.mask[i] & groupbit) rho[i] = sum_[i];
    engine_.comm->forward_comm_field(rho, 1);
  }

 private:
  const PairSph* pair_ = nullptr;
  int rho_ = -1;
  std::vector<double> sum_;
};

// absolut: P = B rho; relativ: P = B (rho - rho0); Tait: P = B ((rho/rho0)^gamma - 1)
class FixSphPressure : public Fix {
 public:
  enum class Eos { Absolut, Relativ, Tait };
  FixSphPressure(Engine& engine, const Args& args) : Fix(engine, args) {
    const std::string usage = "fix ID group sph/pressure absolut B | relativ B rho0 | Tait B rho0 gamma";
    if (args.size() < 5)
      throw InputError("fix " + id + " sph/pressure needs a style and its values; usage: " + usage);
    const std::string& s = args[3];
    std::size_t n = 0;
    if (s == "absolut") {
      eos_ = Eos::Absolut, n = 1;
    } else if (s == "relativ") {
      eos_ = Eos::Relativ, n = 2;
    } else if (s == "Tait") {
      eos_ = Eos::Tait, n = 3;
    } else {
      throw InputError("fix " + id + " sph/pressure: unknown style '" + s + "'; usage: " + usage);
    }
    if (args.size() != 4 + n)
      throw InputError("fix " + id + " sph/pressure " + s + " takes " + std::to_string(n) +
                       " value(s), got " + std::to_string(args.size() - 4) + "; usage: " + usage);
    b_ = parse_double(args[4], "fix sph/pressure B");
    if (n > 1) rho0_ = parse_double(args[5], "fix sph/pressure density0");
    if (n > 2) gamma_ = parse_double(args[6], "fix sph/pressure gamma");
    if (n > 1 && !(rho0_ > 0.0))
      throw InputError("fix " + id + " sph/pressure: density0 must be positive, got '" + args[5] + "'");
  }
  unsigned hooks() const override { return PRE_FORCE; }
  void init() override {
    const std::string who = "fix " + id + " sph/pressure";
    rho_ = PairSph::field(engine_, "sph_rho", who);
    p_ = PairSph::field(engine_, "sph_p", who);
    // the pressure follows the density of the step: the density fixes come first
    bool seen_self = false, density = false;
    for (const auto& f : engine_.modify->fixes) {
      if (f.get() == this) seen_self = true;
      if (!is_density_fix(f->style)) continue;
      density = true;
      if (seen_self)
        throw InputError(who + " is defined before fix " + f->id + " " + f->style +
                         ": the pressure follows the density, so define the density fixes first");
    }
    if (!density)
      throw InputError(who +
                       " needs fix sph/density/continuity or sph/density/summation (the density it follows)");
  }
  void pre_force() override {
    Particles& p = *engine_.particles;
    const std::vector<double>& rho = p.extras[rho_].data;
    std::vector<double>& pres = p.extras[p_].data;
    const int n = p.size();  // ghosts too: their densities are current
    for (int i = 0; i < n; ++i) {
      if (!(p.mask[i] & groupbit)) continue;
      switch (eos_) {
        case Eos::Absolut:
          pres[i] = b_ * rho[i];
          break;
        case Eos::Relativ:
          pres[i] = b_ * (rho[i] - rho0_);
          break;
        case Eos::Tait:
          pres[i] = b_ * (std::pow(rho[i] / rho0_, gamma_) - 1.0);
          break;
      }
    }
  }

 private:
  Eos eos_ = Eos::Tait;
  double b_ = 0.0, rho0_ = 1.0, gamma_ = 1.0;
  int rho_ = -1, p_ = -1;
};

// The repulsive wall force of the SPH walls at distance r < r0 (Monaghan 1994):
// F = D ((r0/r)^4 - (r0/r)^2), pushing the particle away from the wall.
double wall_force(double r, double r0, double d) {
  const double q = r0 / r, q2 = q * q;
  return d * (q2 * q2 - q2);
}

class FixWallRegionSph : public Fix {
 public:
  FixWallRegionSph(Engine& engine, const Args& args) : Fix(engine, args) {
    require_args(args, 6, 6, "fix ID group wall/region/sph region-ID r0 D");
    region_id_ = args[3];
    engine.domain->region_or_error(region_id_, "fix " + id + " wall/region/sph");
    r0_ = parse_double(args[4], "fix wall/region/sph r0");
    d_ = parse_double(args[5], "fix wall/region/sph D");
    if (!(r0_ > 0.0))
      throw InputError("fix " + id + " wall/region/sph: r0 must be positive, got '" + args[4] + "'");
  }
  unsigned hooks() const override { return POST_FORCE; }
  void init() override {
    region_ = engine_.domain->region_or_error(region_id_, "fix " + id + " wall/region/sph");
    pair_ = &sph_pair(engine_, "fix " + id + " wall/region/sph");
  }
  void post_force() override {
    Particles& p = *engine_.particles;
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit)) continue;
      if (!region_->match(p.x[i]))
        throw RunError("fix " + id + " wall/region/sph: particle " + std::to_string(p.id[i]) +
                       " left region " + region_id_ + " (through its wall) at step " +
                       std::to_string(engine_.update->ntimestep) +
                       "; raise D or r0, or lower the timestep, so that the wall holds the particles");
      const double hi = pair_->h(p.type[i]);
      region_->surface(p.x[i], std::max(r0_, hi), points_);
      for (const Region::SurfacePoint& s : points_) {
        // the particle's clone at the wall point, closer than h: its pressure pushes back
        if (s.r < hi && s.r > 0.0) p.f[i] += pair_->clone_force(p, i, s.del);
        if (s.r >= r0_) continue;
        if (!(s.r > 0.0))
          throw RunError("fix " + id + " wall/region/sph: particle " + std::to_string(p.id[i]) +
                         " is on the surface of region " + region_id_ + " at step " +
                         std::to_string(engine_.update->ntimestep) +
                         "; start the particles farther than r0 from the wall, or raise D");
        p.f[i] += (wall_force(s.r, r0_, d_) / s.r) * s.del;
      }
    }
  }

 private:
  std::string region_id_;
  const Region* region_ = nullptr;
  const PairSph* pair_ = nullptr;
  double r0_ = 0.0, d_ = 0.0;
  std::vector<Region::SurfacePoint> points_;
};

class FixWallSph : public Fix {
 public:
  FixWallSph(Engine& engine, const Args& args) : Fix(engine, args) {
    const char* usage =
        "fix ID group wall/sph xplane|yplane|zplane lo hi r0 D   (lo, hi: a coordinate or NULL)";
    require_args(args, 8, 8, usage);
    const std::string& s = args[3];
    if (s != "xplane" && s != "yplane" && s != "zplane")
      throw InputError("fix " + id + " wall/sph: unknown wall style '" + s + "'; usage: " + usage);
    dim_ = s[0] - 'x';
    for (int k = 0; k < 2; ++k) {
      has_[k] = args[4 + k] != "NULL";
      if (has_[k]) plane_[k] = parse_double(args[4 + k], "fix wall/sph plane position");
    }
    if (!has_[0] && !has_[1])
      throw InputError("fix " + id + " wall/sph: lo and hi are both NULL; usage: " + usage);
    r0_ = parse_double(args[6], "fix wall/sph r0");
    d_ = parse_double(args[7], "fix wall/sph D");
    if (!(r0_ > 0.0)) throw InputError("fix " + id + " wall/sph: r0 must be positive, got '" + args[6] + "'");
  }
  unsigned hooks() const override { return POST_FORCE; }
  // each plane pushes particles on either side of it away from it
  void post_force() override {
    Particles& p = *engine_.particles;
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit)) continue;
      for (int k = 0; k < 2; ++k) {
        if (!has_[k]) continue;
        const double del = p.x[i][dim_] - plane_[k], r = std::fabs(del);
        if (r >= r0_) continue;
        if (!(r > 0.0))
          throw RunError("fix " + id + " wall/sph: particle " + std::to_string(p.id[i]) +
                         " is on the plane at step " + std::to_string(engine_.update->ntimestep) +
                         "; start the particles farther than r0 from the wall, or raise D");
        p.f[i][dim_] += wall_force(r, r0_, d_) * (del > 0.0 ? 1.0 : -1.0);
      }
    }
  }

 private:
  int dim_ = 0;
  bool has_[2] = {false, false};
  double plane_[2] = {0.0, 0.0};
  double r0_ = 0.0, d_ = 0.0;
};

// boundary particles: they take part in the density and the forces of their
// neighbours but neither move nor change velocity
class FixNveSphStationary : public Fix {
 public:
  FixNveSphStationary(Engine& engine, const Args& args) : Fix(engine, args) {
    require_args(args, 3, 3, "fix ID group nve/sph/stationary");
    time_integrate = true;
  }
  unsigned hooks() const override { return 0; }
  void init() override { PairSph::field(engine_, "sph_rho", "fix " + id + " nve/sph/stationary"); }
};

}  // namespace

GRANARY_FIX_STYLE("sph/density/continuity", FixSphDensityContinuity);
GRANARY_FIX_STYLE("sph/density/corr", FixSphDensityCorr);
GRANARY_FIX_STYLE("sph/density/summation", FixSphDensitySummation);
GRANARY_FIX_STYLE("sph/pressure", FixSphPressure);
GRANARY_FIX_STYLE("wall/region/sph", FixWallRegionSph);
GRANARY_FIX_STYLE("wall/sph", FixWallSph);
GRANARY_FIX_STYLE("nve/sph/stationary", FixNveSphStationary);

}  // namespace granary
