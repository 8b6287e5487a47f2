// fix check/timestep/gran: compares the timestep with the Rayleigh time and
// the Hertz collision time of the current particles.
//   fix ID group check/timestep/gran NEVERY FRACTION_RAYLEIGH FRACTION_HERTZ [warn yes|no] [error yes|no]
//       [vmax V]
// f_ID[1] = dt / Rayleigh time, f_ID[2] = dt / Hertz time, f_ID[3] = distance two
// particles can approach in one step / skin = 2 vmax dt / skin (at the last check).
#include <mpi.h>

#include <cmath>
#include <cstdio>

#include "core/engine.h"
#include "core/error.h"
#include "core/logger.h"
#include "core/registry.h"
#include "core/update.h"
#include "fix/fix.h"
#include "neighbor/neighbor.h"
#include "core/force.h"
#include "pair/pair_granular.h"
#include "particles/particles.h"

namespace granary {

class FixCheckTimestepGran : public Fix {
 public:
  FixCheckTimestepGran(Engine& engine, const Args& args) : Fix(engine, args) {
    const std::string usage =
        "fix ID group check/timestep/gran NEVERY FRACTION_RAYLEIGH FRACTION_HERTZ [warn yes|no] [error "
        "yes|no] [vmax V]";
    if (args.size() < 6) throw InputError("wrong number of arguments; usage: " + usage);
    nevery = static_cast<int>(parse_int(args[3], "nevery"));
    frac_rayleigh_ = parse_double(args[4], "fraction of the Rayleigh time");
    frac_hertz_ = parse_double(args[5], "fraction of the Hertz time");
    if (nevery < 1 || frac_rayleigh_ <= 0 || frac_hertz_ <= 0) {
      throw InputError("check/timestep/gran needs NEVERY >= 1 and positive fractions");
    }
    for (std::size_t k = 6; k < args.size(); k += 2) {
      if (k + 1 >= args.size()) throw InputError("keyword '" + args[k] + "' needs a value; usage: " + usage);
      if (args[k] == "vmax") {
        vmax_user_ = parse_double(args[k + 1], "check/timestep/gran vmax");
        if (vmax_user_ < 0) throw InputError("check/timestep/gran vmax must not be negative");
      } else if (args[k] == "warn")
        warn_ = parse_bool(args[k + 1], "warn");
      else if (args[k] == "error")
        error_ = parse_bool(args[k + 1], "error");
      else
        throw InputError("unknown keyword '" + args[k] + "'; usage: " + usage);
    }
    size_vector = 3;
  }
  unsigned hooks() const override { return END_OF_STEP; }
  void setup() override { check(); }
  void end_of_step() override { check(); }
  double compute_vector(int i) override {
    return i == 0 ? ratio_rayleigh_ : i == 1 ? ratio_hertz_ : ratio_skin_;
  }

 private:
  void check() {
    auto* pair = dynamic_cast<PairGranular*>(engine_.force->pair.get());
    if (!pair)
      throw InputError(
          "fix check/timestep/gran needs a granular pair style (pair_style gran or hertz/rolling)");
    const Particles& p = *engine_.particles;
    const double dt = engine_.update->dt;
    // Hertz time of each particle's impact at the largest speed vmax (LIGGGHTS
    // 3.8's estimate: the particle's own mass and radius, the effective
    // modulus Y* of its type with itself, the impact speed vmax)
    double vmax_local = 0.0, vmax = 0.0;
    for (int i = 0; i < p.nlocal; ++i)
      vmax_local = std::max(vmax_local, p.v[i].norm());
    MPI_Allreduce(&vmax_local, &vmax, 1, MPI_DOUBLE, MPI_MAX, engine_.world);
    vmax = std::max(vmax, vmax_user_);
    const ContactTimes times = pair->contact_times(vmax, groupbit);
    const double t_rayleigh = times.rayleigh, t_hertz = times.hertz;
    ratio_rayleigh_ = std::isfinite(t_rayleigh) ? dt / t_rayleigh : 0.0;
    ratio_hertz_ = std::isfinite(t_hertz) ? dt / t_hertz : 0.0;
    // two particles approach each other by at most 2 vmax dt per step
    const double skin = engine_.neighbor->skin;
    ratio_skin_ = skin > 0 ? 2.0 * vmax * dt / skin : 0.0;
    if (ratio_skin_ > 1.0 && (warn_ || error_)) {
      char msg[256];
      std::snprintf(
          msg, sizeof msg,
          "step %lld: particles can approach each other by %.3g times the neighbour skin in one step; "
          "contacts may be missed: raise the skin or reduce the timestep",
          static_cast<long long>(engine_.update->ntimestep), ratio_skin_);
      if (error_) throw RunError(msg);
      engine_.logger->warning(msg);
    }
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
  double ratio_rayleigh_ = 0.0, ratio_hertz_ = 0.0, ratio_skin_ = 0.0;
  double vmax_user_ = 0.0;  // vmax keyword: lower bound of the speed used for the Hertz time
  bool warn_ = true, error_ = false;
};

GRANARY_FIX_STYLE("check/timestep/gran", FixCheckTimestepGran);

}  // namespace granary
