// fix clog-detect: counts the bodies that pass an outlet, detects clogs
// (nothing passed for a time T), records each avalanche and acts on the clog.
//
//   fix ID group clog-detect outlet REGION timeout T [arch REGION] [arch_layer DZ]
//       [action halt|delete|kick|none] [kick VX VY VZ] [still REGION V] [stop_height H]
//       [stop_empty N] [final_action yes|no] [height_region REGION|NULL] [quantile Q]
//       [remove yes|no] [file F.csv|NULL] [every N]
//
// Design (see doc/fixes/clog_detect.md):
// - A body is a free sphere or a clump. Each body is represented by exactly
//   one owned particle: the free sphere itself, or the clump's sub-sphere 0
//   (fix multisphere's sub-sphere index field), whose rank looks at the
//   clump's centre of mass (replicated on every rank). So one pass over the
//   owned particles sees every body once, without communication.
// - The check runs in post_integrate (positions of the new step) every N
//   steps: an O(nlocal) scan with no allocation, then one MPI_Allreduce of
//   1 + 2 ntypes + 1 numbers. Everything else (avalanche bookkeeping, the
//   timeout, the actions) follows from replicated values, identically on
//   every rank; further collectives happen only at passages and clogs.
// - Removal (remove yes, action delete) asks for a reneighbouring step
//   (Neighbor::force_rebuild) and removes the particles in pre_exchange of the
//   same step, where the contact history is keyed by particle ids and there
//   are no ghosts (as insertion adds them there). Clumps go whole, through
//   Clumps::remove_bodies (shared with delete_atoms mol yes).
// - With remove no, a counted body carries a flag in a per-particle field
//   (on its representative), which migrates with it, is stored in restart
//   files and survives the id renumbering of delete_atoms compress yes.
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "comm/collectives.h"
#include "core/atomic_file.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/logger.h"
#include "core/registry.h"
#include "core/update.h"
#include "domain/domain.h"
#include "domain/region.h"
#include "fix/fix.h"
#include "particles/clumps.h"
#include "core/modify.h"
#include "neighbor/contact_history.h"
#include "neighbor/neighbor.h"
#include "core/force.h"
#include "pair/pair.h"
#include "particles/particles.h"

namespace granary {

namespace {

// 2: per avalanche also the bodies acted on at its clog (format 1 is still read)
constexpr int kRestartFormat = 2;

const char* kUsage =
    "fix ID group clog-detect outlet REGION timeout T [arch REGION] [arch_layer DZ] "
    "[action halt|delete|kick|none] [kick VX VY VZ] [still REGION V] [stop_height H] [stop_empty N] "
    "[final_action yes|no] [height_region REGION|NULL] [quantile Q] [remove yes|no] [file F.csv|NULL] [every "
    "N]";

std::string num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

class FixClogDetect : public Fix {
 public:
  FixClogDetect(Engine& engine, const Args& args);
  ~FixClogDetect() override;

  unsigned hooks() const override { return POST_INTEGRATE | PRE_EXCHANGE; }
  void init() override;
  void setup() override;
  void post_integrate() override;
  void pre_exchange() override;

  double compute_scalar() override { return static_cast<double>(log_.size()); }
  double compute_vector(int i) override;

  void pack_restart(std::string& out) const override;
  void unpack_restart(const std::string& in) override;

 private:
  enum State { kFlowing = 0, kClogged = 1, kFinished = 2 };
  enum class Action { Halt, Delete, Kick, None };

  struct Avalanche {
    double t_start = 0, t_end = 0, t_clog = 0;
    long long bodies = 0;
    double mass = 0, fill = 0;
    long long arch = 0;                  // bodies deleted or kicked at the clog that ended it
    std::vector<long long> bodies_type;  // per atom type 1..ntypes
    std::vector<double> mass_type;
  };

