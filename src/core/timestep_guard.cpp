#include "core/timestep_guard.h"

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "core/engine.h"
#include "core/error.h"
#include "core/force.h"
#include "core/logger.h"
#include "core/modify.h"
#include "comm/comm.h"
#include "core/update.h"
#include "pair/pair.h"
#include "particles/particles.h"

namespace granary {

TimestepGuard::State TimestepGuard::measure() {
  Engine& e = engine_;
  const Particles& p = *e.particles;
  // max speed, -min radius; with the particles this rank lost at the last exchange
  double local[2] = {0.0, std::numeric_limits<double>::max()};
  if (e.comm->nlost > 0) {
    local[0] = e.comm->lost_vmax;
    local[1] = e.comm->lost_rmin;
  }
  for (int i = 0; i < p.nlocal; ++i) {
    local[0] = std::max(local[0], p.v[i].norm());
    local[1] = std::min(local[1], p.radius[i]);
  }
  local[1] = -local[1];
  double all[2];
  MPI_Allreduce(local, all, 2, MPI_DOUBLE, MPI_MAX, e.world);
  vmax_seen_ = std::max(vmax_seen_, all[0]);
  State s{e.update->dt,
          std::numeric_limits<double>::infinity(),
          std::numeric_limits<double>::infinity(),
          vmax_seen_,
          -all[1],
          std::numeric_limits<double>::infinity()};
  if (e.force->pair) {
    const ContactTimes times = e.force->pair->contact_times(vmax_seen_, ~0);
    s.t_rayleigh = times.rayleigh;
    s.t_hertz = times.hertz;
    s.t_spring = times.spring;
  }
  return s;
}

void TimestepGuard::start_run() {
  // each warning once for a timestep (a script's many short runs repeat none)
  if (engine_.update->dt != warned_dt_) warned_rayleigh_ = warned_hertz_ = warned_spring_ = false;
  warned_dt_ = engine_.update->dt;
  check_now(true);
}

void TimestepGuard::check() {
  const Engine& e = engine_;
  if (e.update->ntimestep < next_check_ && e.particles->natoms == natoms_checked_) return;
  check_now(false);
}

void TimestepGuard::check_now(bool at_setup) {
  Engine& e = engine_;
  next_check_ = e.update->ntimestep + kEvery;
  natoms_checked_ = e.particles->natoms;
  const State s = measure();
  last_ = s;
  char buf[512];
  if (s.dt > s.t_rayleigh) {
    std::snprintf(buf, sizeof buf,
                  "timestep %g s is longer than the Rayleigh time %g s of the stiffest particle; "
                  "contacts cannot be resolved. Use a timestep below %g s (%g%% of the Rayleigh time) "
                  "or a smaller Young's modulus",
                  s.dt, s.t_rayleigh, kWarnFraction * s.t_rayleigh, 100 * kWarnFraction);
    if (at_setup) throw InputError(buf);
    throw RunError("step " + std::to_string(e.update->ntimestep) + ": " + buf);
  }
  // fix check/timestep/gran reports with the limits its script chose
  if (e.modify->find_fix_by_style("check/timestep/gran")) return;
  // the tolerance spares a timestep set to exactly the limit from round-off
  const double limit = kWarnFraction * (1.0 + 1e-9);
  // one warning per time scale: what it is, and what the timestep does to it
  auto warn_once = [&](bool& warned, double t, const std::string& what, const char* consequence) {
    if (warned || !(s.dt > limit * t)) return;
    warned = true;
    std::snprintf(
        buf, sizeof buf,
        "step %lld: timestep %g s is %.3g%% of %s, %g s (above %g%%): %s; use a timestep below %g s",
        static_cast<long long>(e.update->ntimestep), s.dt, 100 * s.dt / t, what.c_str(), t,
        100 * kWarnFraction, consequence, kWarnFraction * t);
    e.logger->warning(buf);
  };
  warn_once(warned_rayleigh_, s.t_rayleigh, "the smallest Rayleigh time of the particles",
            "contacts are poorly resolved and fast particles can pass through walls");
  char speed[64];
  std::snprintf(speed, sizeof speed, "%g m/s", s.vmax);
  warn_once(warned_hertz_, s.t_hertz,
            std::string("the Hertz time of an impact at ") + speed + ", the highest speed seen",
            "such impacts are poorly resolved");
  warn_once(warned_spring_, s.t_spring, "the contact time pi sqrt(m/(2 kn)) of the stiffest linear spring",
            "contacts are poorly resolved");
}

std::string TimestepGuard::explain_loss() {
  // the lost particles are gone: their time scales are those of the last check
  State s = measure();
  s.t_rayleigh = std::min(s.t_rayleigh, last_.t_rayleigh);
  s.t_hertz = std::min(s.t_hertz, last_.t_hertz);
  s.t_spring = std::min(s.t_spring, last_.t_spring);
  char buf[512];
  if (s.dt > kWarnFraction * (1.0 + 1e-9) * s.t_spring) {
    std::snprintf(buf, sizeof buf,
                  "the timestep %g s is %.3g%% of the contact time of the stiffest linear spring; above %g%% "
                  "contacts are not resolved and particles pass through walls: reduce the timestep",
                  s.dt, 100 * s.dt / s.t_spring, 100 * kWarnFraction);
    return buf;
  }
  if (s.dt > kWarnFraction * (1.0 + 1e-9) * std::min(s.t_rayleigh, s.t_hertz)) {
    std::snprintf(buf, sizeof buf,
                  "the timestep %g s is %.3g%% of the Rayleigh time and %.3g%% of the Hertz time at the "
                  "highest speed seen (%g m/s); above %g%% contacts are not resolved and particles pass "
                  "through walls: reduce the timestep",
                  s.dt, 100 * s.dt / s.t_rayleigh, 100 * s.dt / s.t_hertz, s.vmax, 100 * kWarnFraction);
    return buf;
  }
  if (s.vmax * s.dt > s.rmin) {
    std::snprintf(buf, sizeof buf,
                  "the fastest particle seen (%g m/s) moves %g m in one step, more than the smallest radius "
                  "%g m: it can pass through a wall between two steps; reduce the timestep or find what "
                  "accelerates it",
                  s.vmax, s.vmax * s.dt, s.rmin);
    return buf;
  }
  return {};
}

}  // namespace granary
