// fix ID group dt/reset N TMIN TMAX XMAX [units lattice|box]
// (LAMMPS/LIGGGHTS syntax): every N steps the timestep becomes the largest in
// which no particle of the group moves farther than XMAX, from its velocity
// and acceleration (|v| dt + |a| dt^2 / 2 <= XMAX, a bound of the velocity
// Verlet displacement), clamped to [TMIN, TMAX] (either may be NULL). The
// scalar is the last step at which the timestep changed.
// See doc/fixes/dt_reset.md.
#include <mpi.h>

#include <cmath>
#include <limits>

#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "core/update.h"
#include "domain/domain.h"
#include "fix/fix.h"
#include "particles/particles.h"

namespace granary {

namespace {

const char* kUsage = "fix ID group dt/reset N TMIN|NULL TMAX|NULL XMAX [units lattice|box]";

class FixDtReset : public Fix {
 public:
  FixDtReset(Engine& engine, const Args& args) : Fix(engine, args) {
    const std::string where = "fix " + id + " dt/reset";
    if (args.size() != 7 && args.size() != 9)
      throw InputError(where + ": wrong number of arguments; usage: " + kUsage);
    const long long n = parse_int(args[3], where + " N");
    if (n < 1) throw InputError(where + ": N must be >= 1");
    nevery = static_cast<int>(n);
    auto bound = [&](const std::string& w, const char* what) {
      if (w == "NULL") return std::numeric_limits<double>::quiet_NaN();
      const double v = parse_double(w, where + " " + what);
      if (!(v > 0.0)) throw InputError(where + ": " + what + " must be positive or NULL, got " + w);
      return v;
    };
    tmin_ = bound(args[4], "TMIN");
    tmax_ = bound(args[5], "TMAX");
    if (tmin_ > tmax_) throw InputError(where + ": TMIN " + args[4] + " is larger than TMAX " + args[5]);
    xmax_ = parse_double(args[6], where + " XMAX");
    if (!(xmax_ > 0.0)) throw InputError(where + ": XMAX must be positive, got " + args[6]);
    bool lattice = true, units_given = false;  // LAMMPS' default: units lattice
    if (args.size() == 9) {
      if (args[7] != "units")
        throw InputError(where + ": unknown keyword '" + args[7] + "'; usage: " + kUsage);
      if (args[8] != "box" && args[8] != "lattice")
        throw InputError(where + " units must be box or lattice, got '" + args[8] + "'");
      lattice = args[8] == "lattice";
      if (lattice && engine.domain->lattice_style == "none")
        throw InputError(where +
                         " units lattice needs a lattice; define one with the lattice command or use units "
                         "box");
      units_given = true;
    }
    const Domain& dom = *engine.domain;
    if (lattice && !units_given && dom.lattice_style == "none")
      throw InputError(
          where +
          ": XMAX is in lattice spacings by default (as in LAMMPS and LIGGGHTS) and no lattice is "
          "defined; add 'units box' for XMAX in metres");
    if (lattice) xmax_ *= dom.lattice_spacing[0];
    scalar_flag = true;
  }

  unsigned hooks() const override { return END_OF_STEP; }

  double compute_scalar() override { return static_cast<double>(last_); }

  void end_of_step() override {
    const Particles& p = *engine_.particles;
    double local = std::numeric_limits<double>::infinity();
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit)) continue;
      const double v = p.v[i].norm(), a = p.f[i].norm() / p.rmass[i];
      // the positive root of a dt^2 / 2 + v dt = XMAX, in the form that does
      // not cancel (also for a = 0)
      const double dt = 2.0 * xmax_ / (v + std::sqrt(v * v + 2.0 * a * xmax_));
      if (dt < local) local = dt;
    }
    double dt = 0.0;
    MPI_Allreduce(&local, &dt, 1, MPI_DOUBLE, MPI_MIN, engine_.world);
    if (!std::isfinite(dt)) return;  // nothing moves and nothing pushes: keep the timestep
    if (std::isfinite(tmin_) && dt < tmin_) dt = tmin_;
    if (std::isfinite(tmax_) && dt > tmax_) dt = tmax_;
    if (dt == engine_.update->dt) return;
    engine_.update->set_timestep(dt);
    last_ = engine_.update->ntimestep;
  }

 private:
  double tmin_ = 0.0, tmax_ = 0.0, xmax_ = 0.0;
  std::int64_t last_ = 0;
};

}  // namespace

GRANARY_FIX_STYLE("dt/reset", FixDtReset);

}  // namespace granary
