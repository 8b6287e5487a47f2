// The engine: one context object that owns every subsystem.
//
// Subsystems are created in this order, and each may use the ones before it:
//   logger    screen and log-file output (rank 0 writes)
//   input     script reader, variables, control flow (needs logger)
//   particles per-particle storage
//   domain    box, boundaries, regions, this rank's subdomain
//   groups    named particle groups (bit masks)
//   comm      MPI decomposition: ghosts, exchange, forward/reverse communication
//   neighbor  bins, neighbour lists, rebuild decisions
//   force     the pair style and its material parameters
//   modify    fixes (one list per timestep hook) and computes
//   update    timestep, step counter, simulated time, the run loop
//   thermo    thermodynamic output
//   output    dumps and periodic restart files
// `clear` destroys and recreates everything after `input` (variables survive).
#pragma once

#include <mpi.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/utils.h"

namespace granary {

class Logger;
class Input;
class Particles;
class Domain;
class Groups;
class Comm;
class Neighbor;
class Force;
class Modify;
class Update;
class Thermo;
class Output;
class Clumps;

class Engine {
 public:
  explicit Engine(MPI_Comm world);
  ~Engine();
  Engine(const Engine&) = delete;
  Engine& operator=(const Engine&) = delete;

  /// The `clear` command: forget particles, box, styles and settings; keep variables.
  void clear();

  /// Execute one command (first word is the command name) through the command
  /// registry. Unknown names raise InputError with a suggestion.
  void execute(const Args& words);
  /// Execute one script line through the input layer (substitution applies).
  void input_line(const std::string& line);

  // ---- values used by expressions, thermo output and styles (engine_eval.cpp)
  /// Thermo keyword ("step", "time", "dt", "atoms", "ke", "cpu", "vol", ...);
  /// sets found = false when the name is not a keyword.
  double thermo_keyword(const std::string& name, bool& found);
  /// Global value of compute ID: index 0 = its scalar, i >= 1 = element i of its vector.
  double compute_value(const std::string& id, int index);
  /// Global value of fix ID, same indexing.
  double fix_value(const std::string& id, int index);
  /// Group functions count(g), mass(g), xcm(g,dim), vcm(g,dim), bound(g,xmin), ...
  /// with an optional region as last argument.
  double group_function(const std::string& name, const Args& args);
  /// Per-atom property of the local particles ("x", "vx", "mass", "radius",
  /// "type", "id", "fx", "omegax", "tqx", "density", ...); false if unknown.
  bool atom_vector(const std::string& name, std::vector<double>& out);
  /// Per-atom values of compute ID (col 0 = its per-atom vector, col >= 1 = array column).
  void compute_peratom(const std::string& id, int col, std::vector<double>& out);
  /// Per-atom values of fix ID, same indexing.
  void fix_peratom(const std::string& id, int col, std::vector<double>& out);

  // ---- deleting particles (engine.cpp): every deletion goes through here
  /// Delete owned particle i and everything keyed on it (its contact history
  /// in the pair style's store; per-particle fields go with the particle).
  /// The last owned particle moves into slot i and ghosts are dropped. Not
  /// collective; body records of clumps are FixMultisphere's to remove.
  void delete_particle(int i);
  /// Delete the owned particles with doomed[i] != 0 (nlocal entries), from the
  /// last to the first (a particle moved into a freed slot has been looked at
  /// already). Returns the number deleted on this rank.
  long long delete_particles(const std::vector<char>& doomed);

  /// Called with the words of every command before it runs (after
  /// substitution); it may refuse one by throwing InputError. Unset in the
  /// granary program; the engine fuzz targets keep random scripts small and
  /// inside their folder with it (unittest/fuzz/fuzz_engine.cpp).
  std::function<void(const Args&)> command_guard;

  MPI_Comm world;
  int rank = 0;
  int nprocs = 1;

  std::unique_ptr<Logger> logger;
  std::unique_ptr<Input> input;
  std::unique_ptr<Particles> particles;
  std::unique_ptr<Domain> domain;
  std::unique_ptr<Groups> groups;
  std::unique_ptr<Comm> comm;
  std::unique_ptr<Neighbor> neighbor;
  std::unique_ptr<Force> force;
  std::unique_ptr<Modify> modify;
  std::unique_ptr<Update> update;
  std::unique_ptr<Thermo> thermo;
  std::unique_ptr<Output> output;
  /// The rigid clumps: set by fix multisphere while it exists, else null.
  Clumps* clumps = nullptr;

 private:
  void create_subsystems();
  void destroy_subsystems();
};

}  // namespace granary