  std::string label() const { return "fix " + id + " (clog-detect)"; }
  /// Whether owned particle i stands for a body of the group; its centre and
  /// clump index (-1 for a free sphere).
  bool representative(int i, Vec3& centre, int& b) const;
  double body_mass(int i, int b) const {
    return b >= 0 ? ms_->bodies().mass[b] : engine_.particles->rmass[i];
  }
  bool counted(int i) const {
    return counted_field_ >= 0 && engine_.particles->extras[counted_field_].data[i] != 0.0;
  }
  void start_avalanche(double t);
  void record_passage(double now);
  void declare_clog(double now);
  /// Fill height (collective): the quantile of the body centres' heights.
  double fill_height();
  /// Bodies of the group whose centre is in the arch region: free spheres
  /// owned here (local indices) and clumps (ids, gathered on every rank).
  void arch_bodies(std::vector<int>& free_local, std::vector<tagint>& clumps);
  /// Deletes or kicks the arch; returns the number of bodies acted on.
  long long act_on_arch();
  /// Whether every body of the group in the `still` region moves slower than
  /// the `still` speed (collective).
  bool arch_at_rest();
  void rewrite_file();
  void write_row(const Avalanche& a, std::size_t index);
  void size_types(int ntypes);

  // settings
  std::string outlet_id_, arch_id_, height_id_, file_, still_id_;
  double timeout_ = -1.0;
  double arch_layer_ = -1.0;   // < 0: every body in the arch region
  double still_speed_ = -1.0;  // < 0: no rest condition
  Action action_ = Action::Halt;
  Vec3 kick_{0, 0, 0};
  bool kick_given_ = false, action_given_ = false;
  double stop_height_ = 0.0;
  bool stop_given_ = false;
  int stop_empty_ = 0;         // end after this many empty avalanches in a row (0: never)
  bool final_action_ = false;  // act on the arch also at the clog that ends the discharge
  double quantile_ = 0.99;
  bool remove_ = true;
  int every_ = 1;

  // cached at init
  const Region* outlet_ = nullptr;
  const Region* arch_ = nullptr;
  const Region* height_ = nullptr;
  const Region* still_ = nullptr;
  Clumps* ms_ = nullptr;
  int index_field_ = -1;    // fix multisphere's sub-sphere index + 1
  int counted_field_ = -1;  // remove no: 1 on the representative of a counted body
  bool any_periodic_ = false;

  // state (replicated on every rank; saved in restart files)
  int ntypes_ = 0;
  int state_ = kFlowing;
  bool started_ = false;    // the first avalanche has begun
  bool has_pass_ = false;   // a body passed in the current avalanche
  double t_start_ = 0.0;    // current avalanche
  double last_pass_ = 0.0;  // time of the last passage in the current avalanche
  Avalanche cur_;           // current avalanche's counts
  long long total_bodies_ = 0;
  double total_mass_ = 0.0;
  long long acted_ = 0;  // bodies deleted or kicked at clogs
  double last_fill_ = 0.0;
  std::vector<Avalanche> log_;

  // work buffers (sized at init; no allocation per step)
  std::vector<double> send_, recv_;
  std::vector<tagint> pending_ids_;       // free spheres to remove (local ids)
  std::vector<long long> pending_local_;  // clumps to remove, found here
  std::vector<tagint> pending_bodies_;    // clumps to remove (all ranks)
  std::vector<int> passed_local_;         // local indices that passed this check
  bool delete_pending_ = false;

