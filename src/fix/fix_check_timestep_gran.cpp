// fix check/timestep/gran: compares the timestep with the Rayleigh time and
// the Hertz collision time of the current particles.
//   fix ID group check/timestep/gran NEVERY FRACTION_RAYLEIGH FRACTION_HERTZ [warn yes|no] [error yes|no]
// f_ID[1] = dt / Rayleigh time, f_ID[2] = dt / Hertz time (both at the last check).
#include <mpi.h>

#include <cmath>
#include <cstdio>

#include "core/engine.h"
#include "core/error.h"
#include "core/logger.h"
#include "core/registry.h"
#include "core/update.h"
#include "fix/fix.h"
#include "pair/force.h"
#include "pair/pair_granular.h"
#include "particles/particles.h"

namespace granary {

class FixCheckTimestepGran : public Fix {
 public:
  FixCheckTimestepGran(Engine& engine, const Args& args) : Fix(engine, args) {
    const std::string usage =
        "fix ID group check/timestep/gran NEVERY FRACTION_RAYLEIGH FRACTION_HERTZ [warn yes|no] [error "
        "yes|no]";
    if (args.size() < 6) throw InputError("wrong number of arguments; usage: " + usage);
    nevery = static_cast<int>(parse_int(args[3], "nevery"));
    frac_rayleigh_ = parse_double(args[4], "fraction of the Rayleigh time");
    frac_hertz_ = parse_double(args[5], "fraction of the Hertz time");
    if (nevery < 1 || frac_rayleigh_ <= 0 || frac_hertz_ <= 0) {
      throw InputError("check/timestep/gran needs NEVERY >= 1 and positive fractions");
    }
    for (std::size_t k = 6; k < args.size(); k += 2) {
      if (k + 1 >= args.size())
        throw InputError("keyword '" + args[k] + "' needs yes or no; usage: " + usage);
      if (args[k] == "warn")
        warn_ = parse_bool(args[k + 1], "warn");
      else if (args[k] == "error")
        error_ = parse_bool(args[k + 1], "error");
      else
        throw InputError("unknown keyword '" + args[k] + "'; usage: " + usage);
    }
    size_vector = 2;
  }
  unsigned hooks() const override { return END_OF_STEP; }
  void setup() override { check(); }
  void end_of_step() override { check(); }
  double compute_vector(int i) override { return i == 0 ? ratio_rayleigh_ : ratio_hertz_; }

 private:
  void check() {
    auto* pair = dynamic_cast<PairGranular*>(engine_.force->pair.get());
    if (!pair)
      throw InputError(
          "fix check/timestep/gran needs a granular pair style (pair_style gran or hertz/rolling)");
    const MaterialTable& mat = pair->materials();
    const Particles& p = *engine_.particles;
    const double dt = engine_.update->dt;
    const double t_rayleigh = min_rayleigh_time(engine_, mat);
    // Hertz time of a head-on impact of two equal particles at twice the largest speed.
    double vmax_local = 0.0, vmax = 0.0;
    for (int i = 0; i < p.nlocal; ++i)
      vmax_local = std::max(vmax_local, p.v[i].norm());
    MPI_Allreduce(&vmax_local, &vmax, 1, MPI_DOUBLE, MPI_MAX, engine_.world);
    double th_local = 1e300, t_hertz = 1e300;
    const double vrel = 2.0 * vmax;
    if (vrel > 0) {
      for (int i = 0; i < p.nlocal; ++i) {
        if (!(p.mask[i] & groupbit)) continue;
        const int t = p.type[i];
        const double m_eff = 0.5 * p.rmass[i], r_eff = 0.5 * p.radius[i];
        const double y_eff = mat(t, t).Y_eff;
        const double th = 2.87 * std::pow(m_eff * m_eff / (r_eff * y_eff * y_eff * vrel), 0.2);
        th_local = std::min(th_local, th);
      }
    }
    MPI_Allreduce(&th_local, &t_hertz, 1, MPI_DOUBLE, MPI_MIN, engine_.world);
    ratio_rayleigh_ = t_rayleigh < 1e300 ? dt / t_rayleigh : 0.0;
    ratio_hertz_ = t_hertz < 1e300 ? dt / t_hertz : 0.0;
    const bool bad_r = ratio_rayleigh_ > frac_rayleigh_, bad_h = ratio_hertz_ > frac_hertz_;
    if (!bad_r && !bad_h) return;
    char buf[512];
    std::snprintf(buf, sizeof buf,
                  "step %lld: timestep %g s is %.3g%% of the Rayleigh time (limit %.3g%%) and %.3g%% of "
                  "the Hertz time (limit %.3g%%); reduce the timestep or the Young's modulus",
                  static_cast<long long>(engine_.update->ntimestep), dt, 100 * ratio_rayleigh_,
                  100 * frac_rayleigh_, 100 * ratio_hertz_, 100 * frac_hertz_);
    if (error_) throw RunError(buf);
    if (warn_) engine_.logger->warning(buf);
  }
  double frac_rayleigh_ = 0.2, frac_hertz_ = 0.1;
  double ratio_rayleigh_ = 0.0, ratio_hertz_ = 0.0;
  bool warn_ = true, error_ = false;
};

GRANARY_FIX_STYLE("check/timestep/gran", FixCheckTimestepGran);

}  // namespace granary
