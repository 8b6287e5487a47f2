// pair_style sph/artVisc/tensCorr (see pair_sph.h).
#include "pair/pair_sph.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/engine.h"
#include "core/error.h"
#include "core/force.h"
#include "core/global_property.h"
#include "core/logger.h"
#include "core/modify.h"
#include "core/registry.h"
#include "core/update.h"
#include "neighbor/neighbor.h"

namespace granary {

namespace {

const char* const kUsage =
    "pair_style sph/artVisc/tensCorr cubicspline|cubicspline2d|wendland|wendland2d h "
    "[artVisc [alpha beta eta]] [tensCorr [epsilon deltap]]";

}  // namespace

PairSph::PairSph(Engine& engine, const Args& args) : Pair(engine, args) {
  style = "sph/artVisc/tensCorr";
  if (args.size() < 2) throw InputError("pair_style " + style + " needs a kernel and h; usage: " + kUsage);
  if (!sph::kernel_from_name(args[0], kernel_))
    throw InputError("pair_style " + style + ": unknown kernel '" + args[0] + "'; expected " +
                     sph::kernel_names());
  h_arg_ = parse_double(args[1], "pair_style " + style + " h");
  if (!(h_arg_ > 0.0))
    throw InputError("pair_style " + style + ": h must be positive, got '" + args[1] + "'");
  for (std::size_t k = 2; k < args.size();) {
    const std::string& w = args[k];
    const std::size_t nvalues = w == "artVisc" ? 3 : w == "tensCorr" ? 2 : 0;
    if (nvalues == 0)
      throw InputError("pair_style " + style + ": unknown keyword '" + w +
                       "'; expected artVisc or tensCorr; usage: " + kUsage);
    std::vector<double>& values = w == "artVisc" ? artvisc_args_ : tenscorr_args_;
    (w == "artVisc" ? artvisc_ : tenscorr_) = true;
    ++k;
    // values on the line, or none (then fix property/global gives them)
    if (k < args.size() && is_number(args[k])) {
      if (k + nvalues > args.size())
        throw InputError("pair_style " + style + " " + w + " takes " + std::to_string(nvalues) +
                         " values or none (then fix property/global gives them); usage: " + kUsage);
      for (std::size_t m = 0; m < nvalues; ++m)
        values.push_back(parse_double(args[k + m], "pair_style " + style + " " + w));
      k += nvalues;
    }
  }
}

void PairSph::coeff(const Args& args) {
  require_args(args, 2, 3, "pair_coeff * *");
  int lo, hi;
  const int n = engine_.particles->ntypes;
  for (int k = 0; k < 2; ++k) {
    parse_type_range(args[k], n, lo, hi);
    if (lo != 1 || hi != n)
      throw InputError("pair_style " + style +
                       " takes its parameters for all types at once; use pair_coeff * *");
  }
  if (args.size() == 3 && args[2] != style)
    throw InputError("pair_coeff * * takes no parameters for pair_style " + style + ", got '" + args[2] +
                     "'");
  coeff_set_ = true;
}

int PairSph::field(const Engine& engine, const char* name, const std::string& who) {
  const int k = engine.particles->find_field(name);
  if (k < 0 || !engine.particles->sph) throw InputError(who + " needs atom_style sph");
  return k;
}

void PairSph::init() {
  const std::string who = "pair_style " + style;
  if (!coeff_set_) throw InputError(who + " needs 'pair_coeff * *' before run");
  rho_ = field(engine_, "sph_rho", who);
  p_ = field(engine_, "sph_p", who);
  if (engine_.force->newton_pair)
    throw InputError(who + " needs 'newton off' (each rank computes the forces of its own particles)");
  Particles& p = *engine_.particles;
  const int nt = p.ntypes;
  const Modify& modify = *engine_.modify;
  std::vector<double> h, c(nt + 1, 0.0), alpha(nt + 1, 0.0), beta(nt + 1, 0.0), deltap(nt + 1, 0.0);
  auto per_type = [&](const char* name, std::vector<double>& out) {
    const GlobalProperty& g = modify.require_property(name, who);
    out.assign(nt + 1, 0.0);
    for (int t = 1; t <= nt; ++t)
      out[t] = g.per_type(t);
  };
  // smoothing length: per type (sl) where defined, else the pair_style's h
  if (modify.find_property("sl")) {
    per_type("sl", h);
    for (int t = 1; t <= nt; ++t)
      if (!(h[t] > 0.0))
        throw InputError(who + ": the smoothing length sl of type " + std::to_string(t) +
                         " must be positive");
  } else {
    h.assign(nt + 1, h_arg_);
  }
  if (!p.sph_kernel.empty()) {
    sph::Kernel k = kernel_;
    sph::kernel_from_name(p.sph_kernel, k);
    if (k != kernel_)
      throw InputError("set sphkernel " + p.sph_kernel + " differs from the kernel of " + who + " (" +
                       args_[0] + "): the SPH fixes use the pair style's kernel");
  }
  if (artvisc_) {
    per_type("speedOfSound", c);
    if (artvisc_args_.empty()) {
      per_type("artViscAlpha", alpha);
      per_type("artViscBeta", beta);
      eta2_ = modify.require_property("artViscEta", who).scalar();
    } else {
      alpha.assign(nt + 1, artvisc_args_[0]);
      beta.assign(nt + 1, artvisc_args_[1]);
      eta2_ = artvisc_args_[2];
    }
  }
  if (tenscorr_) {
    if (tenscorr_args_.empty()) {
      epsilon_ = modify.require_property("tensCorrEpsilon", who).scalar();
      per_type("tensCorrDeltaP", deltap);
    } else {
      epsilon_ = tenscorr_args_[0];
      deltap.assign(nt + 1, tenscorr_args_[1]);
    }
  }
  ntypes1_ = static_cast<std::size_t>(nt) + 1;
  mix_.assign(ntypes1_ * ntypes1_, Mix{});
  for (int ti = 1; ti <= nt; ++ti)
    for (int tj = 1; tj <= nt; ++tj) {
      Mix& m = mix_[ti * ntypes1_ + tj];
      m.h = 0.5 * (h[ti] + h[tj]);
      m.c = 0.5 * (c[ti] + c[tj]);
      m.alpha = 0.5 * (alpha[ti] + alpha[tj]);
      m.beta = 0.5 * (beta[ti] + beta[tj]);
      if (tenscorr_) m.w_dp = sph::kernel_w(kernel_, 0.5 * (deltap[ti] + deltap[tj]), m.h);
    }
  // Monaghan's (1992) timestep condition for the sound waves: dt < 0.25 h / c
  if (artvisc_) {
    double hmin = h[1], cmax = c[1];
    for (int t = 1; t <= nt; ++t)
      hmin = std::min(hmin, h[t]), cmax = std::max(cmax, c[t]);
    const double limit = 0.25 * hmin / cmax, dt = engine_.update->dt;
    if (cmax > 0.0 && dt > limit)
      engine_.logger->warning(who + ": the timestep " + format_number(dt) +
                              " s exceeds 0.25 h / c = " + format_number(limit) +
                              " s (smallest smoothing length, largest speedOfSound): sound waves are not "
                              "resolved; lower the timestep");
  }
  // the neighbour list holds the pairs within 2h + skin: each particle's
  // radius is its smoothing length (radius_i + radius_j = 2h)
  const std::vector<double>& rho = p.extras[rho_].data;
  long long bad = 0;
  for (int i = 0; i < p.nlocal; ++i) {
    p.radius[i] = h[p.type[i]];
    if (!(rho[i] > 0.0) || !(p.rmass[i] > 0.0)) ++bad;
  }
  long long all = 0;
  MPI_Allreduce(&bad, &all, 1, MPI_LONG_LONG, MPI_SUM, engine_.world);
  if (all > 0)
    throw InputError(who + ": " + std::to_string(all) +
                     " particles have no positive density or mass; give them with 'set group all meso_rho "
                     "VALUE' and 'mass TYPE VALUE'");
}

void PairSph::compute() {
  Particles& p = *engine_.particles;
  const double* rho = p.extras[rho_].data.data();
  const double* pres = p.extras[p_].data.data();
  const int nlocal = p.nlocal;
  // P/rho^2 and the tensile-correction R (zero for P >= 0) of owned and ghost particles
  const int n = p.size();
  p_rho2_.resize(n);
  tension_.resize(n);
  for (int a = 0; a < n; ++a) {
    p_rho2_[a] = pres[a] / (rho[a] * rho[a]);
    tension_[a] = tenscorr_ && pres[a] < 0.0 ? epsilon_ * std::fabs(p_rho2_[a]) : 0.0;
  }
  for_each_pair(p, *engine_.neighbor, [&](int i, int j, double r2, double h) {
    if (r2 == 0.0) return;
    const Mix& m = mix(p.type[i], p.type[j]);
    const Vec3 dx = p.x[i] - p.x[j];
    const double r = std::sqrt(r2);
    double bracket = p_rho2_[i] + p_rho2_[j];
    if (artvisc_) {
      const double vr = (p.v[i] - p.v[j]).dot(dx);
      if (vr < 0.0) {
        const double mu = h * vr / (r2 + eta2_);
        bracket += (-m.alpha * m.c * mu + m.beta * mu * mu) / (0.5 * (rho[i] + rho[j]));
      }
    }
    if (tenscorr_) {
      const double rr = tension_[i] + tension_[j];
      if (rr > 0.0) {
        const double fab = sph::kernel_w(kernel_, r, h) / m.w_dp;
        const double f2 = fab * fab;
        bracket += rr * f2 * f2;
      }
    }
    // grad_i W_ij = dW/dr dx / r
    const Vec3 force = (-p.rmass[i] * p.rmass[j] * bracket * sph::kernel_dw(kernel_, r, h) / r) * dx;
    p.f[i] += force;
    if (j < nlocal) p.f[j] -= force;
  });
}

Vec3 PairSph::clone_force(const Particles& p, int i, const Vec3& dx) const {
  const double r2 = dx.squaredNorm();
  const Mix& m = mix(p.type[i], p.type[i]);
  const double h = m.h;
  if (r2 >= 4.0 * h * h || r2 == 0.0) return Vec3::Zero();
  const double r = std::sqrt(r2);
  const double rho = p.extras[rho_].data[i];
  const double pres = p.extras[p_].data[i];
  const double rr = rho * rho;
  double bracket = 2.0 * pres / rr;
  if (tenscorr_ && pres < 0.0) {
    const double fab = sph::kernel_w(kernel_, r, h) / m.w_dp;
    const double f2 = fab * fab;
    bracket += 2.0 * epsilon_ * std::fabs(pres) / rr * f2 * f2;
  }
  return (-p.rmass[i] * p.rmass[i] * bracket * sph::kernel_dw(kernel_, r, h) / r) * dx;
}

GRANARY_PAIR_STYLE("sph/artVisc/tensCorr", PairSph);

}  // namespace granary
