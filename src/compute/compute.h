// Base class of computes: quantities evaluated on demand (c_ID, c_ID[i], per-atom).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/utils.h"

namespace granary {

class Engine;

class Compute {
 public:
  /// args = "ID group-ID style style-args...".
  Compute(Engine& engine, const Args& args);
  virtual ~Compute() = default;

  virtual void init() {}
  /// Called by uncompute before the compute is deleted (release per-particle fields here).
  virtual void uncomputed() {}
  /// Global scalar (collective: every rank calls it together).
  virtual double compute_scalar() { return 0.0; }
  /// Global vector into `vector` (collective).
  virtual void compute_vector() {}
  /// Per-atom values of the local particles into vector_atom (cols 0) or array_atom.
  virtual void compute_peratom() {}
  /// Local values (rows of items this rank holds, e.g. contacts) into
  /// array_local (collective: every rank calls it together).
  virtual void compute_local() {}
  /// A global array (size_array_rows x size_array_cols, row-major in `array`).
  virtual void compute_array() {}

  bool scalar_flag = false;
  int size_vector = 0;
  bool peratom_flag = false;
  int peratom_cols = 0;    // 0: a per-atom vector
  bool extensive = false;  // scalar grows with the number of particles (thermo_modify norm)
  bool local_flag = false;
  int size_local_cols = 0;                       // 0: a local vector
  int size_local_rows = 0;                       // rows of this rank after compute_local()
  int size_array_rows = 0, size_array_cols = 0;  // a global array: 0 columns = none

  std::vector<double> vector;
  std::vector<double> vector_atom;
  std::vector<std::vector<double>> array_atom;  // [col][i]
  std::vector<double> array_local;              // row-major: [row * max(1, size_local_cols) + col]
  std::vector<double> array;                    // global array, row-major: [row * size_array_cols + col]

  // cache: step at which each output was last computed (-1: never)
  std::int64_t invoked_scalar = -1, invoked_vector = -1, invoked_peratom = -1, invoked_local = -1,
               invoked_array = -1;
  double scalar = 0.0;

  std::string id, style;
  int igroup = 0;
  int groupbit = 1;

 protected:
  /// InputError unless the ghost shell holds every particle within `cutoff`
  /// of an owned one (always so on one rank without periodic boundaries).
  void require_ghost_reach(double cutoff) const;

  Engine& engine_;
  Args args_;
};

}  // namespace granary
