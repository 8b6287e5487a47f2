// What compute pair/gran/local and compute wall/gran/local share: their
// keywords (pos vel id force force_normal force_tangential torque history
// contactArea delta contactPoint), the column layout of a row (LIGGGHTS'
// order whatever the order of the keywords) and the particles of each row,
// which dump local/gran/vtk reads.
#pragma once

#include <string>
#include <vector>

#include "compute/compute.h"

namespace granary {

class ComputeGranLocal : public Compute {
 public:
  /// First column of each output in a row (-1: not requested), in LIGGGHTS'
  /// order: pos (6), vel (6), id (3), force, force_normal, force_tangential,
  /// torque (3 each), history (nhistory), contactArea, delta (1 each),
  /// contactPoint (3). Pair contacts: pos and vel of the two particles, id =
  /// the two ids and a periodic flag. Wall contacts (wall = true): pos = the
  /// contact point on the wall and the particle centre, vel = the wall's
  /// velocity there and the particle's, id = mesh, triangle and particle id.
  struct Layout {
    int pos = -1, vel = -1, id = -1, force = -1, force_normal = -1, force_tangential = -1, torque = -1,
        history = -1, contact_area = -1, delta = -1, contact_point = -1;
    int nhistory = 0;
    int ncols = 0;
    bool wall = false;
  };
  /// The layout for the current contact models (the number of history
  /// values depends on them).
  Layout layout() const;

  /// Local indices of the two particles of each row of the last
  /// compute_local() (the second may be a ghost; -1 for a wall); valid until
  /// particles move between ranks.
  std::vector<int> row_i, row_j;

 protected:
  /// Parses the keywords (args from index 3); none: LIGGGHTS' default set.
  ComputeGranLocal(Engine& engine, const Args& args);
  /// size_local_cols for a layout: one column is a local vector (0), as in
  /// LIGGGHTS; more make a local array.
  static int local_cols(const Layout& L) { return L.ncols == 1 ? 0 : L.ncols; }
  /// Doubles of contact history per contact (0 while unknown).
  virtual int history_size() const = 0;
  virtual bool wall() const = 0;

  bool want_pos_ = false, want_vel_ = false, want_id_ = false, want_force_ = false, want_fn_ = false,
       want_ft_ = false, want_torque_ = false, want_history_ = false, want_area_ = false, want_delta_ = false,
       want_point_ = false;
};

}  // namespace granary
