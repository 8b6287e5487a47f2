// `compute ID group pair/gran/local [pos] [vel] [id] [force] [force_normal]
// [force_tangential] [torque] [history] [contactArea] [delta] [contactPoint]`:
// one row per particle-particle contact (both particles in the group) with the
// requested values, in LIGGGHTS' column order whatever the order of the
// keywords. The forces are those the granular pair style gives for the
// current positions, velocities and contact history (evaluated without
// advancing the history). Each contact is listed once over all ranks, by the
// rank owning its first particle. See doc/computes/pair_gran_local.md.
#pragma once

#include <string>
#include <vector>

#include "compute/compute.h"

namespace granary {

class PairGranular;

class ComputePairGranLocal : public Compute {
 public:
  ComputePairGranLocal(Engine& engine, const Args& args);

  void init() override;
  void compute_local() override;

  /// First column of each output in a row (-1: not requested), in LIGGGHTS'
  /// order: pos (x1 y1 z1 x2 y2 z2), vel (6), id (id1 id2 periodic), force,
  /// force_normal, force_tangential, torque (3 each), history (nhistory),
  /// contactArea, delta (1 each), contactPoint (3).
  struct Layout {
    int pos = -1, vel = -1, id = -1, force = -1, force_normal = -1, force_tangential = -1, torque = -1,
        history = -1, contact_area = -1, delta = -1, contact_point = -1;
    int nhistory = 0;
    int ncols = 0;
  };
  /// The layout for the current pair style (the number of history values
  /// depends on it).
  Layout layout() const;

  /// Local indices of the two particles of each row of the last
  /// compute_local() (the second may be a ghost); valid until particles move
  /// between ranks.
  std::vector<int> row_i, row_j;

 private:
  /// The granular pair style, or an InputError naming what is missing.
  PairGranular& pair() const;

  bool want_pos_ = false, want_vel_ = false, want_id_ = false, want_force_ = false, want_fn_ = false,
       want_ft_ = false, want_torque_ = false, want_history_ = false, want_area_ = false, want_delta_ = false,
       want_point_ = false;
};

}  // namespace granary
