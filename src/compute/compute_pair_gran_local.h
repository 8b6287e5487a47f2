// `compute ID group pair/gran/local [pos] [vel] [id] [force] [force_normal]
// [force_tangential] [torque] [history] [contactArea] [delta] [contactPoint]`:
// one row per particle-particle contact (both particles in the group) with the
// requested values, in LIGGGHTS' column order whatever the order of the
// keywords. The forces are those the granular pair style gives for the
// current positions, velocities and contact history (evaluated without
// advancing the history). Each contact is listed once over all ranks, by the
// rank owning its first particle. See doc/computes/pair_gran_local.md.
#pragma once

#include "compute/compute_gran_local.h"

namespace granary {

class PairGranular;

class ComputePairGranLocal : public ComputeGranLocal {
 public:
  ComputePairGranLocal(Engine& engine, const Args& args);

  void init() override;
  void compute_local() override;

 protected:
  int history_size() const override;
  bool wall() const override { return false; }

 private:
  /// The granular pair style, or an InputError naming what is missing.
  PairGranular& pair() const;
};

}  // namespace granary
