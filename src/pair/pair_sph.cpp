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

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

bool is_number(const std::string& w) {
  char* end = nullptr;
  std::strtod(w.c_str(), &end);
  return !w.empty() && end && *end == '\0';
}

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
  auto per_type = [&](const char* name, std::vector<double>& out) {
    const GlobalProperty& g = modify.require_property(name, who);
    out.assign(nt + 1, 0.0);
    for (int t = 1; t <= nt; ++t)
      out[t] = g.per_type(t);
  };
  // smoothing length: per type (sl) where defined, else the pair_style's h
  if (modify.find_property("sl")) {
    per_type("sl", h_);
    for (int t = 1; t <= nt; ++t)
      if (!(h_[t] > 0.0))
        throw InputError(who + ": the smoothing length sl of type " + std::to_string(t) +
                         " must be positive");
  } else {
    h_.assign(nt + 1, h_arg_);
  }
  if (!p.sph_kernel.empty()) {
    sph::Kernel k = kernel_;
    sph::kernel_from_name(p.sph_kernel, k);
    if (k != kernel_)
      throw InputError("set sphkernel " + p.sph_kernel + " differs from the kernel of " + who + " (" +
                       args_[0] + "): the SPH fixes use the pair style's kernel");
  }
  if (artvisc_) {
    per_type("speedOfSound", c_);
    if (artvisc_args_.empty()) {
      per_type("artViscAlpha", alpha_);
      per_type("artViscBeta", beta_);
      eta2_ = modify.require_property("artViscEta", who).scalar();
    } else {
      alpha_.assign(nt + 1, artvisc_args_[0]);
      beta_.assign(nt + 1, artvisc_args_[1]);
      eta2_ = artvisc_args_[2];
    }
  }
  if (tenscorr_) {
    if (tenscorr_args_.empty()) {
      epsilon_ = modify.require_property("tensCorrEpsilon", who).scalar();
      per_type("tensCorrDeltaP", deltap_);
    } else {
      epsilon_ = tenscorr_args_[0];
      deltap_.assign(nt + 1, tenscorr_args_[1]);
    }
  }
  // Monaghan's (1992) timestep condition for the sound waves: dt < 0.25 h / c
  if (artvisc_) {
    double hmin = h_[1], cmax = c_[1];
    for (int t = 1; t <= nt; ++t)
      hmin = std::min(hmin, h_[t]), cmax = std::max(cmax, c_[t]);
    const double limit = 0.25 * hmin / cmax, dt = engine_.update->dt;
    if (cmax > 0.0 && dt > limit)
      engine_.logger->warning(who + ": the timestep " + num(dt) + " s exceeds 0.25 h / c = " + num(limit) +
                              " s (smallest smoothing length, largest speedOfSound): sound waves are not "
                              "resolved; lower the timestep");
  }
  // the neighbour list holds the pairs within 2h + skin: each particle's
  // radius is its smoothing length (radius_i + radius_j = 2h)
  const std::vector<double>& rho = p.extras[rho_].data;
  long long bad = 0;
  for (int i = 0; i < p.nlocal; ++i) {
    p.radius[i] = h_[p.type[i]];
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
  const Neighbor& list = *engine_.neighbor;
  const double* rho = p.extras[rho_].data.data();
  const double* pres = p.extras[p_].data.data();
  const int nlocal = p.nlocal;
  for (int i = 0; i < nlocal; ++i) {
    const int ti = p.type[i];
    const double pi_rho2 = pres[i] / (rho[i] * rho[i]);
    const double ri_t = tenscorr_ && pres[i] < 0.0 ? epsilon_ * std::fabs(pres[i]) / (rho[i] * rho[i]) : 0.0;
    for (int k = list.offset[i]; k < list.offset[i + 1]; ++k) {
      const int j = list.neigh[k];
      const int tj = p.type[j];
      const Vec3 dx = p.x[i] - p.x[j];
      const double r2 = dx.squaredNorm();
      const double h = 0.5 * (h_[ti] + h_[tj]);
      if (r2 >= 4.0 * h * h || r2 == 0.0) continue;
      const double r = std::sqrt(r2);
      const Vec3 grad = (sph::kernel_dw(kernel_, r, h) / r) * dx;  // grad_i W_ij
      double bracket = pi_rho2 + pres[j] / (rho[j] * rho[j]);
      if (artvisc_) {
        const double vr = (p.v[i] - p.v[j]).dot(dx);
        if (vr < 0.0) {
          const double mu = h * vr / (r2 + eta2_);
          const double cbar = 0.5 * (c_[ti] + c_[tj]);
          const double rhobar = 0.5 * (rho[i] + rho[j]);
          const double alpha = 0.5 * (alpha_[ti] + alpha_[tj]), beta = 0.5 * (beta_[ti] + beta_[tj]);
          bracket += (-alpha * cbar * mu + beta * mu * mu) / rhobar;
        }
      }
      if (tenscorr_) {
        const double rj_t = pres[j] < 0.0 ? epsilon_ * std::fabs(pres[j]) / (rho[j] * rho[j]) : 0.0;
        const double rr = ri_t + rj_t;
        if (rr > 0.0) {
          const double dp = 0.5 * (deltap_[ti] + deltap_[tj]);
          const double fab = sph::kernel_w(kernel_, r, h) / sph::kernel_w(kernel_, dp, h);
          const double f2 = fab * fab;
          bracket += rr * f2 * f2;
        }
      }
      const Vec3 force = (-p.rmass[i] * p.rmass[j] * bracket) * grad;
      p.f[i] += force;
      if (j < nlocal) p.f[j] -= force;
    }
  }
}

Vec3 PairSph::clone_force(const Particles& p, int i, const Vec3& dx) const {
  const double r2 = dx.squaredNorm();
  const int t = p.type[i];
  const double h = h_[t];
  if (r2 >= 4.0 * h * h || r2 == 0.0) return Vec3::Zero();
  const double r = std::sqrt(r2);
  const double rho = p.extras[rho_].data[i];
  const double pres = p.extras[p_].data[i];
  const double rr = rho * rho;
  double bracket = 2.0 * pres / rr;
  if (tenscorr_ && pres < 0.0) {
    const double fab = sph::kernel_w(kernel_, r, h) / sph::kernel_w(kernel_, deltap_[t], h);
    const double f2 = fab * fab;
    bracket += 2.0 * epsilon_ * std::fabs(pres) / rr * f2 * f2;
  }
  return (-p.rmass[i] * p.rmass[i] * bracket * sph::kernel_dw(kernel_, r, h) / r) * dx;
}

GRANARY_PAIR_STYLE("sph/artVisc/tensCorr", PairSph);

}  // namespace granary
