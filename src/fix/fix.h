// Base class of fixes: operations applied during the timestep.
//
// A fix declares the hooks it needs (hooks() returns a bit mask); Modify keeps
// one list per hook and calls them in the order the fixes were defined. The
// order of one timestep is written down in doc/architecture.md.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/utils.h"

namespace granary {

class Engine;

class Fix {
 public:
  enum Hook : unsigned {
    INITIAL_INTEGRATE = 1u << 0,  // first half-kick and drift
    POST_INTEGRATE = 1u << 1,     // after the drift, before communication
    PRE_EXCHANGE = 1u << 2,       // before particles migrate (reneighbour steps only)
    PRE_NEIGHBOR = 1u << 3,       // after migration and ghosts, before the list build
    POST_NEIGHBOR = 1u << 4,      // after the neighbour list build
    PRE_FORCE = 1u << 5,          // after forces are zeroed, before pair forces
    POST_FORCE = 1u << 6,         // after pair forces (walls, gravity, ...)
    FINAL_INTEGRATE = 1u << 7,    // second half-kick
    END_OF_STEP = 1u << 8,        // output-time work every nevery steps
  };

  /// args = "ID group-ID style style-args...".
  Fix(Engine& engine, const Args& args);
  virtual ~Fix() = default;

  virtual unsigned hooks() const = 0;

  virtual void init() {}   // before every run: check settings, cache lookups
  virtual void setup() {}  // start of a run, after the first forces are computed
  virtual void initial_integrate() {}
  virtual void post_integrate() {}
  virtual void pre_exchange() {}
  virtual void pre_neighbor() {}
  virtual void post_neighbor() {}
  virtual void pre_force() {}
  virtual void post_force() {}
  virtual void final_integrate() {}
  virtual void end_of_step() {}
  virtual void reset_dt() {}
  /// Called by unfix just before the fix is destroyed (not when a fix is
  /// replaced by one with the same ID): release per-particle storage only it uses.
  virtual void unfixed() {}
  /// fix_modify: the keyword at args[k] with its values, if this style has
  /// it; returns the number of words it took (0: not a keyword of this style).
  virtual std::size_t modify_param(const Args& /*args*/, std::size_t /*k*/) { return 0; }

  // Global and per-atom outputs (f_ID, f_ID[i]); indices are 1-based in scripts.
  virtual double compute_scalar() { return 0.0; }
  virtual double compute_vector(int /*i: 0-based*/) { return 0.0; }
  virtual void peratom(int /*col: 0 = vector*/, std::vector<double>& /*out*/) {}
  bool scalar_flag = false;
  int size_vector = 0;
  bool peratom_flag = false;
  int peratom_cols = 0;  // 0: a per-atom vector

  /// Global state kept in restart files (counters, random-number state, ...).
  /// A fix defined after read_restart with the same ID and style gets it back.
  /// Called on every rank (collective) before a restart file is written, so
  /// that state held in parts on the ranks can be gathered for pack_restart,
  /// which runs on the writing rank only.
  virtual void prepare_restart() {}
  virtual void pack_restart(std::string& /*out*/) const {}
  virtual void unpack_restart(const std::string& /*in*/) {}
  bool restart_global = false;  // set by fixes that implement the two above

  /// Whether end_of_step() at this step reads the state (collective answer,
  /// the same on every rank): by default every nevery steps; a fix that
  /// keeps its own sampling steps (ave/time, ave/atom, ...) names those. A
  /// step that no fix, output or run end reads may leave work for the next
  /// one (Update::step_observed).
  virtual bool end_of_step_due(std::int64_t step) const { return step % nevery == 0; }

  std::string id, style;
  /// Other IDs f_ID finds this fix by (LIGGGHTS' names of per-atom
  /// properties a fix owns, e.g. f_massflow_ID of fix massflow/mesh).
  std::vector<std::string> aliases;
  int igroup = 0;               // group index
  int groupbit = 1;             // group bit mask
  int nevery = 1;               // end_of_step period
  bool time_integrate = false;  // integrates positions (nve/sphere, multisphere, ...)
  /// Seconds this rank spent in the fix's timestep hooks since the setup of
  /// the current run (kept by Modify, printed by the run's timing report).
  double run_time = 0.0;
  /// Whether the group is `all` (index 0, which every particle is in and no
  /// command removes one from): a loop over the group needs no mask test.
  bool group_is_all() const { return igroup == 0; }

 protected:
  /// The number of particles of the group that are spheres of clumps (collective).
  long long clump_spheres_in_group() const;
  /// InputError unless the group holds no spheres of clumps (for fixes that
  /// move particles, which fix multisphere moves as bodies).
  void require_free_spheres() const;

  Engine& engine_;
  Args args_;
};

}  // namespace granary
