#include "core/update.h"

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "comm/comm.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/logger.h"
#include "core/registry.h"
#include "core/stop_signal.h"
#include "domain/domain.h"
#include "fix/fix.h"
#include "core/modify.h"
#include "neighbor/contact_history.h"
#include "neighbor/neighbor.h"
#include "output/output.h"
#include "output/thermo.h"
#include "core/force.h"
#include "pair/multicontact.h"
#include "pair/pair.h"
#include "particles/particles.h"

namespace granary {

Update::Update(Engine& engine) : engine_(engine) {}

void Update::set_timestep(double new_dt) {
  if (!(new_dt > 0.0)) throw InputError("timestep must be positive");
  // keep the simulated time continuous across a change of dt; the same dt
  // again (a script re-defining it after read_restart) changes nothing, so
  // the time of a step is the same number in a run and in its continuation
  if (new_dt == dt) return;
  atime = time();
  atimestep = ntimestep;
  dt = new_dt;
  if (engine_.modify) engine_.modify->reset_dt();
}

namespace {
struct Timer {
  double& slot;
  double t0;
  explicit Timer(double& s) : slot(s), t0(MPI_Wtime()) {}
  ~Timer() { slot += MPI_Wtime() - t0; }
};
}  // namespace

// Reneighbouring: migrate particles with their contact history, rebuild ghosts and lists.
// During a run the list-aligned history is saved first; at setup it is already
// in the keyed store (saved at the end of the previous run, or read from a restart).
//
// The history is saved and the ghosts are dropped before the pre_exchange
// fixes run, so those fixes (insertion, deletion) may add or remove owned
// particles freely: nothing refers to particle indices any more.
void Update::reneighbor(bool save_history) {
  Engine& e = engine_;
  ContactHistory* history = e.force->contact_history();
  {
    Timer t(timers[kNeigh]);
    // (on one rank no particle migrates: the history may stay in list order)
    if (history && save_history) history->save(*e.neighbor, *e.particles, e.nprocs == 1);
    e.particles->clear_ghosts();
  }
  {
    Timer t(timers[kModify]);
    e.modify->pre_exchange();
  }
  {
    // migration and the lost-particle count: communication, as in LAMMPS
    Timer t(timers[kComm]);
    e.domain->reset_box();
    e.comm->setup(e.neighbor->cutneighmax);
    e.comm->exchange(history);
    check_lost();
  }
  {
    Timer t(timers[kNeigh]);
    timestep_guard_.check();
    e.neighbor->sort_particles(ntimestep);
    e.particles->map_clear();
  }
  {
    Timer t(timers[kComm]);
    e.comm->borders();
  }
  Timer t(timers[kNeigh]);
  e.modify->pre_neighbor();
  e.neighbor->build();
  if (history) history->restore(*e.neighbor, *e.particles);
  e.modify->post_neighbor();
}

void Update::check_lost() {
  Engine& e = engine_;
  int local = e.comm->nlost, total = 0;
  MPI_Allreduce(&local, &total, 1, MPI_INT, MPI_SUM, e.world);
  if (total == 0) return;
  e.particles->natoms -= total;
  // the timestep or a speed may explain the loss (collective)
  const std::string why = timestep_guard_.explain_loss();
  if (e.thermo->lost == Thermo::Lost::Ignore) {
    if (!why.empty() && !loss_explained_) {
      loss_explained_ = true;
      e.logger->warning(std::to_string(total) + " particle(s) left the box at step " +
                        std::to_string(ntimestep) + " (thermo_modify lost ignore): " + why);
    }
    return;
  }
  // the lowest rank that lost one describes it
  int who = local > 0 ? e.rank : e.nprocs, first = 0;
  MPI_Allreduce(&who, &first, 1, MPI_INT, MPI_MIN, e.world);
  char text[256] = {0};
  if (e.rank == first) std::snprintf(text, sizeof text, "%s", e.comm->first_lost.c_str());
  MPI_Bcast(text, sizeof text, MPI_CHAR, first, e.world);
  const std::string msg = std::to_string(total) +
                          " particle(s) left the box through a fixed boundary at step " +
                          std::to_string(ntimestep) + " (first: " + text + ")";
  if (e.thermo->lost == Thermo::Lost::Warn) {
    e.logger->warning(why.empty() ? msg : msg + "; " + why);
    return;
  }
  throw RunError(msg + (why.empty()
                            ? "; contain them with walls, use shrink-wrapped boundaries (boundary m m m), "
                              "or accept the loss with thermo_modify lost ignore"
                            : "; " + why));
}

void Update::compute_forces() {
  Engine& e = engine_;
  Particles& p = *e.particles;
  // With newton off nothing adds to a ghost's force or torque (every pair
  // style and fix writes owned particles only, or ghosts only with newton on)
  // and nothing sends or reads them: only the owned particles start from zero.
  const int n = e.force->newton_pair ? p.size() : p.nlocal;
  // (all bits zero is 0.0: one wide fill per array; an empty array may have no storage at all)
  if (n > 0) {
    std::memset(static_cast<void*>(p.f.data()), 0, sizeof(Vec3) * static_cast<std::size_t>(n));
    std::memset(static_cast<void*>(p.torque.data()), 0, sizeof(Vec3) * static_cast<std::size_t>(n));
  }
  {
    Timer t(timers[kModify]);
    e.modify->pre_force();
  }
  if (e.force->multicontact) e.force->multicontact->begin();
  if (e.force->pair) {
    Timer t(timers[kPair]);
    e.force->pair->compute();
  }
  if (e.force->newton_pair) {
    Timer t(timers[kComm]);
    e.comm->reverse_comm();
  }
  Timer t(timers[kModify]);
  e.modify->post_force();
  if (e.force->multicontact) e.force->multicontact->finish();
}

void Update::setup() {
  Engine& e = engine_;
  if (!e.domain->box_exist)
    throw InputError("run needs a simulation box: use create_box or read_restart first");
  e.logger->print("Setting up run ...\n");
  std::fill(std::begin(timers), std::end(timers), 0.0);
  e.particles->natoms = count_global();
  if (e.force->pair) e.force->pair->init();
  e.neighbor->init();
  e.modify->init();
  loss_explained_ = false;
  timestep_guard_.start_run();
  reneighbor(false);
  // Forces at the start of a run are those of the current state: contact
  // history (pair and per-particle fields marked as history) is not advanced.
  {
    ContactHistory* history = e.force->contact_history();
    if (history) history->hold();
    // Per-particle history fields (wall contacts) are mostly zero: only the
    // rows of particles with history are kept, and restored over a cleared field.
    struct SavedRows {
      std::vector<int> rows;
      std::vector<double> values;
    };
    std::vector<SavedRows> saved_fields;
    for (const auto& field : e.particles->extras) {
      if (!field.history) continue;
      SavedRows saved;
      const std::size_t nc = static_cast<std::size_t>(field.ncomp);
      const std::size_t nrows = nc > 0 ? field.data.size() / nc : 0;
      for (std::size_t r = 0; r < nrows; ++r) {
        const double* row = field.data.data() + r * nc;
        if (std::any_of(row, row + nc, [](double v) { return v != 0.0; })) {
          saved.rows.push_back(static_cast<int>(r));
          saved.values.insert(saved.values.end(), row, row + nc);
        }
      }
      saved_fields.push_back(std::move(saved));
    }
    in_setup_forces = true;
    compute_forces();
    in_setup_forces = false;
    if (history) history->put_back();
    std::size_t k = 0;
    for (auto& field : e.particles->extras) {
      if (!field.history) continue;
      const SavedRows& saved = saved_fields[k++];
      const std::size_t nc = static_cast<std::size_t>(field.ncomp);
      std::fill(field.data.begin(), field.data.end(), 0.0);
      for (std::size_t m = 0; m < saved.rows.size(); ++m)
        std::copy(saved.values.begin() + m * nc, saved.values.begin() + (m + 1) * nc,
                  field.data.begin() + saved.rows[m] * nc);
    }
  }
  // the same on every rank: read_restart registers the field on all of them
  // (a rank without particles has it too, with no values)
  if (e.particles->find_field(kRestartForcesField) >= 0) use_restart_forces();
  e.modify->setup();
  // dumps before thermo, as in LIGGGHTS and LAMMPS: a compute with a side
  // effect (nparticles/tracer/region unmarking what it counted) shows the
  // same per-atom values in a dump of the step as there
  e.output->setup();
  e.thermo->header();
  e.thermo->line();
}

// Velocity Verlet's state is (x, v, f): the forces of step n were computed
// with the half-step velocities, so with velocity-dependent (damping) forces
// they cannot be recomputed from x and v alone. The first run after
// read_restart therefore starts from the forces stored in the file, as an
// uninterrupted run would, unless the set of particles changed since (then the
// recomputed forces are used). A restarted run thus continues bit for bit.
void Update::use_restart_forces() {
  Engine& e = engine_;
  Particles& p = *e.particles;
  // the stored forces travelled with their particles (a shrink-wrapped box
  // changed, fix balance moved the cuts at setup); a particle created since
  // has none, one deleted since leaves fewer than the file held
  const double* const s = FieldRef(p, kRestartForcesField).data(p);
  long long local = 0, all = 0;
  for (int i = 0; i < p.nlocal; ++i)
    local += s[static_cast<std::size_t>(i) * kRestartForceValues + 6] == 1.0 ? 1 : 0;
  MPI_Allreduce(&local, &all, 1, MPI_LONG_LONG, MPI_SUM, e.world);
  const long long natoms = count_global();
  const bool same = all == natoms && natoms == restart_forces_natoms;
  if (same) {
    for (int i = 0; i < p.nlocal; ++i) {
      const double* si = s + static_cast<std::size_t>(i) * kRestartForceValues;
      p.f[i] = Vec3(si[0], si[1], si[2]);
      p.torque[i] = Vec3(si[3], si[4], si[5]);
    }
  }
  e.logger->print(same ? "Starting from the forces stored in the restart file\n"
                       : "Particles changed since read_restart: forces recomputed\n");
  p.release_field(kRestartForcesField);
}

std::int64_t Update::count_global() const {
  long long local = engine_.particles->nlocal, total = 0;
  MPI_Allreduce(&local, &total, 1, MPI_LONG_LONG, MPI_SUM, engine_.world);
  return total;
}

bool Update::step_observed() const {
  const Engine& e = engine_;
  if (!running || ntimestep == laststep || halt_requested || stop_signal != 0) return true;
  if (e.thermo->every > 0 && ntimestep % e.thermo->every == 0) return true;
  if (ntimestep == e.output->next) return true;
  return e.modify->end_of_step_due(ntimestep);
}

void Update::step_loop(std::int64_t n) {
  Engine& e = engine_;
  Modify& modify = *e.modify;
  for (std::int64_t k = 0; k < n; ++k) {
    ++ntimestep;
    {
      Timer t(timers[kModify]);
      modify.initial_integrate();
      modify.post_integrate();
    }
    ++e.neighbor->ago;
    // a batch system's signal (possibly seen by some ranks only): the ranks
    // agree on it with the neighbour decision's reduction (or with one of
    // their own when the decision makes none) and stop together at the end of
    // the step; nothing before this point asks whether the step is observed
    int signal = stop_signal_received();
    const bool rebuild = e.neighbor->decide(&signal);
    if (signal < 0) signal = e.nprocs > 1 ? stop_signal_agreed(e.world) : stop_signal_received();
    stop_signal = signal;
    if (rebuild) {
      reneighbor(true);
    } else {
      Timer t(timers[kComm]);
      e.comm->forward_comm();
    }
    compute_forces();
    e.neighbor->watch_step_done();
    {
      Timer t(timers[kModify]);
      modify.final_integrate();
      modify.end_of_step(ntimestep);
    }
    Timer t(timers[kOutput]);
    const bool last = ntimestep == laststep;
    const bool thermo_due = last || (e.thermo->every > 0 && ntimestep % e.thermo->every == 0);
    // Fixes that halt a run decide collectively, so every rank leaves together
    // (with a thermo line for the step where it stopped).
    if (ntimestep == e.output->next) e.output->write(ntimestep);  // dumps first, as at setup
    if (thermo_due || halt_requested || stop_signal != 0) e.thermo->line();
    if (stop_signal != 0) {
      stop_restart_ = e.output->write_restart_now(ntimestep);
      break;
    }
    if (halt_requested) break;
    if (ntimestep % 64 == 0) e.thermo->progress();
  }
}

void Update::run(std::int64_t n, bool pre, bool post) {
  Engine& e = engine_;
  if (n < 0) throw InputError("run needs a non-negative number of steps");
  firststep = ntimestep;
  laststep = ntimestep + n;
  builds_before_ = e.neighbor->nbuilds;  // the report counts this run's builds, set-up included
  if (!bounds_set_) {
    beginstep = firststep;
    endstep = laststep;
  }
  bounds_set_ = false;
  running = true;
  halt_requested = false;
  stop_signal = 0;
  if (pre || first_run) setup();
  first_run = false;
  // from here on the forces in memory are those of the current particles, so
  // restart files written during the run (restart N, a stop by a signal) store
  // them and the continuation starts from them, as the run itself goes on
  forces_current = true;
  // the time split covers the loop only, not setup
  std::fill(std::begin(timers), std::end(timers), 0.0);
  for (auto& f : e.modify->fixes)
    f->run_time = 0.0;
  if (!e.modify->has_integrator() && n > 0) {
    e.logger->warning("no fix integrates the particles' motion (e.g. fix nve/sphere); they will not move");
  }
  const double t0 = MPI_Wtime();
  loop_start_wall = t0;
  step_loop(n);
  run_wall_time = MPI_Wtime() - t0;
  running = false;
  forces_current = true;
  // Keep contact history keyed by particle ids between runs (particles may be
  // added, deleted or moved before the next run rebuilds the lists).
  if (ContactHistory* history = e.force->contact_history()) history->save(*e.neighbor, *e.particles);
  if (post) report();
  if (stop_signal != 0) stop_after_signal();
}

void Update::stop_after_signal() {
  const std::string& restart_file = stop_restart_;
  // the end of the whole `run` command (several chunks with `run ... every`)
  const std::int64_t end = std::max(laststep, command_end_);
  std::string msg = "Run stopped by " + signal_name(stop_signal) + " at step " + std::to_string(ntimestep) +
                    " (the run was to end at step " + std::to_string(end) + "). ";
  if (!restart_file.empty()) {
    msg += "Restart file '" + restart_file + "' written at step " + std::to_string(ntimestep) +
           ": to continue, read it with 'read_restart " + restart_file +
           "' in place of the set-up and run the remaining steps (e.g. 'run " + std::to_string(end) +
           " upto').";
  } else {
    msg +=
        "No restart file was written: the script has no restart command (add e.g. 'restart 10000 "
        "restart.*' before the run to be able to continue).";
  }
  throw StopRequested(msg);
}

namespace {
// Rows of LAMMPS' timing table, one per value: its minimum, mean and maximum
// over the ranks; %varavg is the spread (max - min) relative to the mean, so a
// large value marks a load imbalance; %total is the mean's share of the loop
// time. With skip_zero, rows whose maximum is 0 are left out.
std::string timing_rows(MPI_Comm world, int nprocs, double wall, const std::vector<std::string>& names,
                        const std::vector<double>& mine, int width, bool skip_zero) {
  const int n = static_cast<int>(mine.size());
  std::vector<double> tmin(n), tsum(n), tmax(n);
  MPI_Allreduce(mine.data(), tmin.data(), n, MPI_DOUBLE, MPI_MIN, world);
  MPI_Allreduce(mine.data(), tsum.data(), n, MPI_DOUBLE, MPI_SUM, world);
  MPI_Allreduce(mine.data(), tmax.data(), n, MPI_DOUBLE, MPI_MAX, world);
  std::string text;
  char line[512];
  for (int k = 0; k < n; ++k) {
    if (skip_zero && tmax[k] <= 0) continue;
    const double avg = tsum[k] / nprocs;
    std::snprintf(line, sizeof line, "%-*s | %10.4g | %10.4g | %10.4g | %5.1f | %5.1f\n", width,
                  names[k].c_str(), tmin[k], avg, tmax[k], avg > 0 ? 100.0 * (tmax[k] - tmin[k]) / avg : 0.0,
                  wall > 0 ? 100.0 * avg / wall : 0.0);
    text += line;
  }
  return text;
}
}  // namespace

void Update::report() {
  Engine& e = engine_;
  const std::int64_t steps = ntimestep - firststep;
  char line[512];
  std::snprintf(line, sizeof line, "Loop time of %g on %d procs for %lld steps with %lld atoms\n\n",
                run_wall_time, e.nprocs, static_cast<long long>(steps),
                static_cast<long long>(e.particles->natoms));
  e.logger->print(line);
  if (run_wall_time > 0 && steps > 0) {
    std::snprintf(line, sizeof line, "Performance: %.4g particle-steps/s, %.4g steps/s\n",
                  static_cast<double>(e.particles->natoms) * steps / run_wall_time, steps / run_wall_time);
    e.logger->print(line);
  }
  // LAMMPS' MPI task timing breakdown: each section's time on the ranks.
  // "Other" is the loop time not in any section on the rank where it is largest.
  std::vector<double> mine(timers, timers + kNumTimers);
  double other = run_wall_time;
  for (double t : mine)
    other -= t;
  mine.push_back(std::max(0.0, other));
  e.logger->print(
      "Section |  min time  |  avg time  |  max time  |%varavg| %total\n"
      "---------------------------------------------------------------\n" +
      timing_rows(e.world, e.nprocs, run_wall_time, {"Pair", "Neigh", "Comm", "Modify", "Output", "Other"},
                  mine, 7, false));
  report_fixes();
  std::snprintf(line, sizeof line, "Neighbor list builds = %lld\n\n",
                static_cast<long long>(e.neighbor->nbuilds - builds_before_));
  e.logger->print(line);
  e.logger->flush();
}

// Each fix's share, in the same columns: the time in its timestep hooks.
// Hooks called while reneighbouring (pre_neighbor, post_neighbor) are counted
// under Neigh in the section table, the others under Modify. Every rank has
// the same fixes in the same order (fix commands run on all ranks); fixes
// that took no time (no timestep hook: property/global, ...) are left out.
void Update::report_fixes() {
  Engine& e = engine_;
  if (e.modify->fixes.empty() || run_wall_time <= 0) return;
  std::vector<std::string> names;
  std::vector<double> mine;
  for (const auto& f : e.modify->fixes) {
    names.push_back("fix " + f->id + " " + f->style);
    mine.push_back(f->run_time);
  }
  const std::string text = timing_rows(e.world, e.nprocs, run_wall_time, names, mine, 31, true);
  if (text.empty()) return;
  e.logger->print(
      "\nFix (ID style)                  |  min time  |  avg time  |  max time  |%varavg| %total\n"
      "-----------------------------------------------------------------------------------------\n" +
      text);
}

// run N [upto] [start S] [stop S] [pre yes|no] [post yes|no] [every M "commands"]
void Update::run_command(const Args& args) {
  if (args.empty())
    throw InputError(
        "usage: run N [upto] [start S] [stop S] [pre yes|no] [post yes|no] [every M command ...]");
  std::int64_t n = parse_int(args[0], "run steps");
  bool upto = false, pre = true, post = true;
  std::int64_t start = -1, stop = -1, every = 0;
  std::vector<std::string> commands;
  for (std::size_t k = 1; k < args.size(); ++k) {
    const std::string& w = args[k];
    auto value = [&]() -> const std::string& {
      if (k + 1 >= args.size()) throw InputError("run keyword '" + w + "' needs a value");
      return args[++k];
    };
    if (w == "upto")
      upto = true;
    else if (w == "start")
      start = parse_int(value(), "run start");
    else if (w == "stop")
      stop = parse_int(value(), "run stop");
    else if (w == "pre")
      pre = parse_bool(value(), "run pre");
    else if (w == "post")
      post = parse_bool(value(), "run post");
    else if (w == "every") {
      every = parse_int(value(), "run every");
      if (every <= 0) throw InputError("run every needs a positive number of steps");
      commands.assign(args.begin() + k + 1, args.end());
      break;
    } else {
      throw InputError("unknown run keyword '" + w + "'; expected upto, start, stop, pre, post or every");
    }
  }
  if (upto) n -= ntimestep;
  if (n < 0) throw InputError("run upto a step that has already passed");
  command_end_ = ntimestep + n;
  if (start >= 0 || stop >= 0) {
    beginstep = start >= 0 ? start : ntimestep;
    endstep = stop >= 0 ? stop : ntimestep + n;
    bounds_set_ = true;
  }
  if (every == 0) {
    run(n, pre, post);
    return;
  }
  // run in chunks of `every` steps, executing the commands after each chunk
  std::int64_t done = 0;
  bool first = true;
  const bool keep_bounds = bounds_set_;
  if (!keep_bounds) {
    beginstep = ntimestep;
    endstep = ntimestep + n;
  }
  while (done < n) {
    const std::int64_t chunk = std::min(every, n - done);
    bounds_set_ = true;
    run(chunk, first || pre, post);
    first = false;
    done += chunk;
    for (const auto& c : commands) {
      if (c != "NULL") engine_.input_line(c);
    }
  }
}

void cmd_run(Engine& e, const Args& a) {
  e.update->run_command(a);
}
void cmd_timestep(Engine& e, const Args& a) {
  require_args(a, 1, 1, "timestep DT");
  e.update->set_timestep(parse_double(a[0], "timestep"));
}
void cmd_reset_timestep(Engine& e, const Args& a) {
  require_args(a, 1, 1, "reset_timestep N");
  const auto n = parse_int(a[0], "reset_timestep");
  if (n < 0) throw InputError("reset_timestep needs N >= 0");
  e.update->atime = e.update->time();
  e.update->ntimestep = n;
  e.update->atimestep = n;
}
GRANARY_COMMAND("run", cmd_run);
GRANARY_COMMAND("timestep", cmd_timestep);
GRANARY_COMMAND("reset_timestep", cmd_reset_timestep);

}  // namespace granary
