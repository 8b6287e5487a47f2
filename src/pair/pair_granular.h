// Granular contact pair style, assembled at run time from contact sub-models.
//
//   pair_style gran model hertz tangential history rolling_friction cdt   (LIGGGHTS spelling)
//   pair_style hertz/rolling [rolling_friction cdt|epsd|epsd2|epsd3|off] [tangential history|no_history] ...
//   pair_style hybrid gran model hertz ...  (one granular sub-style, LIGGGHTS' pair hybrid)
// All build the same ContactModel; hertz/rolling defaults to Hertz normal
// force, tangential history and cdt rolling friction.
#pragma once

#include "contact/contact_kernels.h"
#include "contact/contact_model.h"
#include <memory>

#include "neighbor/contact_history.h"
#include "pair/liquid_bridge.h"
#include "pair/materials.h"
#include "pair/pair.h"
#include "particles/particles.h"

namespace granary {

class PairGranular : public Pair {
 public:
  PairGranular(Engine& engine, const Args& args, const std::string& style_name);
  void coeff(const Args& args) override;
  void init() override;
  void compute() override;
  int history_size() const override { return contact::history_size(spec_); }
  void history_swap_signs(double* signs) const override { contact::history_swap_signs(spec_, signs); }
  ContactHistory* history() override { return history_size() > 0 ? &history_ : nullptr; }
  ContactTimes contact_times(double vmax, int groupbit) override {
    return granary::contact_times(engine_, materials_, spec(), vmax, groupbit);
  }

  /// The contact model as the kernels evaluate it (a liquid-bridge cohesion is
  /// added by the bridge pass, not by the kernels, and does not appear here).
  const contact::ModelSpec& spec() const { return kernel_spec_; }
  /// Scan the near list (default) or every neighbour-list entry; the results
  /// are the same to the last bit (unittest/test_pair_lane_loop.cpp).
  bool near_list = true;
  const MaterialTable& materials() const { return materials_; }

 private:
  template <class Kernel>
  void loop();
  void take_restart_history();
  contact::ModelSpec spec_;
  /// spec_ as the kernels see it: a liquid-bridge cohesion is computed by bridge_, not by them
  contact::ModelSpec kernel_spec_;
  std::unique_ptr<LiquidBridge> bridge_;  ///< cohesion easo/capillary/viscous or washino/capillary/viscous
  MaterialTable materials_;
  ContactHistory history_;
  bool coeff_set_ = false;
  FieldRef body_mass_;             ///< clump mass of each sub-sphere (fix multisphere), found at init
  std::vector<int> owner_;         // particle of each neighbour-list entry (pair loop)
  std::int64_t owner_build_ = -1;  // the list build owner_ belongs to
  /// The near list: the entries of the neighbour list whose spheres were
  /// within a quarter of the skin of touching when it was built, their two
  /// particles and history slots (copied, so that the pair loop reads them
  /// in step with the entries and not from the arrays of all entries; the
  /// pair loop keeps the slots equal to the entries' own), and the positions
  /// and radii then (owned particles and ghosts). Until some
  /// particle has moved by half that margin (or a radius changed, or the
  /// list was rebuilt) no other entry can touch, so the pair loop scans only
  /// these; the contacts, their order and so the forces are the same. When it
  /// is stale, the pair loop scans every entry and makes it anew on the way.
  bool near_list_current(const Particles& p, double margin);
  std::vector<int> near_;
  std::vector<int> near_i_, near_j_;     // the particle and neighbour of each near entry
  std::vector<std::int32_t> near_slot_;  // and its history slot (with history)
  std::vector<Vec3> near_x_;
  std::vector<double> near_r_;
  std::int64_t near_epoch_ = -1;  // the neighbour list's watch epoch when it was made
};

}  // namespace granary