  std::FILE* csv_ = nullptr;  // rank 0
  bool file_dirty_ = true;    // rewrite in full at the next init
};

FixClogDetect::FixClogDetect(Engine& engine, const Args& args) : Fix(engine, args) {
  const std::string what = label();
  for (std::size_t k = 3; k < args.size();) {
    const std::string& w = args[k];
    auto value = [&](std::size_t m) -> const std::string& {
      if (k + m >= args.size())
        throw InputError(what + ": keyword '" + w + "' needs " + std::to_string(m) +
                         " value(s); usage: " + kUsage);
      return args[k + m];
    };
    std::size_t used = 1;
    if (w == "outlet") {
      outlet_id_ = value(1);
    } else if (w == "timeout") {
      timeout_ = parse_double(value(1), what + " timeout");
      if (!(timeout_ > 0.0))
        throw InputError(what + ": timeout must be a positive time in seconds of simulated time, got '" +
                         args[k + 1] + "'");
    } else if (w == "arch") {
      arch_id_ = value(1);
    } else if (w == "arch_layer") {
      arch_layer_ = parse_double(value(1), what + " arch_layer");
      if (!(arch_layer_ >= 0.0))
        throw InputError(what +
                         ": arch_layer must be a height >= 0 (m) above the lowest body of the arch "
                         "region, got '" +
                         args[k + 1] + "'");
    } else if (w == "still") {
      value(2);  // checks that the region and the speed are there
      still_id_ = args[k + 1];
      still_speed_ = parse_double(args[k + 2], what + " still");
      if (!(still_speed_ > 0.0))
        throw InputError(what + ": still needs a region and a positive speed (m/s), got '" + args[k + 2] +
                         "'");
      used = 2;
    } else if (w == "action") {
      const std::string& a = value(1);
      if (a == "halt")
        action_ = Action::Halt;
      else if (a == "delete")
        action_ = Action::Delete;
      else if (a == "kick")
        action_ = Action::Kick;
      else if (a == "none")
        action_ = Action::None;
      else {
        const std::string hint = did_you_mean(a, {"halt", "delete", "kick", "none"});
        throw InputError(what + ": unknown action '" + a + "'" + (hint.empty() ? "" : "; " + hint) +
                         "; expected halt, delete, kick or none");
      }
      action_given_ = true;
    } else if (w == "kick") {
      value(3);  // checks that the three components are there
      for (int d = 0; d < 3; ++d)
        kick_[d] = parse_double(args[k + 1 + d], what + " kick velocity");
      kick_given_ = true;
      used = 3;
    } else if (w == "stop_height") {
      stop_height_ = parse_double(value(1), what + " stop_height");
      stop_given_ = true;
    } else if (w == "stop_empty") {
      const long long n = parse_int(value(1), what + " stop_empty");
      if (n < 1) throw InputError(what + ": stop_empty needs a positive number of avalanches");
      stop_empty_ = static_cast<int>(n);
    } else if (w == "final_action") {
      final_action_ = parse_bool(value(1), what + " final_action");
    } else if (w == "height_region") {
      height_id_ = value(1) == "NULL" ? "" : value(1);
    } else if (w == "quantile") {
      quantile_ = parse_double(value(1), what + " quantile");
      if (!(quantile_ > 0.0 && quantile_ <= 1.0))
        throw InputError(what + ": quantile must lie in (0, 1], got '" + args[k + 1] + "'");
    } else if (w == "remove") {
      remove_ = parse_bool(value(1), what + " remove");
    } else if (w == "file") {
      file_ = value(1) == "NULL" ? "" : value(1);
    } else if (w == "every") {
      const long long n = parse_int(value(1), what + " every");
      if (n < 1) throw InputError(what + ": every needs a positive number of steps");
      every_ = static_cast<int>(n);
    } else {
      const std::string hint = did_you_mean(
          w, {"outlet", "timeout", "arch", "arch_layer", "action", "kick", "still", "stop_height",
              "stop_empty", "final_action", "height_region", "quantile", "remove", "file", "every"});
      throw InputError(what + ": unknown keyword '" + w + "'" + (hint.empty() ? "" : "; " + hint) +
                       "; usage: " + kUsage);
    }
    k += used + 1;
  }
  if (outlet_id_.empty())
    throw InputError(what + ": the outlet REGION keyword is required; usage: " + kUsage);
  if (timeout_ < 0.0) throw InputError(what + ": the timeout T keyword is required; usage: " + kUsage);
  if (kick_given_ && !action_given_) action_ = Action::Kick;
  if (action_ == Action::Kick && !kick_given_)
    throw InputError(what + ": action kick needs the velocity: kick VX VY VZ");
  if (kick_given_ && action_ != Action::Kick)
    throw InputError(what + ": kick VX VY VZ is only used with action kick");
  if ((action_ == Action::Delete || action_ == Action::Kick) && arch_id_.empty())
    throw InputError(what + ": action " + (action_ == Action::Delete ? "delete" : "kick") +
                     " acts on the bodies in the arch region: give arch REGION");
  if (final_action_ && action_ != Action::Delete && action_ != Action::Kick)
    throw InputError(
        what + ": final_action yes acts on the arch at the last clog: use it with action delete or kick");
  if (arch_layer_ >= 0.0 && arch_id_.empty())
    throw InputError(what + ": arch_layer selects bodies of the arch region: give arch REGION");
  engine.domain->region_or_error(outlet_id_, what + " outlet");
  if (!arch_id_.empty()) engine.domain->region_or_error(arch_id_, what + " arch");
  if (!still_id_.empty()) engine.domain->region_or_error(still_id_, what + " still");
  if (!height_id_.empty()) engine.domain->region_or_error(height_id_, what + " height_region");
  scalar_flag = true;
  size_vector = 12;
  restart_global = true;
  nevery = every_;
  if (!remove_)
    counted_field_ = engine.particles->add_field("clog-detect/" + id + "/counted", 1, false, true);
}

FixClogDetect::~FixClogDetect() {
  if (csv_) std::fclose(csv_);
}

void FixClogDetect::size_types(int ntypes) {
  ntypes_ = ntypes;
  cur_.bodies_type.assign(ntypes, 0);
  cur_.mass_type.assign(ntypes, 0.0);
}

void FixClogDetect::init() {
  Engine& e = engine_;
  const std::string what = label();
  outlet_ = e.domain->region_or_error(outlet_id_, what + " outlet");
  arch_ = arch_id_.empty() ? nullptr : e.domain->region_or_error(arch_id_, what + " arch");
  height_ = height_id_.empty() ? nullptr : e.domain->region_or_error(height_id_, what + " height_region");
  still_ = still_id_.empty() ? nullptr : e.domain->region_or_error(still_id_, what + " still");
  ms_ = e.clumps;
  index_field_ = ms_ ? e.particles->find_field("multisphere/index") : -1;
  if (!remove_) counted_field_ = e.particles->add_field("clog-detect/" + id + "/counted", 1, false, true);
  any_periodic_ = e.domain->periodic[0] || e.domain->periodic[1] || e.domain->periodic[2];
  const int nt = e.particles->ntypes;
  if (ntypes_ == 0) {
    size_types(nt);
  } else if (ntypes_ != nt) {
    throw InputError(what + ": the state read from the restart file is for " + std::to_string(ntypes_) +
                     " atom types, the simulation has " + std::to_string(nt));
  }
  send_.assign(2 + 2 * static_cast<std::size_t>(ntypes_), 0.0);
  recv_.assign(send_.size(), 0.0);
  if (file_dirty_) rewrite_file();
}

void FixClogDetect::setup() {
  const double now = engine_.update->time();
  // the discharge starts with the first run; after a halt at a clog the next
  // run (the script has dealt with the arch) starts the next avalanche
  if (!started_ || (state_ == kClogged && action_ == Action::Halt)) {
    started_ = true;
    start_avalanche(now);
  }
}

void FixClogDetect::start_avalanche(double t) {
  t_start_ = t;
  has_pass_ = false;
  last_pass_ = t;
  cur_.bodies = 0;
  cur_.mass = 0.0;
  std::fill(cur_.bodies_type.begin(), cur_.bodies_type.end(), 0);
  std::fill(cur_.mass_type.begin(), cur_.mass_type.end(), 0.0);
  state_ = kFlowing;
}

bool FixClogDetect::representative(int i, Vec3& centre, int& b) const {
  const Particles& p = *engine_.particles;
  if (!(p.mask[i] & groupbit)) return false;
  if (p.body[i] < 0) {
    b = -1;
    centre = p.x[i];
    if (any_periodic_) {
      int image = Particles::image_pack(0, 0, 0);
      engine_.domain->remap(centre, image);  // not yet wrapped in post_integrate
    }
    return true;
  }
  if (index_field_ < 0 || p.extras[index_field_].data[i] != 1.0) return false;
  b = ms_->bodies().find(p.body[i]);
  if (b < 0) return false;
  centre = ms_->wrapped_centre(b);
  return true;
}

void FixClogDetect::post_integrate() {
  Engine& e = engine_;
  if (!started_ || e.update->ntimestep % every_ != 0) return;
  const Particles& p = *e.particles;
  // scan: bodies whose centre is in the outlet (not yet counted)
  std::fill(send_.begin(), send_.end(), 0.0);
  passed_local_.clear();
  for (int i = 0; i < p.nlocal; ++i) {
    Vec3 c;
    int b;
    if (!representative(i, c, b) || !outlet_->match(c) || counted(i)) continue;
    passed_local_.push_back(i);  // capacity kept between steps
    send_[0] += 1.0;
    if (b >= 0) send_[1] += 1.0;
    const int t = p.type[i] - 1;
    send_[2 + t] += 1.0;
    send_[2 + ntypes_ + t] += body_mass(i, b);
  }
  MPI_Allreduce(send_.data(), recv_.data(), static_cast<int>(send_.size()), MPI_DOUBLE, MPI_SUM, e.world);
  const double now = e.update->time();
  if (recv_[0] > 0.0) record_passage(now);
  if (state_ != kFlowing) return;
  // the clog: nothing passed for timeout seconds (round-off of the step times allowed for)
  const double since = now - (has_pass_ ? last_pass_ : t_start_);
  if (since > timeout_ - 1e-6 * e.update->dt && (!still_ || arch_at_rest())) declare_clog(now);
}

void FixClogDetect::record_passage(double now) {
  Engine& e = engine_;
  Particles& p = *e.particles;
  // flow resumed by itself after a clog that was only recorded (action none)
  if (state_ == kClogged) start_avalanche(now);
  const long long n = std::llround(recv_[0]);
  double mass = 0.0;
  for (int t = 0; t < ntypes_; ++t)
    mass += recv_[2 + ntypes_ + t];
  total_bodies_ += n;
  total_mass_ += mass;
  if (state_ == kFlowing) {
    cur_.bodies += n;
    cur_.mass += mass;
    for (int t = 0; t < ntypes_; ++t) {
      cur_.bodies_type[t] += std::llround(recv_[2 + t]);
      cur_.mass_type[t] += recv_[2 + ntypes_ + t];
    }
    has_pass_ = true;
    last_pass_ = now;
  }
  if (!remove_) {
    for (int i : passed_local_)
      p.extras[counted_field_].data[i] = 1.0;
    return;
  }
  // removed in pre_exchange of this step
  pending_local_.clear();
  for (int i : passed_local_) {
    if (p.body[i] < 0)
      pending_ids_.push_back(p.id[i]);
    else
      pending_local_.push_back(static_cast<long long>(p.body[i]));
  }
  if (recv_[1] > 0.0) {
    const std::vector<long long> all = allgather(e.world, pending_local_);
    pending_bodies_.insert(pending_bodies_.end(), all.begin(), all.end());
  }
  delete_pending_ = true;
  e.neighbor->force_rebuild = true;
}

double FixClogDetect::fill_height() {
  Engine& e = engine_;
  const Particles& p = *e.particles;
  std::vector<double> z;
  for (int i = 0; i < p.nlocal; ++i) {
    Vec3 c;
    int b;
    if (!representative(i, c, b) || counted(i)) continue;
    if (height_ && !height_->match(c)) continue;
    z.push_back(c[2]);
  }
  std::vector<double> all = allgather(e.world, z);
  if (all.empty()) return 0.0;
  std::sort(all.begin(), all.end());
  // the lowest height with at least a fraction `quantile` of the centres at or below it
  const double n = static_cast<double>(all.size());
  std::size_t k = static_cast<std::size_t>(std::ceil(quantile_ * n - 1e-9));
  k = std::clamp<std::size_t>(k, 1, all.size());
  return all[k - 1];
}

bool FixClogDetect::arch_at_rest() {
  Engine& e = engine_;
  const Particles& p = *e.particles;
  double vmax2 = 0.0;
  for (int i = 0; i < p.nlocal; ++i) {
    Vec3 c;
    int b;
    if (!representative(i, c, b) || counted(i) || !still_->match(c)) continue;
    const Vec3& v = b >= 0 ? ms_->bodies().vcm[b] : p.v[i];
    vmax2 = std::max(vmax2, v.dot(v));
  }
  double all = 0.0;
  MPI_Allreduce(&vmax2, &all, 1, MPI_DOUBLE, MPI_MAX, e.world);
  return all < still_speed_ * still_speed_;
}

void FixClogDetect::declare_clog(double now) {
  Engine& e = engine_;
  Avalanche a = cur_;
  a.t_start = t_start_;
  a.t_end = has_pass_ ? last_pass_ : t_start_;
  a.t_clog = now;
  a.fill = fill_height();
  last_fill_ = a.fill;
  // stop_empty: the last N avalanches (this one included) passed nothing (the
  // flow does not restart, e.g. only stagnant zones are left beside the outlet)
  bool empty_run =
      stop_empty_ > 0 && log_.size() + 1 >= static_cast<std::size_t>(stop_empty_) && a.bodies == 0;
  for (std::size_t k = log_.size() + 1 - (empty_run ? stop_empty_ : 1); empty_run && k < log_.size(); ++k)
    empty_run = log_[k].bodies == 0;
  const bool below = stop_given_ && a.fill < stop_height_;
  const bool finished = below || empty_run;
  const char* act = below                       ? "finished (fill height below stop_height)"
                    : finished                  ? "finished (stop_empty avalanches in a row passed nothing)"
                    : action_ == Action::Halt   ? "halting the run"
                    : action_ == Action::Delete ? "deleting the arch"
                    : action_ == Action::Kick   ? "kicking the arch"
                                                : "recorded";
  e.logger->print(label() + ": clog at t = " + num(now) + " s (step " + std::to_string(e.update->ntimestep) +
                  "): avalanche " + std::to_string(log_.size() + 1) + " passed " + std::to_string(a.bodies) +
                  " bodies, " + num(a.mass) + " kg in " + num(a.t_end - a.t_start) + " s; fill height " +
                  num(a.fill) + " m; " + act + "\n");
  if (finished) {
    // final_action: the outlet is left open for the next discharge (e.g. after a refill)
    if (final_action_) a.arch = act_on_arch();
    state_ = kFinished;
    e.update->halt_requested = true;
  } else if (action_ == Action::Halt) {
    state_ = kClogged;
    e.update->halt_requested = true;
  } else if (action_ == Action::None) {
    state_ = kClogged;
  } else {
    a.arch = act_on_arch();
    start_avalanche(now);
  }
  log_.push_back(a);
  write_row(a, log_.size());
}

void FixClogDetect::arch_bodies(std::vector<int>& free_local, std::vector<tagint>& clumps) {
  Engine& e = engine_;
  const Particles& p = *e.particles;
  // the bodies of the group in the arch region, with their centre heights
  std::vector<int> local;
  std::vector<double> z;
  for (int i = 0; i < p.nlocal; ++i) {
    Vec3 c;
    int b;
    if (!representative(i, c, b) || counted(i) || !arch_->match(c)) continue;
    local.push_back(i);
    z.push_back(c[2]);
  }
  // arch_layer: only the lowest layer, centres within DZ of the lowest centre
  double zcut = std::numeric_limits<double>::infinity();
  if (arch_layer_ >= 0.0) {
    double zmin = z.empty() ? std::numeric_limits<double>::infinity() : *std::min_element(z.begin(), z.end());
    double all = zmin;
    MPI_Allreduce(&zmin, &all, 1, MPI_DOUBLE, MPI_MIN, e.world);
    zcut = all + arch_layer_;
  }
  std::vector<long long> mine;
  free_local.clear();
  for (std::size_t k = 0; k < local.size(); ++k) {
    if (z[k] > zcut) continue;
    const int i = local[k];
    if (p.body[i] < 0)
      free_local.push_back(i);
    else
      mine.push_back(static_cast<long long>(p.body[i]));
  }
  const std::vector<long long> all = allgather(e.world, mine);
  clumps.assign(all.begin(), all.end());
}

long long FixClogDetect::act_on_arch() {
  Engine& e = engine_;
  Particles& p = *e.particles;
  std::vector<int> free_local;
  std::vector<tagint> clumps;
  arch_bodies(free_local, clumps);
  long long mine = static_cast<long long>(free_local.size()), nfree = 0;
  MPI_Allreduce(&mine, &nfree, 1, MPI_LONG_LONG, MPI_SUM, e.world);
  const long long n = nfree + static_cast<long long>(clumps.size());
  acted_ += n;
  e.logger->print(label() + ": " + (action_ == Action::Delete ? "deleting " : "kicking ") +
                  std::to_string(n) + " bodies in region " + arch_id_ + "\n");
  if (action_ == Action::Kick) {
    for (int i : free_local)
      p.v[i] = kick_;
    if (ms_) {
      Bodies& bodies = ms_->bodies();
      for (tagint t : clumps) {
        const int b = bodies.find(t);
        if (b >= 0) bodies.vcm[b] = kick_;  // sub-sphere velocities follow in final_integrate
      }
    }
    return n;
  }
  for (int i : free_local)
    pending_ids_.push_back(p.id[i]);
  pending_bodies_.insert(pending_bodies_.end(), clumps.begin(), clumps.end());
  if (n > 0) {
    delete_pending_ = true;
    e.neighbor->force_rebuild = true;
  }
  return n;
}

void FixClogDetect::pre_exchange() {
  if (!delete_pending_) return;
  delete_pending_ = false;
  Engine& e = engine_;
  Particles& p = *e.particles;
  std::sort(pending_ids_.begin(), pending_ids_.end());
  std::vector<char> doomed(p.nlocal, 0);
  for (int i = 0; i < p.nlocal; ++i)
    doomed[i] = p.body[i] < 0 && std::binary_search(pending_ids_.begin(), pending_ids_.end(), p.id[i]);
  long long removed = e.delete_particles(doomed);
  if (!pending_bodies_.empty() && ms_) removed += ms_->remove_bodies(pending_bodies_);
  long long all = 0;
  MPI_Allreduce(&removed, &all, 1, MPI_LONG_LONG, MPI_SUM, e.world);
  p.natoms -= all;
  p.map_clear();
  pending_ids_.clear();
  pending_bodies_.clear();
}

double FixClogDetect::compute_vector(int i) {
  const Avalanche* last = log_.empty() ? nullptr : &log_.back();
  switch (i) {
    case 0:
      return static_cast<double>(log_.size());
    case 1:
      return last ? static_cast<double>(last->bodies) : 0.0;
    case 2:
      return last ? last->mass : 0.0;
    case 3:
      return last ? last->t_end - last->t_start : 0.0;
    case 4:
      return static_cast<double>(total_bodies_);
    case 5:
      return total_mass_;
    case 6:
      return state_;
    case 7:
      return last_fill_;
    case 8:
      if (!started_) return 0.0;
      return engine_.update->time() - (has_pass_ ? last_pass_ : t_start_);
    case 9:
      return state_ == kFinished ? 1.0 : 0.0;
    case 10:
      return static_cast<double>(acted_);
    case 11:
      return static_cast<double>(cur_.bodies);
    default:
      return 0.0;
  }
}

// ------------------------------------------------------------------ file

void FixClogDetect::rewrite_file() {
  Engine& e = engine_;
  file_dirty_ = false;
  if (file_.empty()) return;
  int ok = 1;
  if (e.rank == 0) {
    if (csv_) std::fclose(csv_);
    csv_ = nullptr;
    // the whole log to a temporary name, then renamed: never half-written
    const std::string err = replace_file(file_, [&](std::FILE* f) {
      std::fprintf(f, "# Granary fix clog-detect %s: one row per avalanche through region %s\n", id.c_str(),
                   outlet_id_.c_str());
      std::fprintf(f, "# units: SI (times s, masses kg, heights m, flow_rate kg/s)\n");
      std::fprintf(f, "# settings: fix %s\n", join(args_).c_str());
      std::fprintf(f, "# types:");
      for (int t = 1; t <= ntypes_; ++t)
        std::fprintf(f, " %d", t);
      std::fprintf(f, " (bodies_tK, mass_tK: bodies of atom type K)\n");
      std::fprintf(f,
                   "avalanche,t_start,t_end,t_clog,duration,bodies,mass,flow_rate,fill_height,arch_removed");
      for (int t = 1; t <= ntypes_; ++t)
        std::fprintf(f, ",bodies_t%d,mass_t%d", t, t);
      std::fprintf(f, "\n");
      csv_ = f;
      for (std::size_t k = 0; k < log_.size(); ++k)
        write_row(log_[k], k + 1);
      csv_ = nullptr;
    });
    if (err.empty()) csv_ = std::fopen(file_.c_str(), "a");
    ok = err.empty() && csv_ != nullptr;
  }
  MPI_Bcast(&ok, 1, MPI_INT, 0, e.world);
  if (!ok) throw InputError(label() + ": cannot write the avalanche file '" + file_ + "'; check the path");
}

void FixClogDetect::write_row(const Avalanche& a, std::size_t index) {
  if (!csv_) return;
  const double duration = a.t_end - a.t_start;
  const double rate = duration > 0.0 ? a.mass / duration : 0.0;
  std::fprintf(csv_, "%zu,%s,%s,%s,%s,%lld,%s,%s,%s,%lld", index, num(a.t_start).c_str(),
               num(a.t_end).c_str(), num(a.t_clog).c_str(), num(duration).c_str(), a.bodies,
               num(a.mass).c_str(), num(rate).c_str(), num(a.fill).c_str(), a.arch);
  for (int t = 0; t < ntypes_; ++t)
    std::fprintf(csv_, ",%lld,%s", a.bodies_type[t], num(a.mass_type[t]).c_str());
  std::fprintf(csv_, "\n");
  std::fflush(csv_);
}

// --------------------------------------------------------------- restart

void FixClogDetect::pack_restart(std::string& out) const {
  std::ostringstream os;
  os.precision(17);  // doubles round-trip exactly
  auto put_avalanche = [&](std::ostream& o, const Avalanche& a, int ntypes) {
    o << ' ' << a.t_start << ' ' << a.t_end << ' ' << a.t_clog << ' ' << a.bodies << ' ' << a.mass << ' '
      << a.fill << ' ' << a.arch;
    for (int t = 0; t < ntypes; ++t)
      o << ' ' << a.bodies_type[t] << ' ' << a.mass_type[t];
  };
  os << kRestartFormat << ' ' << ntypes_ << ' ' << state_ << ' ' << started_ << ' ' << has_pass_ << ' '
     << t_start_ << ' ' << last_pass_ << ' ' << total_bodies_ << ' ' << total_mass_ << ' ' << acted_ << ' '
     << last_fill_;
  put_avalanche(os, cur_, ntypes_);
  os << ' ' << log_.size();
  for (const auto& a : log_)
    put_avalanche(os, a, ntypes_);
  out = os.str();
}

void FixClogDetect::unpack_restart(const std::string& in) {
  std::istringstream is(in);
  int format = 0, nt = 0, state = 0;
  bool started = false, has_pass = false;
  auto bad = [&]() { return InputError(label() + ": the restart file's clog-detect state is unreadable"); };
  if (!(is >> format) || format < 1 || format > kRestartFormat) throw bad();
  if (!(is >> nt >> state >> started >> has_pass >> t_start_ >> last_pass_ >> total_bodies_ >> total_mass_ >>
        acted_ >> last_fill_) ||
      nt < 0 || nt > 100000)
    throw bad();
  auto get = [&](Avalanche& a) {
    a.bodies_type.assign(nt, 0);
    a.mass_type.assign(nt, 0.0);
    if (!(is >> a.t_start >> a.t_end >> a.t_clog >> a.bodies >> a.mass >> a.fill)) throw bad();
    a.arch = 0;
    if (format >= 2 && !(is >> a.arch)) throw bad();
    for (int t = 0; t < nt; ++t)
      if (!(is >> a.bodies_type[t] >> a.mass_type[t])) throw bad();
  };
  ntypes_ = nt;
  state_ = state;
  started_ = started;
  has_pass_ = has_pass;
  get(cur_);
  std::size_t n = 0;
  if (!(is >> n)) throw bad();
  log_.assign(n, Avalanche());
  for (auto& a : log_)
    get(a);
  file_dirty_ = true;
}

}  // namespace

GRANARY_FIX_STYLE("clog-detect", FixClogDetect);
GRANARY_FIX_STYLE("clog/detect", FixClogDetect);

}  // namespace granary
