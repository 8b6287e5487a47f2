#include "pair/pair_granular.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <algorithm>
#include <memory>
#include <stdexcept>

#include "contact/contact_kernels.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/growth.h"
#include "core/logger.h"
#include "core/registry.h"
#include "core/update.h"
#include "neighbor/neighbor.h"
#include "core/force.h"
#include "pair/pair_loop.h"
#include "particles/particles.h"

namespace granary {

namespace {
bool is_hybrid(const std::string& style) {
  return style == "hybrid" || style == "hybrid/overlay";
}

bool is_granular_substyle(const std::string& w) {
  return w == "gran" || w == "bubble" || w == "gran_bubble";
}

contact::ModelSpec parse_spec(const std::string& style, const Args& args) {
  std::vector<std::string> words;
  if (style == "hertz/rolling") {
    // Granary's name: Hertz, tangential history and cdt rolling unless overridden.
    words = {"model", "hertz", "tangential", "history", "rolling_friction", "cdt"};
    for (std::size_t k = 0; k + 1 < args.size(); k += 2) {
      const std::string slot = args[k] == "rolling" ? "rolling_friction" : args[k];
      bool replaced = false;
      for (std::size_t w = 0; w + 1 < words.size(); w += 2) {
        if (words[w] == slot) {
          words[w + 1] = args[k + 1];
          replaced = true;
        }
      }
      if (!replaced) {
        words.push_back(slot);
        words.push_back(args[k + 1]);
      }
    }
    if (args.size() % 2)
      throw InputError("pair_style hertz/rolling takes keyword/value pairs; '" + args.back() +
                       "' has no value");
  } else if (is_hybrid(style)) {
    // LIGGGHTS' pair hybrid of granular styles: Granary runs one sub-style
    // (gran, or its aliases bubble and gran_bubble) for every type pair
    if (args.empty() || !is_granular_substyle(args[0]))
      throw InputError("pair_style " + style +
                       ": Granary takes one granular sub-style (gran, bubble or "
                       "gran_bubble) followed by its model words, e.g. pair_style " +
                       style + " gran model hertz tangential history; got '" + (args.empty() ? "" : args[0]) +
                       "'");
    for (std::size_t k = 1; k < args.size(); ++k)
      if (is_granular_substyle(args[k]))
        throw InputError("pair_style " + style + ": a second sub-style '" + args[k] +
                         "': Granary runs one contact law for all type pairs (different laws per phase "
                         "are not supported); use one sub-style, or pair_style gran");
    words.assign(args.begin() + 1, args.end());
  } else {
    words = args;
  }
  std::size_t pos = 0;
  contact::ModelSpec spec;
  try {
    spec = contact::parse_model_words(words, pos);
  } catch (const std::invalid_argument& e) {
    throw InputError("pair_style " + style + ": " + e.what());
  }
  if (pos != words.size()) {
    throw InputError("pair_style " + style + ": unexpected word '" + words[pos] +
                     "'; expected model, tangential, rolling_friction, cohesion, damping or limitForce");
  }
  return spec;
}
}  // namespace

PairGranular::PairGranular(Engine& engine, const Args& args, const std::string& style_name)
    : Pair(engine, args) {
  style = style_name;
  spec_ = parse_spec(style_name, args);
  kernel_spec_ = spec_;
  if (contact::liquid_bridge(spec_.cohesion)) {
    kernel_spec_.cohesion = contact::CohesionModel::None;
    kernel_spec_.modify_lb_volume = false;
    bridge_ =
        std::make_unique<LiquidBridge>(engine, spec_.cohesion, spec_.modify_lb_volume, "pair_style " + style);
  }
}

void PairGranular::coeff(const Args& args) {
  if (is_hybrid(style)) {
    // pair_coeff * * SUBSTYLE: the one sub-style, for all type pairs
    require_args(args, 3, 3, "pair_coeff * * " + args_[0]);
    if (args[2] != args_[0])
      throw InputError("pair_coeff for pair_style " + style + ": the sub-style is '" + args_[0] + "', got '" +
                       args[2] + "'; use pair_coeff * * " + args_[0]);
  } else {
    require_args(args, 2, 2, "pair_coeff * *");
  }
  int lo, hi;
  const int n = engine_.particles->ntypes;
  for (int k = 0; k < 2; ++k) {
    parse_type_range(args[k], n, lo, hi);
    if (lo != 1 || hi != n) {
      throw InputError(
          "granular pair styles take their parameters from fix property/global for all "
          "types at once; use pair_coeff * *");
    }
  }
  coeff_set_ = true;
}

void PairGranular::init() {
  if (!coeff_set_) throw InputError("pair style " + style + " needs 'pair_coeff * *' before run");
  materials_.build(engine_, kernel_spec_, "pair_style " + style);
  if (bridge_)
    bridge_->init();  // sets the neighbour range
  else
    engine_.neighbor->range_factor = 1.0;
  if (spec_.surface == contact::SurfaceModel::Multicontact && !engine_.force->multicontact)
    throw InputError("pair style " + style +
                     " with 'surface multicontact' needs fix multicontact/halfspace (e.g. fix mc all "
                     "multicontact/halfspace geometric_prefactor 1.125)");
  body_mass_ = FieldRef(*engine_.particles, kBodyMassField);
  std::vector<double> signs(history_size());
  if (!signs.empty()) history_swap_signs(signs.data());
  if (history_.nvalues() != history_size()) history_.configure(history_size(), signs);
  take_restart_history();
}

// Contact history read by read_restart waits in Force until the pair style
// that uses it initialises; its layout must match this model's.
void PairGranular::take_restart_history() {
  Force& force = *engine_.force;
  if (!force.pending_history) return;
  const ContactHistory& pending = *force.pending_history;
  if (pending.nvalues() == history_size()) {
    history_.adopt(pending);
  } else if (pending.stored() > 0) {
    engine_.logger->warning("the restart file's contact history has " + std::to_string(pending.nvalues()) +
                            " values per contact but pair_style " + style + " " + join(args_) + " uses " +
                            std::to_string(history_size()) + "; contacts start without history");
  }
  if (!force.restart_pair_style.empty() && force.restart_pair_style != style + " " + join(args_)) {
    engine_.logger->warning("pair style differs from the restart file's (" + force.restart_pair_style + ")");
  }
  force.pending_history.reset();
}

// One loop for every model (pair/pair_loop.h), lane::Wide contacts at a time
// (four in a build for AVX2, two otherwise).
template <class Kernel>
void PairGranular::loop() {
  Particles& p = *engine_.particles;
  const Neighbor& list = *engine_.neighbor;
  // contact history: a slot number per neighbour-list entry, values per contact
  const int nh = Kernel::history_size(kernel_spec_);
  const std::size_t nlist = list.neigh.size();
  if (nh > 0 && history_.entries() != nlist) history_.reset(nlist);
  PairLoopData L;
  L.nlocal = p.nlocal;
  L.newton = engine_.force->newton_pair;
  L.offset = list.offset.data();
  L.neigh = list.neigh.data();
  L.x = p.x.data();
  L.v = p.v.data();
  L.omega = p.omega.data();
  L.f = p.f.data();
  L.torque = p.torque.data();
  L.radius = p.radius.data();
  L.rmass = p.rmass.data();
  L.body_mass = body_mass_.data(p);
  L.type = p.type.data();
  L.history = nh > 0 ? &history_ : nullptr;
  L.materials = &materials_;
  L.spec = &kernel_spec_;
  L.dt = {engine_.update->history_dt(), engine_.update->dt};
  if (spec_.surface == contact::SurfaceModel::Multicontact) {
    L.mc = engine_.force->multicontact;
    L.particles = &p;
  }
  // the particle of each list entry, for stage 1's single stream
  if (owner_build_ != list.nbuilds || owner_.size() != list.neigh.size()) {
    assign_fresh(owner_, list.neigh.size(), 0);
    for (int i = 0; i < p.nlocal; ++i)
      std::fill(owner_.begin() + L.offset[i], owner_.begin() + L.offset[i + 1], i);
    owner_build_ = list.nbuilds;
  }
  L.owner = owner_.data();
  // (the forces of a run's setup leave the history as it was: a near list
  // built then, which forgot ended contacts, is not kept)
  const bool setup = engine_.update->in_setup_forces;
  if (setup) near_epoch_ = -1;
  const bool use_near = near_list && engine_.neighbor->skin > 0.0;
  const double margin = 0.25 * engine_.neighbor->skin;
  bool remake = false;  // the near list is made anew by this scan of every entry
  if (use_near) {
    if (near_list_current(p, margin)) {
      L.use_near = true;
      L.near = near_.data();
      L.near_i = near_i_.data();
      L.near_j = near_j_.data();
      L.near_slot = near_slot_.data();
      L.nnear = static_cast<int>(near_.size());
    } else {
      remake = true;
      // room for every entry (the old entries need not be kept)
      const std::size_t room =
          static_cast<std::size_t>(L.offset[p.nlocal]) + contact::lane::width<contact::lane::Wide>();
      if (room > near_.capacity())
        assign_fresh(near_, room, 0);
      else
        near_.resize(room);
      L.near_out = near_.data();
      L.near_margin = margin;
    }
  } else {
    engine_.neighbor->watch(0.0);
  }
  const int nnear = pair_loop<Kernel, contact::lane::Wide>(L);
  if (remake) {
    near_.resize(static_cast<std::size_t>(nnear));
    // the entries' particles and slots, read in step with the entries while
    // the list is used
    assign_fresh(near_i_, near_.size(), 0);
    assign_fresh(near_j_, near_.size(), 0);
    if (nh > 0) assign_fresh(near_slot_, near_.size(), ContactHistory::kNone);
    const std::int32_t* const slot = nh > 0 ? history_.slots() : nullptr;
    // (the entries ascend: their particle is found by walking the offsets,
    // not read from owner_, a value per list entry)
    for (int q = 0, i = 0; q < nnear; ++q) {
      const int k = near_[q];
      while (L.offset[i + 1] <= k)
        ++i;
      near_i_[q] = i;
      near_j_[q] = L.neigh[k];
      if (slot) near_slot_[q] = slot[k];
    }
    near_x_.assign(p.x.begin(), p.x.begin() + p.size());
    near_r_.assign(p.radius.begin(), p.radius.begin() + p.size());
    near_epoch_ = engine_.neighbor->watch_epoch();
  }
  if (setup) near_epoch_ = -1;
}

bool PairGranular::near_list_current(const Particles& p, double margin) {
  Neighbor& list = *engine_.neighbor;
  const int nall = p.size();
  // a pair's distance changes by at most the sum of the two displacements:
  // stale when a particle moved by half the margin, found by the neighbour
  // list's watch at this step (all ranks remake theirs together, so that a
  // ghost's displacement is its owner's) or, when it did not look, here
  list.watch(0.25 * margin * margin);
  // (every build begins a new epoch)
  if (near_epoch_ != list.watch_epoch() || static_cast<int>(near_x_.size()) != nall) return false;
  if (!list.watch_checked() &&
      Neighbor::moved_beyond(p.x.data(), near_x_.data(), nall, 0.25 * margin * margin))
    return false;
  return Neighbor::same_values(p.radius.data(), near_r_.data(), nall);
}

void PairGranular::compute() {
  contact::dispatch_model(kernel_spec_, [this](auto kernel) { this->loop<decltype(kernel)>(); });
  if (bridge_) bridge_->compute();
}

// One class under every name: gran (LIGGGHTS), hertz/rolling (Granary's, other
// defaults), bubble and gran_bubble (LIGGGHTS' aliases of gran), hybrid and
// hybrid/overlay (one granular sub-style for all type pairs).
static const bool granular_pair_styles_registered = [] {
  for (const char* name : {"gran", "hertz/rolling", "bubble", "gran_bubble", "hybrid", "hybrid/overlay"})
    PairRegistry::instance().add(name, [name](Engine& e, const Args& a) -> std::unique_ptr<Pair> {
      return std::make_unique<PairGranular>(e, a, name);
    });
  return true;
}();

}  // namespace granary
